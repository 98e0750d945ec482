#pragma once
// What every benchmark needs: medians and percentiles of timings, and numbers
// from the command line that are checked, with a clear message and exit code
// 2 on a bad one instead of an uncaught exception or a silent zero.

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace dovetail::bench {

/// The median; NaN for none.
inline double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// The p-quantile (0 to 1): the sorted value at index round(p (n - 1)); NaN for none.
inline double percentile(std::vector<double> v, double p) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(std::llround(p * static_cast<double>(v.size() - 1)))];
}

/// `text`, the value of `option`, as a whole number in [min, max]; otherwise
/// "PROGRAM: OPTION needs a whole number from MIN to MAX, not 'TEXT'" and exit 2.
inline long long whole(const char* program, const char* option, const char* text, long long min,
                       long long max) {
  char* end = nullptr;
  errno = 0;
  const long long v = text ? std::strtoll(text, &end, 10) : 0;
  if (!text || end == text || *end != '\0' || errno == ERANGE || v < min || v > max) {
    std::fprintf(stderr, "%s: %s needs a whole number from %lld to %lld, not '%s'\n", program,
                 option, min, max, text ? text : "");
    std::exit(2);
  }
  return v;
}

/// `text`, the value of `option`, as a finite number of at least `min`;
/// otherwise a message as for whole() and exit 2.
inline double real(const char* program, const char* option, const char* text, double min) {
  char* end = nullptr;
  errno = 0;
  const double v = text ? std::strtod(text, &end) : 0;
  if (!text || end == text || *end != '\0' || errno == ERANGE || !std::isfinite(v) || v < min) {
    std::fprintf(stderr, "%s: %s needs a number of at least %g, not '%s'\n", program, option, min,
                 text ? text : "");
    std::exit(2);
  }
  return v;
}

/// The items of a comma-separated list ("a,b,c"); an empty item stays empty.
inline std::vector<std::string> comma_list(const std::string& list) {
  std::vector<std::string> items;
  for (std::size_t start = 0; start <= list.size();) {
    const std::size_t comma = std::min(list.find(',', start), list.size());
    items.push_back(list.substr(start, comma - start));
    start = comma + 1;
  }
  return items;
}

}  // namespace dovetail::bench
