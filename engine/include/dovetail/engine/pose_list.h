#pragma once
/// \file pose_list.h
/// Pose lists: the text format in which outside tools hand poses to
/// `dovetail query` and receive them from `dovetail poses`.
///
/// Format: one pose per line, `tx ty tz qw qx qy qz`, whitespace separated,
/// the pose of B in A's frame (translation, then a quaternion that need not be
/// unit length; it is normalised). Columns after the seventh are ignored; blank
/// lines and lines whose first non-blank character is `#` are skipped. A zero
/// or non-finite quaternion, a missing column, a non-number or a non-finite
/// number is an error naming file and line (`poses.txt:12: ...`). The rotation
/// is computed by collision::rotation_from_quaternion, the same function the
/// pose generators use, so every reader gets the same bits.

#include <cstddef>
#include <filesystem>
#include <fstream>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "dovetail/collision/types.h"

namespace dovetail::engine {

/// Thrown for a pose list that cannot be read or written; what() starts with
/// `file:line: ` for a bad line, `file: ` otherwise.
class PoseListError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A rotation as a quaternion (w, x, y, z).
struct Quaternion {
  collision::Real w = 1;
  collision::Real x = 0;
  collision::Real y = 0;
  collision::Real z = 0;
};

/// One pose read from a list, with the 1-based line it came from.
struct PoseEntry {
  collision::Transform X_AB;
  std::size_t line = 0;
};

/// The whole token as a double, or nullopt when it is not a number: an
/// optional leading '+', decimal or exponent form, `inf`/`nan` as from_chars
/// reads them; overflow gives infinity, underflow the nearest subnormal or
/// zero. The one number parser of the project's text formats.
std::optional<collision::Real> parse_real(std::string_view token);

/// A token of a text file as an error message shows it: its first 40 bytes
/// ("..." after more), control bytes as \xNN so that a message never drives
/// the terminal.
std::string shown_token(std::string_view token);

/// `text` with its control bytes (below 0x20, and 0x7f) written as \xNN,
/// but those in `keep`: what a message shows of a file's text, so that it
/// neither drives the terminal nor is cut short at a NUL.
std::string escape_control_bytes(std::string_view text, std::string_view keep = {});

/// Parses one line of a pose list. Returns nullopt for a blank or comment
/// line; throws PoseListError with message `where: what` for a bad line.
std::optional<collision::Transform> parse_pose_line(std::string_view text, std::string_view where);

/// Reads a pose list line by line, so that the poses before a bad line can
/// still be used.
class PoseListReader {
 public:
  /// Opens `path`; throws PoseListError when it is missing, a directory or unreadable.
  explicit PoseListReader(std::filesystem::path path);

  /// The next pose, or nullopt at the end of the file. Throws PoseListError
  /// (`file:line: what`) for a bad line; reading stops there.
  std::optional<PoseEntry> next();

  /// 1-based number of the last line read (0 before the first).
  std::size_t line() const { return line_; }

 private:
  std::filesystem::path path_;
  std::ifstream in_;
  std::size_t line_ = 0;
};

/// Every pose of `path`; throws PoseListError at the first bad line.
std::vector<PoseEntry> read_pose_list(const std::filesystem::path& path);

/// Unit quaternion of rotation matrix `R` (orthonormal), with w >= 0.
Quaternion quaternion_from_rotation(const collision::Mat3& R);

/// `tx ty tz qw qx qy qz` of X_AB with 17 significant digits (`%.17g`), so
/// the translation reads back bit for bit and the rotation to rounding.
std::string format_pose(const collision::Transform& X_AB);

/// Writes `poses` one per line after an optional `# ` comment line
/// (`comment` without the `#`); throws PoseListError when the file cannot be written.
void write_pose_list(const std::filesystem::path& path, std::span<const collision::Transform> poses,
                     std::string_view comment = {});

}  // namespace dovetail::engine
