#pragma once
/// \file glove_trace.h
/// Glove traces: the CSV format in which glove samples are recorded,
/// replayed and handed to outside tools (docs/cli.md, "Glove traces").
///
/// Format: a header row naming the 30 columns, then one sample per row,
/// comma separated. Columns `t` (s), `x y z` (m, tracker position in the
/// world), `qw qx qy qz` (tracker orientation, need not be unit length), then
/// the 22 joint angles in degrees named as joint_name() names them. A reader
/// accepts the columns in any order; a writer writes them in the order above.
/// Numbers are written in the shortest form that reads back to the same bits,
/// so writing then reading gives the same samples bit for bit, and reading
/// then writing a written trace gives the same bytes.
///
/// Lines end in '\n' or "\r\n". Blank lines and lines whose first non-blank
/// is `#` are skipped anywhere; the header is the first other line. Blanks
/// around a field are ignored, a number may start with '+', and one too small
/// for a double reads as the nearest subnormal or zero. A writer writes no
/// comments, no blanks and no '\r'.
///
/// Errors name the file and the line (`trace.csv:12: ...`): a missing,
/// unknown or duplicated column, a row with too few or too many fields, a
/// field that is not a number or not finite, a zero quaternion, time that does
/// not increase, numbers where the header belongs, a header without samples
/// (named at the header's line), a line longer than kMaxTraceLineBytes
/// (detected without reading the rest of the line). A file with no header
/// at all gives `trace.csv: empty, no header`.

#include <cstddef>
#include <filesystem>
#include <iosfwd>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "dovetail/interaction/glove_sample.h"

namespace dovetail::interaction {

/// Thrown for a trace that cannot be read or written; what() starts with
/// `file:line: ` for a bad line, `file: ` otherwise.
class TraceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Longest accepted line, in bytes (without the line ending).
inline constexpr std::size_t kMaxTraceLineBytes = 64 * 1024;

/// The 30 column names in the order a writer writes them.
std::span<const std::string_view> trace_columns();

/// Reads the trace in `in`; `name` is the file name used in messages.
std::vector<GloveSample> read_trace(std::istream& in, std::string_view name);
/// Reads the trace file at `path`; throws TraceError when it is missing,
/// a directory, unreadable, or bad.
std::vector<GloveSample> read_trace(const std::filesystem::path& path);

/// What makes a trace that reads cleanly doubtful, one sentence each, without
/// the file's name: samples far sparser than any glove's (times written in
/// milliseconds read as seconds), a gap of many samples (samples dropped),
/// joint angles in radians, and a last line without a line end (a file cut
/// short while written, whose last value may be cut too). For warnings.
std::vector<std::string> trace_doubts(const std::filesystem::path& path,
                                      std::span<const GloveSample> samples);
/// The time between a trace's samples: the median gap, the widest and the
/// time it begins (all 0 with fewer than two samples).
struct TraceGaps {
  Real median = 0;
  Real widest = 0;
  Real widest_after = 0;
};
TraceGaps trace_gaps(std::span<const GloveSample> samples);

/// trace_doubts' first: samples more than 0.1 s apart at the median over a
/// take of 1000 s or more (in milliseconds, a second or more); a shorter one
/// is a trace keyed by hand.
std::optional<std::string> sparse_samples(std::span<const GloveSample> samples);
/// trace_doubts' second: the widest gap between samples over 5 times the
/// median gap (samples dropped; the hand moves in a straight line across it).
std::optional<std::string> dropped_samples(std::span<const GloveSample> samples);
/// trace_doubts' third: every joint angle within +-pi while some joint
/// sweeps over 0.5 (radians, where degrees are read; a still hand in
/// degrees sweeps less).
std::optional<std::string> radian_angles(std::span<const GloveSample> samples);

/// The header row and one row per sample, each ending in '\n'. The samples
/// are not checked: ones that read_trace refuses (none, non-finite values, a
/// zero quaternion, time that does not increase) are written as they are.
std::string format_trace(std::span<const GloveSample> samples);
/// Writes format_trace to `path`; throws TraceError naming it on failure.
void write_trace(const std::filesystem::path& path, std::span<const GloveSample> samples);

}  // namespace dovetail::interaction
