#include "report_diff.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string_view>

namespace dovetail::cli {

namespace {

using json = nlohmann::ordered_json;

/// A value as the change shows it: JSON, long texts cut.
std::string shown(const json& value, std::size_t from = 0) {
  constexpr std::size_t kLongest = 160;
  std::string text = value.dump(-1, ' ', false, json::error_handler_t::replace);
  if (from > 0 && from < text.size()) text = "..." + text.substr(from);
  if (text.size() > kLongest) text = text.substr(0, kLongest) + "...";
  return text;
}

/// Where two long texts' JSON forms should be shown from so that their
/// first difference is in view: a little before it, or 0 when it comes
/// early enough to be seen anyway.
std::size_t shown_from(const json& a, const json& b) {
  const std::string x = a.dump(-1, ' ', false, json::error_handler_t::replace);
  const std::string y = b.dump(-1, ' ', false, json::error_handler_t::replace);
  const auto [at, unused] = std::mismatch(x.begin(), x.end(), y.begin(), y.end());
  const auto first = static_cast<std::size_t>(at - x.begin());
  constexpr std::size_t kBefore = 40;
  return first > 120 ? first - kBefore : 0;
}

/// Whether a path may begin at `at` of `text`: at its start, or after a
/// blank, a quote, a bracket or a separator (not inside another path:
/// "s/" is no path in "../assets/").
bool path_starts_at(const std::string& text, std::size_t at) {
  if (at == 0) return true;
  const char before = text[at - 1];
  return std::string_view(" \t\n\"'([{:=,;").find(before) != std::string_view::npos;
}

/// Calls `edit` on every text in `value`, at any depth.
template <typename Edit>
void for_each_text(json& value, const Edit& edit) {
  if (value.is_string()) {
    edit(value.get_ref<std::string&>());
  } else if (value.is_structured()) {
    for (json& child : value) for_each_text(child, edit);
  }
}

/// `from` read as `to` in `text`, where it begins a path.
void replace_paths(std::string& text, const std::string& from, const std::string& to) {
  if (from.empty()) return;
  for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at)) {
    if (path_starts_at(text, at)) {
      text.replace(at, from.size(), to);
      at += to.size();
    } else {
      ++at;
    }
  }
}

/// `name:LINE` read as `name` in `text`: where a clause stands in the file
/// is no behaviour (a comment added above it moves it).
void drop_line_numbers(std::string& text, const std::string& name) {
  if (name.empty()) return;
  const std::string with_colon = name + ":";
  for (std::size_t at = text.find(with_colon); at != std::string::npos;
       at = text.find(with_colon, at + name.size())) {
    std::size_t end = at + with_colon.size();
    while (end < text.size() && text[end] >= '0' && text[end] <= '9') ++end;
    if (end > at + with_colon.size()) text.erase(at + name.size(), end - at - name.size());
  }
}

/// The report without its `file`, the scenario's path in its texts read as
/// the file's name without line numbers, and its folder's paths as
/// relative to the folder; its outcome and error first, the first thing a
/// change should say.
json normalized(const json& report) {
  json r = report;
  if (!r.is_object()) return r;
  if (r.contains("file") && r["file"].is_string()) {
    const std::filesystem::path file = r["file"].get<std::string>();
    r.erase("file");
    const std::string name = file.filename().string();
    const std::string folder = file.has_parent_path() ? file.parent_path().string() + "/" : "";
    for_each_text(r, [&](std::string& text) {
      replace_paths(text, file.string(), name);
      replace_paths(text, folder, "");
      drop_line_numbers(text, name);
    });
  }
  // Both first in both reports, null where one has none, so that an error
  // only the baseline had is the first change too.
  json ordered = json::object();
  for (const char* first : {"outcome", "error"}) {
    const auto it = r.find(first);
    ordered[first] = it != r.end() ? *it : json();
  }
  for (const auto& [key, value] : r.items()) {
    if (!ordered.contains(key)) ordered[key] = value;
  }
  return ordered;
}

/// The text's numbers and the text between them.
struct NumberedText {
  std::vector<std::string> words;  ///< one more than numbers
  std::vector<double> numbers;
};

bool is_digit(char c) { return c >= '0' && c <= '9'; }

/// One pass over the text: a number starts at a digit, or at a sign or a
/// point before one, and runs as far as std::from_chars reads a double.
NumberedText numbered(const std::string& text) {
  NumberedText out;
  std::size_t from = 0;
  std::size_t at = 0;
  while (at < text.size()) {
    std::size_t start = at;
    if ((text[at] == '-' || text[at] == '+') && at + 1 < text.size()) ++start;
    if (text[start] == '.' && start + 1 < text.size()) ++start;
    if (!is_digit(text[start]) || (at > 0 && is_digit(text[at - 1]))) {
      ++at;
      continue;
    }
    const std::size_t begin = text[at] == '+' ? at + 1 : at;  // from_chars reads no '+'
    double value = 0;
    const auto [end, error] =
        std::from_chars(text.data() + begin, text.data() + text.size(), value);
    if (error != std::errc() && error != std::errc::result_out_of_range) {
      ++at;
      continue;
    }
    out.words.push_back(text.substr(from, at - from));
    out.numbers.push_back(value);
    from = at = static_cast<std::size_t>(end - text.data());
  }
  out.words.push_back(text.substr(from));
  return out;
}

/// What names an entry of a list: a step's or part's name, an
/// expectation's text, a pair of parts; empty when nothing does.
std::string label_of(const json& entry) {
  if (!entry.is_object()) return {};
  for (const char* key : {"name", "part", "expect"}) {
    if (const auto it = entry.find(key); it != entry.end() && it->is_string()) {
      return it->get<std::string>();
    }
  }
  const auto a = entry.find("a");
  const auto b = entry.find("b");
  if (a != entry.end() && b != entry.end() && a->is_string() && b->is_string() &&
      !entry.contains("kind")) {  // an event is named by its place in the timeline
    return a->get<std::string>() + "/" + b->get<std::string>();
  }
  return {};
}

class Differ {
 public:
  Differ(std::size_t limit, double tolerance) : limit_(limit), tolerance_(tolerance) {}

  void walk(const json& was, const json& now, const std::string& where) {
    if (was.is_object() && now.is_object()) {
      for (const auto& [key, value] : now.items()) {
        const std::string at = where.empty() ? key : where + "." + key;
        if (tolerance_ > 0 && at == "simulation.state_hash") continue;
        if (const auto it = was.find(key); it != was.end()) {
          walk(*it, value, at);
        } else {
          add(at, value, "null");
        }
      }
      for (const auto& [key, value] : was.items()) {
        if (!now.contains(key)) add(where.empty() ? key : where + "." + key, "null", value);
      }
      return;
    }
    if (was.is_array() && now.is_array() && !labelled(was) && !labelled(now)) {
      align(was, now, where);
      return;
    }
    if (was.is_array() && now.is_array()) {
      const std::size_t common = std::min(was.size(), now.size());
      for (std::size_t i = 0; i < common; ++i) {
        const std::string label = label_of(now[i]);
        const std::string index = where + "[" + std::to_string(i) + "]";
        if (label != label_of(was[i])) {
          add(index, now[i], was[i]);  // another entry in its place
        } else {
          walk(was[i], now[i], label.empty() ? index : where + "[" + label + "]");
        }
      }
      if (was.size() != now.size()) {
        add(where + " entries", std::to_string(now.size()), std::to_string(was.size()));
      }
      for (std::size_t i = common; i < now.size(); ++i) {
        add(where + "[" + std::to_string(i) + "]", now[i], "null");
      }
      for (std::size_t i = common; i < was.size(); ++i) {
        add(where + "[" + std::to_string(i) + "]", "null", was[i]);
      }
      return;
    }
    if (was.is_number() && now.is_number() && tolerance_ > 0 &&
        alike(was.get<double>(), now.get<double>())) {
      return;
    }
    if (was.is_string() && now.is_string() && tolerance_ > 0 &&
        alike_texts(was.get<std::string>(), now.get<std::string>())) {
      return;
    }
    if (was != now) add(where, now, was);
  }

  std::vector<ReportChange> changes;
  std::size_t total = 0;

 private:
  /// Whether some entry of the list has a name (label_of): such lists are
  /// compared entry by entry, by name.
  static bool labelled(const json& list) {
    return std::any_of(list.begin(), list.end(),
                       [](const json& entry) { return !label_of(entry).empty(); });
  }

  /// Whether walk would find no difference between two values: exactly
  /// equal ones, without a tolerance.
  bool same(const json& was, const json& now) const {
    if (tolerance_ == 0) return was == now;
    Differ probe(0, tolerance_);
    probe.walk(was, now, "");
    return probe.total == 0;
  }

  /// A list without names (the events, the messages): entries the two have
  /// alike in the same order are matched (the longest such sequence, after
  /// the common start and end), so that one event more or less is one
  /// difference, not a shift of every later one. Between matches, the
  /// entries left over are compared in pairs, and the surplus are added or
  /// gone. Lists too long to align (over 4 million pairs of entries left
  /// after the common start and end) are compared by position.
  void align(const json& was, const json& now, const std::string& where) {
    std::size_t head = 0;
    while (head < was.size() && head < now.size() && same(was[head], now[head])) ++head;
    std::size_t tail = 0;
    while (tail < was.size() - head && tail < now.size() - head &&
           same(was[was.size() - 1 - tail], now[now.size() - 1 - tail])) {
      ++tail;
    }
    const std::size_t n = was.size() - head - tail, m = now.size() - head - tail;
    // Matched pairs (index in was, index in now), in order.
    std::vector<std::pair<std::size_t, std::size_t>> matched;
    constexpr std::size_t kMostPairs = std::size_t{4} << 20;
    if (n > 0 && m > 0 && n * m <= kMostPairs) {
      // Longest common subsequence of the middles, by dynamic programming.
      std::vector<std::uint32_t> length((n + 1) * (m + 1), 0);
      const auto at = [&](std::size_t i, std::size_t j) -> std::uint32_t& {
        return length[i * (m + 1) + j];
      };
      for (std::size_t i = n; i-- > 0;) {
        for (std::size_t j = m; j-- > 0;) {
          at(i, j) = same(was[head + i], now[head + j]) ? at(i + 1, j + 1) + 1
                                                        : std::max(at(i + 1, j), at(i, j + 1));
        }
      }
      for (std::size_t i = 0, j = 0; i < n && j < m;) {
        if (same(was[head + i], now[head + j])) {
          matched.emplace_back(head + i, head + j);
          ++i;
          ++j;
        } else if (at(i + 1, j) >= at(i, j + 1)) {
          ++i;
        } else {
          ++j;
        }
      }
    }
    matched.emplace_back(was.size() - tail, now.size() - tail);  // the common end
    if (was.size() != now.size()) {
      add(where + " entries", std::to_string(now.size()), std::to_string(was.size()));
    }
    std::size_t i = head, j = head;
    for (const auto& [mi, mj] : matched) {
      // The entries between the last match and this one: in pairs, then the rest.
      for (; i < mi && j < mj; ++i, ++j) {
        walk(was[i], now[j], where + "[" + std::to_string(j) + "]");
      }
      for (; j < mj; ++j) add(where + "[" + std::to_string(j) + "]", now[j], "null");
      for (; i < mi; ++i) {
        add(where + "[" + std::to_string(i) + "] of the baseline", "gone", was[i]);
      }
      i = mi + 1;
      j = mj + 1;
    }
  }

  bool alike(double a, double b) const {
    return std::abs(a - b) <= tolerance_ * std::max({1.0, std::abs(a), std::abs(b)});
  }

  /// The same words with alike numbers between them (an expectation's
  /// detail: "overlapped 1.214e-14 mm").
  bool alike_texts(const std::string& a, const std::string& b) const {
    if (a == b) return true;
    const NumberedText x = numbered(a);
    const NumberedText y = numbered(b);
    if (x.words != y.words) return false;
    for (std::size_t i = 0; i < x.numbers.size(); ++i) {
      if (!alike(x.numbers[i], y.numbers[i])) return false;
    }
    return true;
  }

  /// One side of a difference: a value of a report, formatted only when the
  /// difference is kept (a probe of `same` keeps none), or a word ("null",
  /// "gone", a count). Made implicitly from either, as the call sites read.
  struct Side {
    Side(const json& v) : value(&v) {}
    Side(std::string t) : text(std::move(t)) {}
    Side(const char* t) : text(t) {}
    const json* value = nullptr;
    std::string text;
  };

  void add(std::string where, const Side& now, const Side& was) {
    ++total;
    if (changes.size() >= limit_) return;
    // Two texts are shown from a little before their first difference.
    const std::size_t from =
        now.value && was.value && now.value->is_string() && was.value->is_string()
            ? shown_from(*was.value, *now.value)
            : 0;
    changes.push_back({std::move(where), now.value ? shown(*now.value, from) : now.text,
                       was.value ? shown(*was.value, from) : was.text});
  }

  std::size_t limit_;
  double tolerance_;
};

}  // namespace

std::string ReportChange::str() const { return where + ": " + now + ", was " + was; }

std::vector<ReportChange> report_changes(const json& baseline, const json& now, std::size_t limit,
                                         std::size_t& total, double tolerance) {
  Differ differ(limit, tolerance);
  differ.walk(normalized(baseline), normalized(now), "");
  total = differ.total;
  return std::move(differ.changes);
}

json parse_report(const std::string& text) {
  constexpr int kDeepest = 32;
  const json::parser_callback_t depth = [](int level, json::parse_event_t, json&) {
    if (level > kDeepest) {
      throw std::runtime_error("nested deeper than " + std::to_string(kDeepest) + " levels");
    }
    return true;
  };
  try {
    return json::parse(text, depth);
  } catch (const json::parse_error& e) {
    // The parser's own words give the place: "at line 3, column 1: ...".
    const std::string what = e.what();
    throw std::runtime_error(what.substr(std::min(what.find("at line"), what.size())));
  }
}

bool is_scenario_report(const json& report) {
  if (!report.is_object()) return false;
  const auto format = report.find("format");
  return format != report.end() && *format == "dovetail-scenario-report";
}

}  // namespace dovetail::cli
