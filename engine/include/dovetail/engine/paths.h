#pragma once
/// \file paths.h
/// Whether two paths name one file: the check behind every command's refusal
/// to write an output over one of its inputs.

#include <filesystem>
#include <system_error>

namespace dovetail::engine {

/// Whether `a` and `b` name one file, or would once `a` is written: the same
/// file when `a` exists (links and `..` followed), the same normalised
/// absolute path when not. Paths that cannot be compared (a device) differ.
inline bool same_file(const std::filesystem::path& a, const std::filesystem::path& b) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const bool same = fs::exists(a, ec) ? fs::equivalent(a, b, ec)
                                      : fs::absolute(a, ec).lexically_normal() ==
                                            fs::absolute(b, ec).lexically_normal();
  return same && !ec;
}

}  // namespace dovetail::engine
