#include "dovetail/interaction/glove_trace.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <bit>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "../support/temp_dir.h"

namespace dovetail::interaction {
namespace {

namespace fs = std::filesystem;

constexpr Real kInf = std::numeric_limits<Real>::infinity();

std::string file_bytes(const fs::path& path) {
  std::string bytes(fs::file_size(path), '\0');
  std::ifstream(path, std::ios::binary)
      .read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return bytes;
}

void write_bytes(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

/// A finite double: often an extreme or awkward value, otherwise random bits
/// (sometimes forced subnormal).
Real random_finite(std::mt19937_64& rng) {
  static const Real kSpecial[] = {DBL_MAX,
                                  -DBL_MAX,
                                  DBL_MIN,
                                  -DBL_MIN,
                                  std::numeric_limits<Real>::denorm_min(),
                                  -std::numeric_limits<Real>::denorm_min(),
                                  std::bit_cast<Real>(std::uint64_t{0x000FFFFFFFFFFFFF}),
                                  std::bit_cast<Real>(std::uint64_t{0x0000000123456789}),
                                  -0.0,
                                  0.0,
                                  1e-300,
                                  1e300,
                                  0.1,
                                  -0.1,
                                  1.0 / 3.0,
                                  5e-324 * 3,
                                  123456789.125,
                                  -2.2250738585072009e-308};
  const std::uint64_t pick = rng() % 8;
  if (pick == 0) return kSpecial[rng() % std::size(kSpecial)];
  if (pick == 1) return std::bit_cast<Real>(rng() & 0x800FFFFFFFFFFFFF);  // subnormal or zero
  while (true) {
    const Real value = std::bit_cast<Real>(rng());
    if (std::isfinite(value)) return value;
  }
}

std::vector<GloveSample> random_samples(std::size_t count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  // Distinct random times, sorted: strictly increasing over the whole range.
  std::set<Real> times;
  while (times.size() < count) times.insert(random_finite(rng));
  std::vector<GloveSample> samples;
  samples.reserve(count);
  for (Real t : times) {
    GloveSample s;
    s.t = t;
    for (int i = 0; i < 3; ++i) s.p_WH[i] = random_finite(rng);
    do {
      s.q_WH = {random_finite(rng), random_finite(rng), random_finite(rng), random_finite(rng)};
    } while (s.q_WH.w == 0 && s.q_WH.x == 0 && s.q_WH.y == 0 && s.q_WH.z == 0);
    for (Real& angle : s.joints) angle = random_finite(rng);
    samples.push_back(s);
  }
  return samples;
}

GloveSample simple_sample(Real t) {
  GloveSample s;
  s.t = t;
  s.p_WH = Vec3(0.25, -0.5, 1.0);
  s.q_WH = {1, 0, 0, 0};
  for (std::size_t k = 0; k < kJointCount; ++k) s.joints[k] = 10.0 + static_cast<Real>(k);
  return s;
}

std::string header_line() { return format_trace({}); }

std::string row_line(Real t) {
  const GloveSample s = simple_sample(t);
  return format_trace({&s, 1}).substr(header_line().size());
}

/// The message read_trace throws for `text` read as "trace.csv".
std::string trace_error(const std::string& text) {
  std::istringstream in(text);
  try {
    read_trace(in, "trace.csv");
  } catch (const TraceError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no TraceError for:\n" << text.substr(0, 400);
  return {};
}

/// `row` with field `index` (0-based) replaced by `value`.
std::string with_field(const std::string& row, std::size_t index, const std::string& value) {
  std::vector<std::string> fields;
  std::string field;
  std::istringstream in(row.substr(0, row.size() - 1));
  while (std::getline(in, field, ',')) fields.push_back(field);
  fields.at(index) = value;
  std::string out;
  for (std::size_t i = 0; i < fields.size(); ++i) out += (i ? "," : "") + fields[i];
  return out + "\n";
}

bool starts_with(const std::string& text, const std::string& prefix) {
  return text.rfind(prefix, 0) == 0;
}

#define EXPECT_TRACE_ERROR(message, prefix, part)                             \
  do {                                                                        \
    const std::string m_ = (message);                                         \
    EXPECT_TRUE(starts_with(m_, prefix)) << m_;                               \
    EXPECT_NE(m_.find(part), std::string::npos) << m_ << "\nlacks: " << part; \
  } while (false)

TEST(GloveTrace, ColumnsAreInCanonicalOrder) {
  const std::span<const std::string_view> columns = trace_columns();
  ASSERT_EQ(columns.size(), 30u);
  const std::vector<std::string_view> pose = {"t", "x", "y", "z", "qw", "qx", "qy", "qz"};
  for (std::size_t i = 0; i < pose.size(); ++i) EXPECT_EQ(columns[i], pose[i]);
  for (std::size_t k = 0; k < kJointCount; ++k) {
    EXPECT_EQ(columns[8 + k], joint_name(static_cast<Joint>(k)));
  }
  EXPECT_EQ(header_line(),
            "t,x,y,z,qw,qx,qy,qz,thumb_roll,thumb_mcp,thumb_ip,thumb_abd,index_mcp,index_pip,"
            "index_dip,middle_mcp,middle_pip,middle_dip,ring_mcp,ring_pip,ring_dip,pinky_mcp,"
            "pinky_pip,pinky_dip,index_middle_abd,middle_ring_abd,ring_pinky_abd,palm_arch,"
            "wrist_pitch,wrist_yaw\n");
}

TEST(GloveTrace, WritesShortestRoundTripNumbers) {
  GloveSample s = simple_sample(-0.0);
  s.p_WH = Vec3(0.1, std::numeric_limits<Real>::denorm_min(), DBL_MAX);
  s.q_WH = {-0.0, 1e-300, 1.0 / 3.0, -DBL_MIN};
  const std::string text = format_trace({&s, 1});
  const std::string row = text.substr(header_line().size());
  EXPECT_EQ(row.substr(0, row.find(",10,")),
            "-0,0.1,5e-324,1.7976931348623157e+308,-0,1e-300,0.3333333333333333,"
            "-2.2250738585072014e-308");
  EXPECT_EQ(row.back(), '\n');
  EXPECT_EQ(std::count(row.begin(), row.end(), '\n'), 1);
}

TEST(GloveTrace, RoundTripsRandomSamplesBitForBit) {
  const std::vector<GloveSample> samples = random_samples(100000, 0x5eed'7ace);
  test::TempDir dir("dovetail_trace");
  const fs::path first = dir / "first.csv";
  const fs::path second = dir / "second.csv";
  write_trace(first, samples);

  const std::vector<GloveSample> read = read_trace(first);
  ASSERT_EQ(read.size(), samples.size());
  std::size_t mismatches = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (!same_bits(read[i], samples[i]) && ++mismatches <= 5) {
      ADD_FAILURE() << "sample " << i << " differs after the round trip";
    }
  }
  EXPECT_EQ(mismatches, 0u);

  write_trace(second, read);
  EXPECT_TRUE(file_bytes(first) == file_bytes(second))
      << "rewriting a read trace changed its bytes";
}

TEST(GloveTrace, ReadsColumnsInAnyOrder) {
  // Reverse the canonical order of header and row.
  const std::span<const std::string_view> columns = trace_columns();
  GloveSample s = simple_sample(2.5);
  s.q_WH = {0.5, -0.5, 0.25, 0.125};
  std::string header, row;
  const std::string canonical = format_trace({&s, 1}).substr(header_line().size());
  std::vector<std::string> values;
  std::istringstream fields(canonical.substr(0, canonical.size() - 1));
  for (std::string v; std::getline(fields, v, ',');) values.push_back(v);
  ASSERT_EQ(values.size(), columns.size());
  for (std::size_t i = columns.size(); i-- > 0;) {
    header += std::string(columns[i]) + (i ? "," : "\n");
    row += values[i] + (i ? "," : "\n");
  }
  std::istringstream in(header + row);
  const std::vector<GloveSample> read = read_trace(in, "reversed.csv");
  ASSERT_EQ(read.size(), 1u);
  EXPECT_TRUE(same_bits(read[0], s));
}

TEST(GloveTrace, AcceptsCrLfCommentsBlanksAndSpacesAroundFields) {
  std::string text = "# recorded by hand\r\n\r\n" + header_line() + row_line(1) + "   \n" +
                     "# a comment between rows\n" + row_line(2);
  // CRLF on the header, and blanks around one field.
  text.replace(text.find('\n', text.find("wrist_yaw")), 1, "\r\n");
  text.replace(text.find(",0.25,"), 6, ", 0.25 ,");
  std::istringstream in(text);
  const std::vector<GloveSample> read = read_trace(in, "trace.csv");
  ASSERT_EQ(read.size(), 2u);
  EXPECT_TRUE(same_bits(read[0], simple_sample(1)));
  EXPECT_TRUE(same_bits(read[1], simple_sample(2)));
}

TEST(GloveTrace, AcceptsLinesOfExactlyTheLimit) {
  // Blanks before the first comma pad the row to exactly kMaxTraceLineBytes.
  const std::string base = row_line(1);
  const std::size_t comma = base.find(',');
  std::string content = base.substr(0, comma);
  content.append(kMaxTraceLineBytes - (base.size() - 1), ' ');
  content.append(base, comma, base.size() - 1 - comma);
  ASSERT_EQ(content.size(), kMaxTraceLineBytes);
  for (const char* ending : {"\n", "\r\n", ""}) {
    std::istringstream in(header_line() + content + ending);
    EXPECT_EQ(read_trace(in, "trace.csv").size(), 1u);
  }
  for (const char* ending : {"\n", ""}) {
    EXPECT_TRACE_ERROR(trace_error(header_line() + " " + content + ending),
                       "trace.csv:2: ", "line longer than 65536 bytes");
  }
}

TEST(GloveTrace, RefusesEmptyFile) {
  EXPECT_EQ(trace_error(""), "trace.csv: empty, no header");
  EXPECT_EQ(trace_error("# only a comment\n\n"), "trace.csv: empty, no header");
}

TEST(GloveTrace, RefusesHeaderWithoutSamples) {
  EXPECT_TRACE_ERROR(trace_error("# c\n" + header_line() + "\n# end\n"),
                     "trace.csv:2: ", "header but no samples");
}

TEST(GloveTrace, RefusesNumbersInPlaceOfHeader) {
  EXPECT_TRACE_ERROR(trace_error(row_line(1) + row_line(2)),
                     "trace.csv:1: ", "expected a header row naming the columns");
}

TEST(GloveTrace, RefusesMissingColumns) {
  std::string header = header_line();
  header.erase(header.find("qx,"), 3);
  header.erase(header.find(",wrist_yaw"), 10);
  const std::string message = trace_error("#\n" + header + row_line(1));
  EXPECT_TRACE_ERROR(message, "trace.csv:2: ", "missing columns: qx, wrist_yaw");
}

TEST(GloveTrace, RefusesUnknownColumn) {
  std::string header = header_line();
  header.replace(header.find("palm_arch"), 9, "palm_arc");
  EXPECT_TRACE_ERROR(trace_error(header + row_line(1)),
                     "trace.csv:1: ", "unknown column 'palm_arc' (field 28)");
}

TEST(GloveTrace, RefusesDuplicatedColumn) {
  std::string header = header_line();
  header.replace(header.find(",y,"), 3, ",x,");
  EXPECT_TRACE_ERROR(trace_error(header + row_line(1)),
                     "trace.csv:1: ", "duplicated column 'x' (fields 2 and 3)");
}

TEST(GloveTrace, RefusesRowsWithTooFewOrTooManyFields) {
  std::string few = row_line(2);
  few.erase(few.rfind(','));
  few += "\n";
  EXPECT_TRACE_ERROR(trace_error(header_line() + row_line(1) + few),
                     "trace.csv:3: ", "expected 30 fields, found 29");
  std::string many = row_line(2);
  many.insert(many.size() - 1, ",7");
  EXPECT_TRACE_ERROR(trace_error(header_line() + row_line(1) + many),
                     "trace.csv:3: ", "expected 30 fields, found 31");
}

TEST(GloveTrace, RefusesFieldThatIsNotANumber) {
  EXPECT_TRACE_ERROR(trace_error(header_line() + with_field(row_line(1), 5, "0.5x")),
                     "trace.csv:2: ", "column qx (field 6): '0.5x' is not a number");
  EXPECT_TRACE_ERROR(trace_error(header_line() + with_field(row_line(1), 2, "")),
                     "trace.csv:2: ", "column y (field 3) is empty");
  EXPECT_TRACE_ERROR(trace_error(header_line() + with_field(row_line(1), 0, "0x10")),
                     "trace.csv:2: ", "column t (field 1): '0x10' is not a number");
}

TEST(GloveTrace, RefusesNonFiniteValues) {
  for (const std::string value : {"inf", "-inf", "nan", "1e999", "-1e400"}) {
    EXPECT_TRACE_ERROR(
        trace_error(header_line() + with_field(row_line(1), 29, value)),
        "trace.csv:2: ", "column wrist_yaw (field 30): '" + value + "' is not finite");
  }
}

TEST(GloveTrace, ReadsSubnormalsAndSignedZero) {
  std::string row = with_field(row_line(1), 1, "4.9406564584124654e-324");
  row = with_field(row, 2, "-0");
  row = with_field(row, 3, "+2.5e-310");
  std::istringstream in(header_line() + row);
  const std::vector<GloveSample> read = read_trace(in, "trace.csv");
  ASSERT_EQ(read.size(), 1u);
  EXPECT_EQ(std::bit_cast<std::uint64_t>(read[0].p_WH.x()), 1u);
  EXPECT_EQ(std::bit_cast<std::uint64_t>(read[0].p_WH.y()), std::bit_cast<std::uint64_t>(-0.0));
  EXPECT_EQ(read[0].p_WH.z(), 2.5e-310);
}

TEST(GloveTrace, RefusesZeroQuaternion) {
  std::string row = row_line(2);
  for (std::size_t f = 4; f < 8; ++f) row = with_field(row, f, f == 5 ? "-0" : "0");
  EXPECT_TRACE_ERROR(trace_error(header_line() + row_line(1) + row),
                     "trace.csv:3: ", "quaternion (qw qx qy qz) is zero");
}

TEST(GloveTrace, RefusesTimeThatDoesNotIncrease) {
  EXPECT_TRACE_ERROR(trace_error(header_line() + row_line(1.5) + "\n" + row_line(1.5)),
                     "trace.csv:4: ",
                     "time does not increase: t = 1.5 after t = 1.5 on line 2 (a sample "
                     "repeated, as devices send some twice: keep one of the two)");
  const std::string backwards =
      trace_error(header_line() + row_line(1) + row_line(2) + row_line(0.5));
  EXPECT_TRACE_ERROR(backwards,
                     "trace.csv:4: ", "time does not increase: t = 0.5 after t = 2 on line 3");
  EXPECT_EQ(backwards.find("repeated"), std::string::npos) << backwards;
  EXPECT_TRACE_ERROR(trace_error(header_line() + row_line(0) + row_line(-0.0)),
                     "trace.csv:3: ", "time does not increase: t = -0 after t = 0");
}

TEST(GloveTrace, RefusesGigabyteLineWithoutReadingIt) {
  test::TempDir dir("dovetail_trace");
  const fs::path path = dir / "huge.csv";
  write_bytes(path, header_line() + row_line(1));
  // A sparse file: line 3 is 1 GiB of NUL bytes without a line ending.
  fs::resize_file(path, fs::file_size(path) + (std::uintmax_t{1} << 30));
  const auto start = std::chrono::steady_clock::now();
  try {
    read_trace(path);
    ADD_FAILURE() << "no TraceError";
  } catch (const TraceError& e) {
    EXPECT_EQ(std::string(e.what()), path.string() + ":3: line longer than 65536 bytes");
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  RecordProperty("seconds", std::to_string(seconds));
}

TEST(GloveTrace, RefusesLongLineOfDigits) {
  const std::string digits(100 * 1024, '7');
  EXPECT_EQ(trace_error(header_line() + row_line(1) + digits + "\n" + row_line(2)),
            "trace.csv:3: line longer than 65536 bytes");
  EXPECT_EQ(trace_error(header_line() + row_line(1) + digits),
            "trace.csv:3: line longer than 65536 bytes");
}

TEST(GloveTrace, RefusesMissingDirectoryAndUnreadableFiles) {
  test::TempDir dir("dovetail_trace");
  const fs::path missing = dir / "missing.csv";
  try {
    read_trace(missing);
    ADD_FAILURE() << "no TraceError";
  } catch (const TraceError& e) {
    EXPECT_EQ(std::string(e.what()), missing.string() + ": file not found");
  }
  try {
    read_trace(dir.path());
    ADD_FAILURE() << "no TraceError";
  } catch (const TraceError& e) {
    EXPECT_EQ(std::string(e.what()), dir.path().string() + ": is a directory");
  }
  if (geteuid() != 0) {
    const fs::path locked = dir / "locked.csv";
    write_bytes(locked, header_line() + row_line(1));
    fs::permissions(locked, fs::perms::none);
    try {
      read_trace(locked);
      ADD_FAILURE() << "no TraceError";
    } catch (const TraceError& e) {
      EXPECT_TRUE(starts_with(e.what(), locked.string() + ": cannot be opened: ")) << e.what();
    }
  }
}

TEST(GloveTrace, ReportsWriteFailure) {
  test::TempDir dir("dovetail_trace");
  const GloveSample s = simple_sample(1);
  const fs::path nowhere = dir / "no_such_folder" / "trace.csv";
  try {
    write_trace(nowhere, {&s, 1});
    ADD_FAILURE() << "no TraceError";
  } catch (const TraceError& e) {
    EXPECT_TRUE(starts_with(e.what(), nowhere.string() + ": cannot be written: ")) << e.what();
  }
  try {
    write_trace(dir.path(), {&s, 1});
    ADD_FAILURE() << "no TraceError";
  } catch (const TraceError& e) {
    EXPECT_TRUE(starts_with(e.what(), dir.path().string() + ": cannot be written: ")) << e.what();
  }
  if (fs::exists("/dev/full")) {
    try {
      write_trace("/dev/full", {&s, 1});
      ADD_FAILURE() << "no TraceError";
    } catch (const TraceError& e) {
      EXPECT_TRUE(starts_with(e.what(), "/dev/full: cannot be written: ")) << e.what();
    }
  }
}

TEST(GloveTrace, AFileCutShortInItsLastLineIsSaidToBe) {
  test::TempDir dir("dovetail_trace");
  const auto error_of = [&](const std::string& text) {
    write_bytes(dir / "trace.csv", text);
    try {
      read_trace(dir / "trace.csv");
    } catch (const TraceError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  std::string cut = row_line(2);
  cut.resize(cut.size() / 2);  // no line end, and too few fields
  const std::string message = error_of(header_line() + row_line(1) + cut);
  EXPECT_NE(message.find("trace.csv:3: expected 30 fields"), std::string::npos) << message;
  EXPECT_NE(message.find("last line has no line end: was the file cut short"), std::string::npos)
      << message;
  // A broken line that is not the last, or a last line that ends, is no sign of it.
  std::string few = row_line(2);
  few.erase(few.rfind(','));
  const std::string unended = row_line(3).substr(0, row_line(3).size() - 1);
  for (const std::string& text :
       {header_line() + few + "\n" + unended, header_line() + row_line(1) + few + "\n"}) {
    const std::string m = error_of(text);
    EXPECT_NE(m.find("expected 30 fields"), std::string::npos) << m;
    EXPECT_EQ(m.find("cut short"), std::string::npos) << m;
  }
  // Nor is a mistake no cut makes: a header naming too few columns.
  const std::string header = error_of("t,x,y");
  EXPECT_NE(header.find("missing columns"), std::string::npos) << header;
  EXPECT_EQ(header.find("cut short"), std::string::npos) << header;
}

TEST(GloveTrace, WrittenFileReadsBack) {
  test::TempDir dir("dovetail_trace");
  const std::vector<GloveSample> samples = {simple_sample(0), simple_sample(0.5)};
  write_trace(dir / "t.csv", samples);
  EXPECT_EQ(file_bytes(dir / "t.csv"), format_trace(samples));
  const std::vector<GloveSample> read = read_trace(dir / "t.csv");
  ASSERT_EQ(read.size(), 2u);
  EXPECT_TRUE(same_bits(read[1], samples[1]));
}

}  // namespace
}  // namespace dovetail::interaction

namespace dovetail::interaction {
namespace {

std::vector<GloveSample> samples_at(std::initializer_list<Real> times) {
  std::vector<GloveSample> samples;
  for (const Real t : times) samples.push_back(simple_sample(t));
  return samples;
}

TEST(GloveTraceDoubts, AGapOfManySamplesIsNamedAndAnEvenTraceIsNot) {
  std::vector<GloveSample> even;
  for (int i = 0; i < 100; ++i) even.push_back(simple_sample(i / 90.0));
  EXPECT_FALSE(dropped_samples(even).has_value());
  // Jitter of a sample or two is no drop.
  EXPECT_FALSE(dropped_samples(samples_at({0, 0.01, 0.02, 0.04, 0.05, 0.06})).has_value());
  std::vector<GloveSample> dropped = even;
  dropped.erase(dropped.begin() + 40, dropped.begin() + 60);
  const std::optional<std::string> doubt = dropped_samples(dropped);
  ASSERT_TRUE(doubt.has_value());
  EXPECT_NE(doubt->find("no sample for 0.233333 s after t=0.433333 s, 21 times the median gap"),
            std::string::npos)
      << *doubt;
}

TEST(GloveTraceDoubts, SparseSamplesAreMillisecondsOnlyOverATakeOfASecondInThem) {
  // A trace keyed by hand, a pose every second or so over 4.3 s: seconds.
  EXPECT_FALSE(sparse_samples(samples_at({0, 1.8, 2.6, 3.4, 3.6, 3.9, 4.3})).has_value());
  // A 2 s take at 90 Hz written in milliseconds: 11.1 "s" apart over 2000.
  std::vector<GloveSample> ms;
  for (int i = 0; i <= 180; ++i) ms.push_back(simple_sample(i * 1000 / 90.0));
  const std::optional<std::string> doubt = sparse_samples(ms);
  ASSERT_TRUE(doubt.has_value());
  EXPECT_NE(doubt->find("are its times in milliseconds?"), std::string::npos) << *doubt;
}

}  // namespace
}  // namespace dovetail::interaction
