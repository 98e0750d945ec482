#pragma once
/// \file json.h
/// The small pieces of JSON writing that reports and the command line share.

#include <string>
#include <string_view>

namespace dovetail::engine {

/// `text` as a JSON string literal, quotes included (control characters escaped).
std::string json_string(std::string_view text);

/// The shortest text that reads back to the same double (std::to_chars; so a
/// report's numbers are the same text for the same bits); `null` for NaN and
/// infinities, which JSON cannot hold. The one number formatter of the
/// reports and the command line.
std::string json_number(double value);

}  // namespace dovetail::engine
