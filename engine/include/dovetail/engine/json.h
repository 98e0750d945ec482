#pragma once
/// \file json.h
/// The small pieces of JSON writing that reports and the command line share.

#include <string>
#include <string_view>

namespace dovetail::engine {

/// `text` as a JSON string literal, quotes included (control characters
/// escaped, anything that is not UTF-8 replaced as valid_utf8 does).
std::string json_string(std::string_view text);

/// `text` with every byte that does not belong to a well-formed UTF-8
/// sequence (RFC 3629: no overlong forms, no surrogates, nothing above
/// U+10FFFF) replaced by U+FFFD. JSON, XML and HTML must be UTF-8, and the
/// text a scenario or a file name brings need not be.
std::string valid_utf8(std::string_view text);

/// The shortest text that reads back to the same double (std::to_chars; so a
/// report's numbers are the same text for the same bits); `null` for NaN and
/// infinities, which JSON cannot hold. The one number formatter of the
/// reports and the command line.
std::string json_number(double value);

}  // namespace dovetail::engine
