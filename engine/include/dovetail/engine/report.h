#pragma once
/// \file report.h
/// The report of a simulation run: event timeline, per-pair contact
/// statistics and the state hash, written as JSON; wall-clock timings kept
/// apart; and a progress meter for long headless runs.
///
/// Why: a report is what a regression test compares, so it must be the same
/// bits for the same input whatever the thread count or the machine's speed.
/// Everything in it is derived from simulated state; per-frame wall-clock
/// times, which differ run to run, are written only on request, to their own
/// section or file.

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "dovetail/collision/types.h"
#include "dovetail/engine/events.h"

namespace dovetail::engine {

class Scene;

/// Contact statistics of one pair of parts over a run.
struct PairContactStats {
  std::string a{};  ///< first part, a < b by name
  std::string b{};
  std::uint64_t frames_in_contact = 0;
  std::uint64_t first_frame = 0;   ///< first frame in contact
  std::uint64_t last_frame = 0;    ///< last frame in contact
  std::uint64_t max_contacts = 0;  ///< most contacts (triangle pairs) in one frame
  friend bool operator==(const PairContactStats&, const PairContactStats&) = default;
};

/// How the collision pipeline decided one pair of parts, and why
/// (collision::PairPlan), as the report states it.
struct PairPlanReport {
  std::string a{};  ///< first part, a < b by name
  std::string b{};
  std::string level{};        ///< box, hull or exact
  std::string method{};       ///< the polygon level's hierarchy (exact level), else empty
  bool convex_level = false;  ///< the separating-plane test runs first
  bool front = false;         ///< box pairs found apart kept from step to step
  double max_size = 0;        ///< the polygon level's tolerance cut, metres (0: exact)
  std::string reason{};
  friend bool operator==(const PairPlanReport&, const PairPlanReport&) = default;
};

/// Wall-clock cost of one frame; not deterministic, never part of the report proper.
struct FrameTiming {
  double collision_ms = 0;  ///< the collision pipeline
  double total_ms = 0;      ///< the whole frame
};

/// What a run produced.
struct Report {
  double time_step = 0;
  std::uint64_t frames = 0;  ///< frames simulated
  std::size_t parts = 0;     ///< parts in the scene at the end
  std::uint64_t state_hash = 0;
  std::vector<Event> events;               ///< the timeline, in delivery order
  std::vector<PairContactStats> contacts;  ///< sorted by (a, b)
  /// The plan of every pair the collision pipeline tested, sorted by (a, b).
  std::vector<PairPlanReport> plans;
  /// Things a reader should know (a joint angle clamped to its limit, ...),
  /// in the order noticed.
  std::vector<std::string> notes;
  std::vector<FrameTiming> timings;  ///< one per frame

  /// The report as JSON (see docs/engine.md); with_timings appends the
  /// non-deterministic "timings" section.
  std::string to_json(bool with_timings = false) const;
  /// Writes to_json to `path`; throws std::runtime_error naming the path.
  void write_json(const std::filesystem::path& path, bool with_timings = false) const;
  /// Writes only the timings (summary and per-frame) as JSON.
  void write_timings_json(const std::filesystem::path& path) const;
  /// The timings section alone.
  std::string timings_json() const;
};

/// FNV-1a 64-bit offset basis, the state hash's starting value.
inline constexpr std::uint64_t kFnvOffset = 0xcbf29ce484222325ull;

/// Hash of all part poses bit for bit, word by word: starting from
/// kFnvOffset, each 64-bit word w gives h = (h ^ w) * 0x100000001b3, then
/// h ^= h >> 32. The words are, for each part in name order, its name and a
/// 0 byte as little-endian 8-byte words (the last zero-padded), then the 12
/// doubles of its world pose (R row by row, then t) as IEEE-754 bit patterns.
/// Each step is a bijection of h, so a change in any one bit changes it.
std::uint64_t state_hash(const Scene& scene);

/// The state hash folded one part at a time: add() every part in name order
/// with its world pose, and value() is state_hash of that scene.
class StateHasher {
 public:
  void add(std::string_view name, const collision::Transform& X_WP);
  std::uint64_t value() const { return hash_; }

 private:
  void word(std::uint64_t w) {
    hash_ = (hash_ ^ w) * 0x100000001b3ull;
    hash_ ^= hash_ >> 32;
  }
  std::uint64_t hash_ = kFnvOffset;
};

/// Shows progress of a run on stderr: a bar redrawn in place on a terminal,
/// otherwise a plain line "frame k/N" every few seconds.
class ProgressMeter {
 public:
  /// `out` defaults to stderr; the terminal test is isatty on it.
  explicit ProgressMeter(std::uint64_t total, std::FILE* out = nullptr);
  /// Reports that `done` frames are finished; cheap when nothing is printed.
  void update(std::uint64_t done);
  /// Prints the final state (and ends the bar's line).
  void finish();

 private:
  std::uint64_t total_;
  std::FILE* out_;
  bool terminal_;
  double last_print_s_ = -1;
  double start_s_ = 0;
  int last_percent_ = -1;
};

}  // namespace dovetail::engine
