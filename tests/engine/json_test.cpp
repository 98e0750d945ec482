#include "dovetail/engine/json.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <limits>
#include <string>

namespace dovetail::engine {
namespace {

TEST(Json, NumbersAreShortestAndReadBackToTheSameBits) {
  EXPECT_EQ(json_number(0.1), "0.1");
  EXPECT_EQ(json_number(3.0), "3");
  EXPECT_EQ(json_number(-0.0), "-0");
  EXPECT_EQ(json_number(1e300), "1e+300");
  for (const double x : {1.0 / 90, 2.0 / 3, 1e-310, 123456789.123456789, -7.25e-5}) {
    const std::string text = json_number(x);
    EXPECT_EQ(std::strtod(text.c_str(), nullptr), x) << text;
  }
}

TEST(Json, NonFiniteNumbersAreNull) {
  // JSON has no NaN or infinity: reports and the command line write null.
  EXPECT_EQ(json_number(std::numeric_limits<double>::quiet_NaN()), "null");
  EXPECT_EQ(json_number(std::numeric_limits<double>::infinity()), "null");
  EXPECT_EQ(json_number(-std::numeric_limits<double>::infinity()), "null");
}

TEST(Json, StringsAreEscaped) { EXPECT_EQ(json_string("a\"b\\c\n"), "\"a\\\"b\\\\c\\n\""); }

TEST(Json, TextThatIsNotUtf8IsReplacedByteByByte) {
  const std::string fffd = "\xEF\xBF\xBD";
  // Well-formed text of one to four bytes a character is kept as it is.
  const std::string good = "a \xC3\xA9 \xE2\x82\xAC \xF0\x9F\x94\xA9";
  EXPECT_EQ(valid_utf8(good), good);
  EXPECT_EQ(valid_utf8("bad \xFF\xFE"), "bad " + fffd + fffd);
  EXPECT_EQ(valid_utf8("\xC3"), fffd);                                   // cut short
  EXPECT_EQ(valid_utf8("\xC0\xAF"), fffd + fffd);                        // overlong '/'
  EXPECT_EQ(valid_utf8("\xED\xA0\x80"), fffd + fffd + fffd);             // a surrogate
  EXPECT_EQ(valid_utf8("\xF4\x90\x80\x80"), fffd + fffd + fffd + fffd);  // above U+10FFFF
  EXPECT_EQ(valid_utf8("\xE2\x82x"), fffd + fffd + "x");
  EXPECT_EQ(json_string("n\xFF"), "\"n" + fffd + "\"");
}

}  // namespace
}  // namespace dovetail::engine
