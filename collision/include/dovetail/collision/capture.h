#pragma once
/// \file capture.h
/// Failure capture: a query whose outcome is suspect (two methods that
/// disagree, a search that hit its iteration cap, a value that is not finite)
/// is written with its inputs at full precision, hexadecimal floats, to a
/// file that can be read back and replayed bit for bit. A capture that still
/// reproduces is a bug to fix; once fixed, the file joins
/// `tests/data/captures/` and the test suite replays it for good
/// (docs/reliability.md, "Failure capture").
///
/// The file is text:
///
///     dovetail-capture 1
///     kind methods-disagree
///     what obb says intersecting, the convex level separated the hulls
///     context frame 12: 'peg' and 'block'
///     X_AB <9 numbers of R, row by row> <3 numbers of t>
///     mesh a <vertex count> <triangle count> <source>
///     <x> <y> <z>             one line per vertex, %a
///     <i> <j> <k>             one line per triangle
///     mesh b ...
///     end

#include <cstddef>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "dovetail/collision/mesh.h"
#include "dovetail/collision/types.h"

namespace dovetail::collision {

/// What was seen.
enum class CaptureKind {
  kMethodsDisagree,  ///< two levels or methods gave different verdicts on one pair
  kIterationCap,     ///< a search (GJK, the separating plane) stopped at its iteration cap
  kNonFinite,        ///< a pose or a result that is not a finite number
};

/// "methods-disagree", "iteration-cap", "non-finite".
std::string_view capture_kind_name(CaptureKind kind);

/// One suspect query: two meshes, each in its own frame, B placed in A's frame by X_AB.
struct Capture {
  CaptureKind kind = CaptureKind::kMethodsDisagree;
  std::string what;     ///< one line: what was seen
  std::string context;  ///< one line: where (frame, part names)
  std::shared_ptr<const Mesh> a;
  std::shared_ptr<const Mesh> b;
  Transform X_AB;
};

/// The capture as the text of its file (deterministic: same capture, same bytes).
std::string capture_text(const Capture& capture);

/// A capture file that cannot be read; the message starts with "FILE:LINE: ".
class CaptureError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Reads a capture file written by capture_text. Throws CaptureError.
Capture read_capture(const std::filesystem::path& file);

/// What a replay found.
struct CaptureReplay {
  bool reproduced = false;  ///< the suspect outcome happens again
  std::string what;         ///< what the replay saw, one line
};

/// Runs the captured query again:
/// - methods-disagree: every polygon-level method and the convex level's
///   separating-plane proof against brute force; reproduced when any differs;
/// - iteration-cap: GJK and the separating-plane search on the meshes' hulls;
///   reproduced when either stops at its cap;
/// - non-finite: every method on the (non-finite) input must return, and the
///   hulls' GJK distance must be finite or the input not; reproduced when a
///   finite input gives a non-finite distance.
CaptureReplay replay_capture(const Capture& capture);

/// Where a run's captures go: one file per distinct capture,
/// `<kind>-<16 hex digits of its text's hash>.capture` in `directory`, at
/// most `max_files` of them (later distinct ones are counted, not written).
/// Safe to call from several threads; the collision world records serially,
/// in pair order, so its files do not depend on the thread count.
class CaptureSink {
 public:
  explicit CaptureSink(std::filesystem::path directory, std::size_t max_files = 50);

  /// Writes the capture unless an identical one was written already. Never
  /// throws: a file that cannot be written is counted in failed_writes().
  void record(const Capture& capture);

  std::size_t recorded() const;                      ///< calls of record()
  std::vector<std::filesystem::path> files() const;  ///< written, sorted
  std::size_t failed_writes() const;
  const std::filesystem::path& directory() const { return directory_; }

 private:
  std::filesystem::path directory_;
  std::size_t max_files_;
  mutable std::mutex mutex_;
  std::size_t recorded_ = 0;
  std::size_t failed_ = 0;
  std::set<std::filesystem::path> files_;
};

}  // namespace dovetail::collision
