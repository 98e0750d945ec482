#pragma once
/// \file json.h
/// The small pieces of JSON writing that reports and the command line share.

#include <string>
#include <string_view>

namespace dovetail::engine {

/// `text` as a JSON string literal, quotes included (control characters escaped).
std::string json_string(std::string_view text);

}  // namespace dovetail::engine
