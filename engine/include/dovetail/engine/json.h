#pragma once
/// \file json.h
/// The small pieces of JSON writing that reports and the command line share.

#include <string>
#include <string_view>

namespace dovetail::engine {

/// `text` as a JSON string literal, quotes included (control characters escaped).
std::string json_string(std::string_view text);

/// The shortest of %.15g, %.16g, %.17g that reads back to the same double
/// (so a report's numbers are the same text for the same bits).
std::string json_number(double value);

}  // namespace dovetail::engine
