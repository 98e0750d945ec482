#include "dovetail/engine/pose_list.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <system_error>

#include "dovetail/collision/mesh.h"
#include "dovetail/collision/pose_sampling.h"

namespace dovetail::engine {

namespace fs = std::filesystem;
using collision::Mat3;
using collision::Real;
using collision::Transform;
using collision::Vec3;

namespace {

constexpr std::array<const char*, 7> kColumns = {"tx", "ty", "tz", "qw", "qx", "qy", "qz"};

bool is_blank(char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; }

[[noreturn]] void bad_line(std::string_view where, const std::string& what) {
  throw PoseListError(std::string(where) + ": " + what);
}

std::string format_number(Real value) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", value);
  return buffer;
}

}  // namespace

std::optional<Real> parse_real(std::string_view token) {
  const char* first = token.data();
  const char* last = token.data() + token.size();
  if (first != last && *first == '+') {
    ++first;
    if (first != last && (*first == '-' || *first == '+')) return std::nullopt;
  }
  Real value = 0;
  const auto [ptr, ec] = std::from_chars(first, last, value);
  if (ptr != last || first == last) return std::nullopt;
  if (ec == std::errc::result_out_of_range) {
    // Overflow is reported as not finite; underflow to zero or a subnormal is a number.
    return std::strtod(std::string(first, last).c_str(), nullptr);
  }
  if (ec != std::errc()) return std::nullopt;
  return value;
}

std::string escape_control_bytes(std::string_view text, std::string_view keep) {
  std::string shown;
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if ((byte < 0x20 || byte == 0x7f) && keep.find(c) == std::string_view::npos) {
      char escaped[5];
      std::snprintf(escaped, sizeof escaped, "\\x%02X", byte);
      shown += escaped;
    } else {
      shown += c;
    }
  }
  return shown;
}

std::string shown_token(std::string_view token) {
  constexpr std::size_t kMax = 40;
  return escape_control_bytes(token.substr(0, kMax)) + (token.size() > kMax ? "..." : "");
}

std::optional<Transform> parse_pose_line(std::string_view text, std::string_view where) {
  std::array<Real, 7> v{};
  std::size_t column = 0;
  std::size_t i = 0;
  while (column < v.size()) {
    while (i < text.size() && is_blank(text[i])) ++i;
    if (i == text.size()) break;
    if (column == 0 && text[i] == '#') return std::nullopt;
    const std::size_t start = i;
    while (i < text.size() && !is_blank(text[i])) ++i;
    const std::string_view token = text.substr(start, i - start);
    const std::optional<Real> number = parse_real(token);
    if (!number) {
      bad_line(where, "column " + std::to_string(column + 1) + " (" + kColumns[column] + ") '" +
                          shown_token(token) + "' is not a number");
    }
    if (!std::isfinite(*number)) {
      bad_line(where, "column " + std::to_string(column + 1) + " (" + kColumns[column] + ") '" +
                          shown_token(token) + "' is not finite");
    }
    // The bound of mesh coordinates (MeshLimits): beyond it the exact
    // predicates and distances would overflow.
    if (column < 3 && !(std::abs(*number) <= collision::MeshLimits{}.max_abs_coordinate)) {
      bad_line(where, "column " + std::to_string(column + 1) + " (" + kColumns[column] + ") '" +
                          shown_token(token) + "' is beyond the coordinate limit of 1e30");
    }
    v[column++] = *number;
  }
  if (column == 0) return std::nullopt;
  if (column < v.size()) {
    bad_line(where, "expected 7 columns (tx ty tz qw qx qy qz), found " + std::to_string(column));
  }

  Real w = v[3], x = v[4], y = v[5], z = v[6];
  const Real largest = std::max({std::abs(w), std::abs(x), std::abs(y), std::abs(z)});
  if (largest == 0) bad_line(where, "quaternion (qw qx qy qz) is zero");
  const Real squared = w * w + x * x + y * y + z * z;
  if (!std::isfinite(squared) || squared < 1e-150) {
    // Scale first so that normalising neither overflows nor underflows.
    w /= largest;
    x /= largest;
    y /= largest;
    z /= largest;
  }
  Transform X_AB;
  X_AB.R = collision::rotation_from_quaternion(w, x, y, z);
  X_AB.t = Vec3(v[0], v[1], v[2]);
  if (!X_AB.R.allFinite()) bad_line(where, "quaternion (qw qx qy qz) gives no rotation");
  return X_AB;
}

PoseListReader::PoseListReader(fs::path path) : path_(std::move(path)) {
  std::error_code ec;
  const fs::file_status status = fs::status(path_, ec);
  if (!fs::exists(status)) throw PoseListError(path_.string() + ": file not found");
  if (fs::is_directory(status)) throw PoseListError(path_.string() + ": is a directory");
  in_.open(path_, std::ios::binary);
  if (!in_) {
    throw PoseListError(path_.string() + ": cannot be opened: " + std::strerror(errno));
  }
}

std::optional<PoseEntry> PoseListReader::next() {
  std::string text;
  while (std::getline(in_, text)) {
    ++line_;
    if (line_ == 1 && text.starts_with("\xEF\xBB\xBF")) text.erase(0, 3);  // a byte-order mark
    const std::string where = path_.string() + ":" + std::to_string(line_);
    if (std::optional<Transform> X_AB = parse_pose_line(text, where)) {
      return PoseEntry{*X_AB, line_};
    }
  }
  if (in_.bad())
    throw PoseListError(path_.string() + ": read error after line " + std::to_string(line_));
  return std::nullopt;
}

std::vector<PoseEntry> read_pose_list(const fs::path& path) {
  PoseListReader reader(path);
  std::vector<PoseEntry> poses;
  while (std::optional<PoseEntry> pose = reader.next()) poses.push_back(*pose);
  return poses;
}

Quaternion quaternion_from_rotation(const Mat3& R) {
  // Shepperd: take the square root of the largest of 4w^2, 4x^2, 4y^2, 4z^2
  // and the other components from off-diagonal sums, for stability.
  const Real trace = R(0, 0) + R(1, 1) + R(2, 2);
  Quaternion q;
  if (trace >= R(0, 0) && trace >= R(1, 1) && trace >= R(2, 2)) {
    const Real s = 2 * std::sqrt(std::max<Real>(0, 1 + trace));  // 4w
    q.w = s / 4;
    q.x = (R(2, 1) - R(1, 2)) / s;
    q.y = (R(0, 2) - R(2, 0)) / s;
    q.z = (R(1, 0) - R(0, 1)) / s;
  } else if (R(0, 0) >= R(1, 1) && R(0, 0) >= R(2, 2)) {
    const Real s = 2 * std::sqrt(std::max<Real>(0, 1 + R(0, 0) - R(1, 1) - R(2, 2)));  // 4x
    q.w = (R(2, 1) - R(1, 2)) / s;
    q.x = s / 4;
    q.y = (R(0, 1) + R(1, 0)) / s;
    q.z = (R(0, 2) + R(2, 0)) / s;
  } else if (R(1, 1) >= R(2, 2)) {
    const Real s = 2 * std::sqrt(std::max<Real>(0, 1 + R(1, 1) - R(0, 0) - R(2, 2)));  // 4y
    q.w = (R(0, 2) - R(2, 0)) / s;
    q.x = (R(0, 1) + R(1, 0)) / s;
    q.y = s / 4;
    q.z = (R(1, 2) + R(2, 1)) / s;
  } else {
    const Real s = 2 * std::sqrt(std::max<Real>(0, 1 + R(2, 2) - R(0, 0) - R(1, 1)));  // 4z
    q.w = (R(1, 0) - R(0, 1)) / s;
    q.x = (R(0, 2) + R(2, 0)) / s;
    q.y = (R(1, 2) + R(2, 1)) / s;
    q.z = s / 4;
  }
  if (q.w < 0) q = {-q.w, -q.x, -q.y, -q.z};
  const Real n = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  if (n > 0 && std::isfinite(n)) q = {q.w / n, q.x / n, q.y / n, q.z / n};
  return q;
}

std::string format_pose(const Transform& X_AB) {
  const Quaternion q = quaternion_from_rotation(X_AB.R);
  std::string line;
  for (Real value : {X_AB.t.x(), X_AB.t.y(), X_AB.t.z(), q.w, q.x, q.y, q.z}) {
    if (!line.empty()) line += ' ';
    line += format_number(value);
  }
  return line;
}

void write_pose_list(const fs::path& path, std::span<const Transform> poses,
                     std::string_view comment) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) {
    throw PoseListError(path.string() + ": cannot be written: " + std::strerror(errno));
  }
  if (!comment.empty()) out << "# " << comment << '\n';
  for (const Transform& X_AB : poses) out << format_pose(X_AB) << '\n';
  out.flush();
  if (!out) throw PoseListError(path.string() + ": write failed: " + std::strerror(errno));
}

}  // namespace dovetail::engine
