#pragma once
/// \file scenario_run.h
/// Running a scenario headless: the scene, the hand and its glove, the rules
/// and steps frame by frame, the expectations at the end, and the report.
///
/// Why: `dovetail run`, `replay` and `regress` all do the same thing, and a
/// regression is only worth something if the same scenario and trace give
/// the same report bits at any thread count. Rules see each frame's sorted
/// events and fire in file order; what they change applies at the start of
/// the next frame, so rules cannot cascade within a frame; every time is
/// simulation time. A scenario that fails to load or whose script fails
/// still gets a report, with the error and everything up to it.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dovetail/collision/model.h"
#include "dovetail/engine/pose_list.h"
#include "dovetail/engine/render.h"
#include "dovetail/engine/report.h"
#include "dovetail/scripting/lua_host.h"
#include "dovetail/scripting/scenario.h"

namespace dovetail::scripting {

/// How to run a scenario.
struct RunOptions {
  int threads = 1;  ///< collision worker threads; the report does not depend on them
  /// Replays this glove trace instead of the scenario's own glove.
  std::optional<std::filesystem::path> trace{};
  /// Writes the glove samples the run used here, as a trace.
  std::optional<std::filesystem::path> record{};
  /// Writes PNGs here: every `render_every`-th frame (0: none) and final.png.
  /// The frame files an earlier run left here are removed first, once the
  /// scenario has loaded and its outputs are known to be writable.
  std::optional<std::filesystem::path> render_dir{};
  std::uint64_t render_every = 0;
  int render_width = 960;
  int render_height = 720;
  bool progress = false;  ///< a progress meter on stderr
  /// Failure capture (collision/capture.h): suspect collision queries are
  /// written into this folder; `cross_check` decides every exact pair a second
  /// time with that method. The report does not depend on either.
  std::optional<std::filesystem::path> capture_dir{};
  std::optional<collision::Method> cross_check{};
  SandboxLimits limits{};
  /// Every pair on this polygon-level hierarchy instead of the planned one
  /// (collision::PairPlan); for comparisons.
  std::optional<collision::Method> method{};
  /// Overrides the scenario's accuracy: metres, 0 exact.
  std::optional<double> tolerance_m{};
  /// Files the caller writes after the run (the report). The run refuses to
  /// start, as it does for `record`, when one of them is a file the scenario
  /// reads (load_scenario's files_read) or the trace: it would be overwritten.
  std::vector<std::filesystem::path> outputs{};
  /// Stops the run at the first frame at or after this simulated time and
  /// keeps that frame's scene in RunOutcome::picture; the expectations are
  /// not judged (`dovetail render SCENARIO --time T`). A run that ends, or
  /// fails, before it is an error.
  std::optional<double> picture_at{};
};

/// Whether `name` is that of a frame file a run writes into its render
/// folder: frame_NNNNNN.png, six digits or more.
bool is_frame_file_name(std::string_view name);

/// The version of the scenario report RunOutcome::to_json writes.
inline constexpr int kScenarioReportVersion = 1;

/// The name of the scenario's own camera among RunOutcome::picture's cameras.
inline constexpr const char* kScenarioCamera = "scenario";

/// One expectation's verdict.
struct ExpectationOutcome {
  std::string text{};  ///< as written: `max_penetration(0.01)`
  SourceLocation where{};
  bool passed = false;
  /// Why it failed (or what was measured): which parts, at what time.
  std::string detail{};
};

/// A step as it went.
struct StepOutcome {
  std::string name{};
  std::optional<double> done_at{};  ///< simulated seconds
  bool out_of_order = false;
};

/// A line a rule wrote (log, warn, fail) or a violation noticed.
struct Message {
  double time = 0;
  std::string level{};  ///< "log", "warn", "fail", "violation"
  std::string text{};
  SourceLocation where{};
};

/// What a run found.
struct RunOutcome {
  enum class Status { kPassed, kFailed, kError };
  Status status = Status::kError;
  std::string name{};  ///< the scenario's name (or the file's stem before it loaded)
  std::filesystem::path file{};
  std::string error{};  ///< kError: why the run could not go on (file:line: ...)
  std::vector<ExpectationOutcome> expectations{};
  std::vector<StepOutcome> steps{};
  std::vector<Message> messages{};
  std::vector<std::string> warnings{};  ///< from loading
  /// Deepest overlap of two parts over the run (metres), when and between which.
  double max_penetration = 0;
  double max_penetration_time = 0;
  std::string max_penetration_a{}, max_penetration_b{};
  std::uint64_t rules_fired = 0;
  /// Where every part ended (the hand's segments left out), in scene order:
  /// its origin in metres and its rotation as a unit quaternion (w >= 0).
  struct PartPose {
    std::string part{};
    collision::Vec3 position{collision::Vec3::Zero()};
    engine::Quaternion rotation{};
  };
  std::vector<PartPose> final_poses{};
  double metres_per_unit = 0.001;
  std::string units = "mm";
  engine::Report report{};  ///< the simulation's report (timeline, contacts, state hash)
  double wall_seconds = 0;  ///< the whole run, loading included; not in the JSON report
  /// The frame loop alone (simulation, rules, steps, penetration), for benchmarks.
  double loop_seconds = 0;
  std::optional<std::filesystem::path> final_frame{};  ///< the PNG written, if any
  /// Frame files an earlier run left in RunOptions::render_dir, removed.
  std::size_t old_frames_removed = 0;
  /// With RunOptions::picture_at: the frame the run stopped at.
  struct Picture {
    engine::RenderScene scene{};  ///< the scenario's camera among its cameras as kScenarioCamera
    double time = 0;
    std::uint64_t frame = 0;
    bool hand = false;  ///< whether the scene has the hand
  };
  std::optional<Picture> picture{};
  /// The run did not start because an output is a file it reads (`error`
  /// says which); the caller must not write its outputs either.
  bool outputs_refused = false;
  /// With RunOptions::capture_dir: the capture files written, and how many
  /// suspect queries there were (repeats of one capture write one file).
  /// Not in the JSON report.
  std::vector<std::filesystem::path> captures{};
  std::size_t suspect_queries = 0;

  /// The report as JSON: deterministic, no wall-clock times (docs/authoring.md, "Reports").
  std::string to_json() const;
  /// One line per failed expectation, error or violation, for stderr.
  std::string failure_summary() const;
};
std::string_view status_name(RunOutcome::Status status);

/// Loads and runs the scenario at `file`. Never throws for a bad scenario or
/// a failing script: those end as Status::kError with the message. Throws
/// only for failures of the host itself (an output that cannot be written).
RunOutcome run_scenario(const std::filesystem::path& file, const RunOptions& options = {});

/// Loads and resolves the scenario without simulating (`dovetail check`);
/// throws ScenarioError or ScriptError.
Scenario check_scenario(const std::filesystem::path& file, const SandboxLimits& limits = {});

}  // namespace dovetail::scripting
