#include "dovetail/scripting/scenario_run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <lua.hpp>
#include <map>
#include <optional>
#include <set>

#include "dovetail/collision/contacts.h"
#include "dovetail/collision/containment.h"
#include "dovetail/collision/convex.h"
#include "dovetail/collision/model.h"
#include "dovetail/engine/json.h"
#include "dovetail/engine/paths.h"
#include "dovetail/engine/pose_list.h"
#include "dovetail/engine/render.h"
#include "dovetail/engine/scene_render.h"
#include "dovetail/interaction/glove_plan.h"
#include "dovetail/interaction/glove_trace.h"
#include "dovetail/interaction/grasping.h"
#include "dovetail/interaction/hand.h"
#include "dovetail/interaction/hand_model.h"
#include "dovetail/interaction/overlap.h"
#include "dovetail/scripting/vocabulary.h"

namespace dovetail::scripting {

namespace {

using engine::Event;
using engine::EventKind;
using engine::PartId;

/// What a rule or a step can wait for, after the engine's events have been
/// turned into the scenario's (the hand as one, mates by name, timers).
enum class Happening {
  kTouch,
  kSeparate,
  kGrasp,
  kRelease,
  kMated,
  kSlide,
  kEnter,
  kLeave,
  kCompleted,
  kArrive
};

struct Occurrence {
  Happening kind;
  std::string a{}, b{};
};

/// Seconds to the millisecond; beyond a billion seconds in six digits.
std::string format_time(double t) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, std::abs(t) < 1e9 ? "%.3f" : "%.6g", t);
  return buffer;
}

/// When a trace starts (its first sample's time), 0 for a plan.
double start_time(const interaction::GloveSource& source) {
  const auto* trace = dynamic_cast<const interaction::TraceSource*>(&source);
  return trace ? trace->samples().front().t : 0;
}

/// A length in metres, in the scenario's units ("12.5 mm").
std::string format_length(double metres, double metres_per_unit, const std::string& units) {
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "%.4g %s", metres / metres_per_unit, units.c_str());
  return buffer;
}

/// Warnings about a glove that cannot be what was meant, each starting with
/// `who`: a hand that goes far from every part (a plan written in
/// millimetres reads as metres); joints far outside their ranges (another
/// unit, or a column misnamed); a trace (read from `trace`) sampled too
/// sparsely or cut short; times on a device's clock; a hand that holds a
/// part it starts far from (the part keeps that offset).
/// Frames at t = 0, dt, 2 dt, ... up to the first at or after the end, so
/// that a rule at the end time (after(duration)) has its frame.
std::uint64_t frame_count(const Scenario& scenario, double end_time) {
  return static_cast<std::uint64_t>(std::ceil(end_time / scenario.time_step - 1e-9)) + 1;
}

/// When a run ends: at the scenario's duration; without one, at the glove's
/// last sample, a second later for a plan (its hand comes to rest) and at
/// once for a trace; 1 s without a glove.
double run_end_time(const Scenario& scenario, const interaction::GloveSource* source, bool trace) {
  if (scenario.duration) return *scenario.duration;
  if (!source) return 1;
  return source->end_time() + (trace ? 0 : 1);
}

/// The time of the run's last frame (frame_count).
double last_frame_time(const Scenario& scenario, double end_time) {
  return static_cast<double>(frame_count(scenario, end_time) - 1) * scenario.time_step;
}

/// Steps and rules waiting for after(t) with t past the run's last frame,
/// which never comes: they can never happen.
std::vector<std::string> never_after(const Scenario& scenario, double last_time) {
  std::vector<std::string> out;
  const auto check = [&](const Clause& c, const std::string& context) {
    if (c.word->name == "after" && c.args[0].number > last_time + 1e-9) {
      out.push_back(c.where.str() + ": " + context + c.text +
                    " can never happen: the run ends at t=" + format_time(last_time) + " s");
    }
  };
  for (const StepSpec& step : scenario.steps) {
    if (step.done) check(*step.done, "step '" + step.name + "': ");
  }
  for (const RuleSpec& rule : scenario.rules) check(rule.when, "rule: ");
  return out;
}

std::vector<std::string> glove_warnings(const Scenario& scenario, const GloveSpec& glove,
                                        const interaction::GloveSource& source,
                                        const std::string& who,
                                        const std::filesystem::path& trace) {
  std::vector<std::string> out;
  const auto length = [&](double metres) {
    return format_length(metres, scenario.metres_per_unit, scenario.units);
  };
  const auto box_of = [&](const PartSpec& p) {
    Eigen::AlignedBox<double, 3> box;
    if (p.mesh) {
      for (const Vec3& v : p.mesh->vertices) box.extend(p.X_WP.apply(v));
    }
    return box;
  };
  Eigen::AlignedBox<double, 3> parts;
  for (const PartSpec& p : scenario.parts) parts.extend(box_of(p));
  if (parts.isEmpty()) return out;
  // Farther than ten times the parts' size, and a metre, from all of them.
  const double limit = std::max(1.0, 10 * parts.diagonal().norm());
  double farthest = 0, when = 0;
  constexpr int kSamples = 200;
  for (int k = 0; k <= kSamples; ++k) {
    const double t = source.end_time() * k / kSamples;
    const double d = parts.exteriorDistance(source.sample(t).p_WH);
    if (d > farthest) farthest = d, when = t;
  }
  if (farthest > limit) {
    out.push_back(who + ": the hand is " + length(farthest) +
                  " from every part at t=" + format_time(when) +
                  " s; plans and traces are in metres: is it written in other units?");
  }
  if (const auto* samples = dynamic_cast<const interaction::TraceSource*>(&source)) {
    // A glove's noise goes a degree or two past a joint's range; tens of
    // degrees are another unit or another column: a warning per joint.
    for (const interaction::JointExcursion& e :
         interaction::joints_outside(samples->samples(), interaction::kFarOutsideRange)) {
      out.push_back(who + ": " + interaction::describe(e) +
                    " (clamped): is the trace in other units, or a column misnamed?");
    }
    if (!trace.empty()) {
      for (const std::string& doubt : interaction::trace_doubts(trace, samples->samples())) {
        out.push_back(who + ": " + doubt);
      }
    }
  }
  const double start = start_time(source);
  if (start < 0) {
    out.push_back(who + ": the trace starts at t=" + format_time(start) +
                  " s; what it holds before t=0 is not used (the run starts at 0)");
  }
  // Device clocks (seconds since 1970) instead of seconds from the start of the run.
  if (start > 1) {
    out.push_back(who + ": the trace starts at t=" + format_time(start) +
                  " s; until then the hand stays at its first sample (its times are seconds "
                  "from the start of the run: shift them to start at 0)");
  }
  // A plan cut short by the scenario's duration: the hand stops where it is.
  if (trace.empty() && scenario.duration &&
      source.end_time() > last_frame_time(scenario, *scenario.duration) + 1e-9) {
    out.push_back(who + ": the plan runs to t=" + format_time(source.end_time()) +
                  " s, past the scenario's duration (" + format_time(*scenario.duration) +
                  " s): the run ends before the hand has done it");
  }
  if (!glove.holding.empty()) {
    for (const PartSpec& p : scenario.parts) {
      if (p.name != glove.holding) continue;
      const double d = box_of(p).exteriorDistance(source.sample(0).p_WH);
      if (d > 0.5) {
        out.push_back(who + ": the hand starts " + length(d) + " from '" + glove.holding +
                      "', which it holds; the part keeps that offset");
      }
    }
  }
  return out;
}

std::string format_length(double metres, const RunOutcome& o) {
  return format_length(metres, o.metres_per_unit, o.units);
}

/// The same pose, to the bit.
bool same(const Transform& x, const Transform& y) { return x.R == y.R && x.t == y.t; }

/// The region as the engine watches it: "hand" among its parts stands for
/// every segment of the hand named `hand` (whose events the hand merges
/// into its own).
engine::Region with_hand_segments(engine::Region region, const std::string& hand) {
  if (std::erase(region.parts, "hand") == 0) return region;
  for (std::size_t i = 0; i < interaction::kSegmentCount; ++i) {
    region.parts.push_back(
        hand + "." + std::string(interaction::segment_name(static_cast<interaction::Segment>(i))));
  }
  return region;
}

std::pair<std::string, std::string> ordered(const std::string& a, const std::string& b) {
  return a < b ? std::pair(a, b) : std::pair(b, a);
}

/// When a glove file of the other kind was given (a plan where a trace
/// belongs, or a trace where a plan does), what to do instead; else empty.
/// Judged by the other kind's reader taking it.
std::string other_kind_of_glove_file(const std::filesystem::path& file, bool trace_expected) {
  try {
    if (trace_expected) {
      interaction::read_plan(file);
      return " (" + file.filename().string() +
             " is a glove plan, which a scenario names as glove { plan = \"...\" }; a trace, "
             "as replay, --trace and glove { trace = \"...\" } take, is a recorded CSV file)";
    }
    interaction::read_trace(file);
    return " (" + file.filename().string() +
           " is a glove trace, CSV, which a scenario names as glove { trace = \"...\" })";
  } catch (const std::exception&) {
    return "";  // of neither kind: the reader's own message says what is wrong
  }
}

/// The glove's samples: the trace to replay when given, else the glove's
/// trace or plan, with its noise. Errors name the file (and line) and, for
/// the scenario's own file, the glove that asked for it.
std::shared_ptr<const interaction::GloveSource> glove_source(
    const Scenario& scenario, const std::optional<std::filesystem::path>& replay) {
  const GloveSpec glove = scenario.glove.value_or(GloveSpec{});
  std::shared_ptr<const interaction::GloveSource> source;
  try {
    if (replay) {
      source = std::make_shared<interaction::TraceSource>(interaction::read_trace(*replay));
    } else if (!glove.trace.empty()) {
      source = std::make_shared<interaction::TraceSource>(interaction::read_trace(glove.trace));
    } else {
      source = std::make_shared<interaction::SimulatedGlove>(interaction::read_plan(glove.plan));
    }
  } catch (const std::exception& e) {
    // The file's own message names it (and its line); say which glove asked
    // for it, and what to give when it is a file of the other kind.
    const bool trace = replay || !glove.trace.empty();
    const std::string hint = other_kind_of_glove_file(replay  ? *replay
                                                      : trace ? glove.trace
                                                              : glove.plan,
                                                      trace);
    throw ScenarioError(
        (replay ? std::string(e.what()) : glove.where.str() + ": glove: " + e.what()) + hint);
  }
  if (glove.noise && !replay)
    source = std::make_shared<interaction::NoisyGlove>(source, *glove.noise);
  // Without a duration the run lasts as long as the glove: no longer than a
  // scenario's duration may be.
  if (!scenario.duration && !(source->end_time() <= kMaxRunSeconds)) {
    const bool trace = replay || !glove.trace.empty();
    const std::filesystem::path& file = replay ? *replay : trace ? glove.trace : glove.plan;
    const double start = start_time(*source);
    // What else is doubtful about a trace (times in milliseconds) is its likelier cause.
    std::string doubts;
    if (const auto* samples = dynamic_cast<const interaction::TraceSource*>(source.get())) {
      if (const auto sparse = interaction::sparse_samples(samples->samples())) {
        doubts = "; " + *sparse;
      }
    }
    // A trace on a device clock fits once its times are shifted; a longer
    // take can only be cut short.
    std::string advice = doubts;
    if (advice.empty() && start > 1 && source->end_time() - start <= kMaxRunSeconds) {
      char exact[40];  // the start to the digit, which the shift needs
      std::snprintf(exact, sizeof exact, "%.15g", start);
      advice = "; shift its times to start at 0 (subtract " + std::string(exact) + " s from each)";
    } else if (advice.empty()) {
      advice = "; a scenario's duration (at most " + format_time(kMaxRunSeconds) +
               " s) replays its first part only";
    }
    throw ScenarioError(
        (replay ? std::string() : glove.where.str() + ": glove: ") + file.string() + ": the " +
        (trace ? "trace" : "plan") + " ends at t=" + format_time(source->end_time()) + " s" +
        (start > 1 ? " (it starts at t=" + format_time(start) +
                         " s; its times are seconds from the start of the run)"
                   : std::string()) +
        ", later than the " + format_time(kMaxRunSeconds) + " s a run may last" + advice);
  }
  return source;
}

constexpr const char* kRunnerKey = "dovetail.runner";
constexpr std::array<float, 3> kHighlight = {1.0F, 0.55F, 0.0F};

class Runner {
 public:
  Runner(const std::filesystem::path& file, const RunOptions& options, RunOutcome& outcome)
      : file_(file), options_(options), out_(outcome), host_(options.limits, 1) {}

  void run();

  // ---- the low-level API of custom actions (called from Lua through C functions)
  /// Fills `error` and returns false for an unknown part.
  bool part_pose(const char* name, Transform& X, char* error, std::size_t size);
  bool set_part_pose(const char* name, const Transform& X, char* error, std::size_t size);
  /// Fills `error` for an unknown part: its name and the nearest the scenario declares.
  void no_part(const char* name, char* error, std::size_t size) const;
  /// The time of the frame whose start runs the action (or of the last
  /// frame, for actions applied after it).
  double time() const { return action_time_; }
  void log(std::string text) {
    out_.messages.push_back({time(), "log", std::move(text), current_where_});
  }
  double metres_per_unit() const { return scenario_.metres_per_unit; }

 private:
  /// Why an output (the recording, RunOptions::outputs) may not be written:
  /// it is a file the run reads.
  std::optional<std::string> output_read() const;
  void refuse_outputs();
  void build();
  void warn_about_glove(const GloveSpec& glove, const interaction::GloveSource& source);
  void start_frame(std::uint64_t frame, double t);
  void end_frame(const engine::FrameResult& result, double previous_time);
  std::vector<Occurrence> occurrences(const engine::FrameResult& result);
  bool matches(const Clause& when, const Occurrence& o) const;
  bool timer_fires(const Clause& when, double now, double previous) const;
  bool holds(const Clause& state) const;
  bool near(const interaction::Mate& mate) const;
  void complete_step(std::size_t index, double now, std::vector<Occurrence>& occurrences);
  void apply(const Clause& action, double now);
  void measure_penetration(double now);
  /// Each mate's closest approach so far, and the snaps refused this frame as warnings.
  void watch_mates(double now);
  /// Why a mate never snapped, for its expectation: a refused snap, or how
  /// close its part came to its place against the tolerances.
  std::string why_not_snapped(const MateSpec& mate) const;
  /// For a grasp never made: the other parts the hand touched at its closest
  /// try at `part` (a table under a bar stops the fingers), or empty.
  std::string also_touched_then(const std::string& part) const;
  void evaluate_expectations();
  /// Draws the scene to `path`: the frames of --every from one camera, fitted
  /// to the first; the final picture from one fitted to the final scene (so
  /// that it does not depend on --every), unless the scenario has a camera.
  void render(const std::filesystem::path& path, bool final_picture);
  /// Keeps the scene of this frame in out_.picture (RunOptions::picture_at).
  void take_picture(std::uint64_t frame, double time);
  const MateSpec* mate(const std::string& name) const;

  std::filesystem::path file_;
  RunOptions options_;
  RunOutcome& out_;
  LuaHost host_;
  Scenario scenario_;
  std::vector<std::filesystem::path> files_read_;    ///< by the loader, even when it fails
  std::unique_ptr<collision::CaptureSink> capture_;  ///< outlives the simulation's world
  std::unique_ptr<engine::Simulation> sim_;
  std::unique_ptr<interaction::Hand> hand_;
  std::unique_ptr<interaction::Grasping> grasping_;

  std::set<std::pair<std::string, std::string>>
      touching_;  ///< part pairs in contact, ordered names
  /// Per part pair: how many of (contact, sliding) hold; touching while > 0.
  std::map<std::pair<std::string, std::string>, int> contact_sources_;
  std::map<std::string, int> hand_touching_;              ///< part -> hand segments touching it
  std::set<std::pair<std::string, std::string>> inside_;  ///< (part, region)
  std::map<std::pair<std::string, std::string>, double> first_contact_;
  std::vector<std::optional<double>> step_done_;
  std::vector<std::size_t> completion_order_;  ///< step indices in the order completed
  std::vector<std::optional<double>> rule_last_;
  std::vector<std::pair<const Clause*, double>> pending_;  ///< actions for the next frame
  double action_time_ = 0;                                 ///< see time()
  std::set<std::string> carried_ever_;                     ///< every part the hand has carried
  std::vector<std::size_t> forced_steps_;                  ///< `complete` actions this frame
  std::vector<Event> injected_;                            ///< `snap` mate events this frame
  /// Per mate: the poses of its part and other part when it last fired `mated`.
  std::map<std::string, std::pair<Transform, Transform>> seated_;
  struct Motion {
    std::string part;
    Vec3 from, to;
    double t0, t1;
    SourceLocation where;  ///< the move's action
  };
  std::vector<Motion> motions_;
  std::vector<std::string> arrived_;  ///< parts whose move ended this frame, in order
  /// Per mate (by index): the frame its part came closest to its place.
  struct Closest {
    interaction::MateOffset offset;
    double time = 0;
    bool seen = false;
  };
  std::vector<Closest> closest_;
  /// Per mate (by index): where its part was when the hand last let it go.
  std::vector<Closest> released_;
  std::set<std::string> carried_now_;  ///< the parts the hand carried in the last frame
  std::size_t refusals_seen_ = 0;      ///< of grasping_->refused_snaps(), written as warnings
  interaction::OverlapGauge overlap_;  ///< max_penetration's measure
  std::optional<engine::Camera> camera_;
  /// Poses at which each touching pair's depth was last measured.
  std::map<std::pair<std::string, std::string>, std::optional<std::pair<Transform, Transform>>>
      measured_;
  SourceLocation current_where_{};
  bool failed_by_rule_ = false;
  /// In the frame after the last, which only finishes the last frame's
  /// actions: timers (after, every) are past the run's end and do not fire.
  bool past_end_ = false;
};

// ---- Lua side of the low-level API. These functions hold no C++ object with a
// destructor when they raise a Lua error (Lua unwinds with longjmp).

Runner* runner_of(lua_State* L) {
  lua_getfield(L, LUA_REGISTRYINDEX, kRunnerKey);
  auto* runner = static_cast<Runner*>(lua_touserdata(L, -1));
  lua_pop(L, 1);
  return runner;
}

const char* part_name_of(lua_State* L) {
  luaL_checktype(L, 1, LUA_TTABLE);
  lua_rawgeti(L, 1, 1);
  const char* name = lua_tostring(L, -1);
  lua_pop(L, 1);
  if (name == nullptr) luaL_error(L, "call part methods with ':' : dt.part(\"peg\"):translation()");
  return name;
}

int api_translation(lua_State* L) {
  const char* name = part_name_of(L);
  Runner* runner = runner_of(L);
  Transform X;
  char error[256];
  if (!runner->part_pose(name, X, error, sizeof error)) return luaL_error(L, "%s", error);
  const double s = 1 / runner->metres_per_unit();
  lua_pushnumber(L, X.t.x() * s);
  lua_pushnumber(L, X.t.y() * s);
  lua_pushnumber(L, X.t.z() * s);
  return 3;
}

int api_set_translation(lua_State* L) {
  const char* name = part_name_of(L);
  const double x = luaL_checknumber(L, 2), y = luaL_checknumber(L, 3), z = luaL_checknumber(L, 4);
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
    return luaL_error(L, "set_translation: coordinates must be finite");
  }
  Runner* runner = runner_of(L);
  constexpr double kCoordinateLimit_m = 1e30;  // the scenario's and the pose lists'
  if (std::max({std::abs(x), std::abs(y), std::abs(z)}) * runner->metres_per_unit() >
      kCoordinateLimit_m) {
    return luaL_error(L, "set_translation: a coordinate is beyond the limit of 1e30 m");
  }
  Transform X;
  char error[256];
  if (!runner->part_pose(name, X, error, sizeof error)) return luaL_error(L, "%s", error);
  X.t = Vec3(x, y, z) * runner->metres_per_unit();
  if (!runner->set_part_pose(name, X, error, sizeof error)) return luaL_error(L, "%s", error);
  return 0;
}

int api_matrix(lua_State* L) {
  const char* name = part_name_of(L);
  Runner* runner = runner_of(L);
  Transform X;
  char error[256];
  if (!runner->part_pose(name, X, error, sizeof error)) return luaL_error(L, "%s", error);
  lua_createtable(L, 16, 0);
  const double s = 1 / runner->metres_per_unit();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      const double v = r == 3 ? (c == 3 ? 1 : 0) : c == 3 ? X.t[r] * s : X.R(r, c);
      lua_pushnumber(L, v);
      lua_rawseti(L, -2, 4 * r + c + 1);
    }
  }
  return 1;
}

int api_set_matrix(lua_State* L) {
  const char* name = part_name_of(L);
  luaL_checktype(L, 2, LUA_TTABLE);
  double m[16];
  for (int i = 0; i < 16; ++i) {
    lua_rawgeti(L, 2, i + 1);
    if (lua_type(L, -1) != LUA_TNUMBER)
      return luaL_error(L, "set_matrix: needs 16 numbers, row by row");
    m[i] = lua_tonumber(L, -1);
    lua_pop(L, 1);
    if (!std::isfinite(m[i])) return luaL_error(L, "set_matrix: numbers must be finite");
  }
  if (lua_rawlen(L, 2) != 16) return luaL_error(L, "set_matrix: needs 16 numbers, row by row");
  if (m[12] != 0 || m[13] != 0 || m[14] != 0 || m[15] != 1) {
    return luaL_error(L, "set_matrix: the last row must be 0, 0, 0, 1");
  }
  Runner* runner = runner_of(L);
  Transform X;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) X.R(r, c) = m[4 * r + c];
    X.t[r] = m[4 * r + 3] * runner->metres_per_unit();
  }
  const double orthogonality = (X.R.transpose() * X.R - collision::Mat3::Identity()).norm();
  if (!(orthogonality < 1e-6) || X.R.determinant() < 0) {
    return luaL_error(L, "set_matrix: the upper 3x3 is not a rotation");
  }
  char error[256];
  if (!runner->set_part_pose(name, X, error, sizeof error)) return luaL_error(L, "%s", error);
  return 0;
}

int api_part(lua_State* L) {
  const char* name = luaL_checkstring(L, 1);
  Runner* runner = runner_of(L);
  Transform X;
  char error[256];
  if (!runner->part_pose(name, X, error, sizeof error)) return luaL_error(L, "%s", error);
  lua_createtable(L, 1, 0);
  lua_pushstring(L, name);
  lua_rawseti(L, -2, 1);
  lua_getfield(L, LUA_REGISTRYINDEX, "dovetail.part_methods");
  lua_setmetatable(L, -2);
  return 1;
}

int api_time(lua_State* L) {
  lua_pushnumber(L, runner_of(L)->time());
  return 1;
}

int api_log(lua_State* L) {
  std::size_t length = 0;
  const char* text = luaL_checklstring(L, 1, &length);
  runner_of(L)->log(std::string(text, length));  // no error raised after the copy
  return 0;
}

/// __index of the method table and of `dt` (upvalue 1: what it is, "a part"
/// or "dt"): a name neither has is an error with the nearest name, where Lua
/// would only say "attempt to call a nil value".
int api_unknown(lua_State* L) {
  const char* what = lua_tostring(L, lua_upvalueindex(1));
  if (lua_type(L, 2) != LUA_TSTRING) return luaL_error(L, "%s has no such field", what);
  {
    // The message is built, and its C++ objects gone, before Lua's error
    // unwinds this frame (a longjmp, which runs no destructor).
    const std::string name = lua_tostring(L, 2);
    std::vector<std::string> known;
    lua_pushnil(L);
    while (lua_next(L, 1) != 0) {
      if (lua_type(L, -2) == LUA_TSTRING) known.emplace_back(lua_tostring(L, -2));
      lua_pop(L, 1);
    }
    std::sort(known.begin(), known.end());
    const std::string message =
        std::string(what) + " has no '" + name + "'" + did_you_mean(name, known);
    luaL_where(L, 1);
    lua_pushlstring(L, message.data(), message.size());
    lua_concat(L, 2);
  }
  return lua_error(L);
}

/// Makes the table on top of the stack raise api_unknown for names it lacks.
void refuse_unknown_names(lua_State* L, const char* what) {
  lua_createtable(L, 0, 2);
  lua_pushstring(L, what);
  lua_pushcclosure(L, api_unknown, 1);
  lua_setfield(L, -2, "__index");
  lua_pushboolean(L, 0);
  lua_setfield(L, -2, "__metatable");
  lua_setmetatable(L, -2);
}

/// Registers the runner and pushes the `dt` table of custom actions.
void push_api(lua_State* L) {
  lua_getfield(L, LUA_REGISTRYINDEX, "dovetail.dt");
  if (lua_type(L, -1) == LUA_TTABLE) return;
  lua_pop(L, 1);
  // Part methods: a protected metatable whose __index is the method table.
  lua_createtable(L, 0, 3);
  lua_createtable(L, 0, 4);
  const luaL_Reg methods[] = {{"translation", api_translation},
                              {"set_translation", api_set_translation},
                              {"matrix", api_matrix},
                              {"set_matrix", api_set_matrix},
                              {nullptr, nullptr}};
  luaL_setfuncs(L, methods, 0);
  refuse_unknown_names(L, "a part");
  lua_setfield(L, -2, "__index");
  lua_pushboolean(L, 0);
  lua_setfield(L, -2, "__metatable");
  lua_setfield(L, LUA_REGISTRYINDEX, "dovetail.part_methods");
  lua_createtable(L, 0, 3);
  const luaL_Reg functions[] = {
      {"part", api_part}, {"time", api_time}, {"log", api_log}, {nullptr, nullptr}};
  luaL_setfuncs(L, functions, 0);
  refuse_unknown_names(L, "dt");
  lua_pushvalue(L, -1);
  lua_setfield(L, LUA_REGISTRYINDEX, "dovetail.dt");
}

// ---- the runner

void Runner::no_part(const char* name, char* error, std::size_t size) const {
  std::vector<std::string> parts;
  for (const PartSpec& p : scenario_.parts) parts.push_back(p.name);
  std::snprintf(error, size, "dt.part: no part '%s'%s", name, did_you_mean(name, parts).c_str());
}

bool Runner::part_pose(const char* name, Transform& X, char* error, std::size_t size) {
  const PartId p = sim_->scene().find(name);
  if (!p.valid()) {
    no_part(name, error, size);
    return false;
  }
  X = sim_->scene().world_pose(p);
  return true;
}

bool Runner::set_part_pose(const char* name, const Transform& X, char* error, std::size_t size) {
  const PartId p = sim_->scene().find(name);
  if (!p.valid()) {
    no_part(name, error, size);
    return false;
  }
  if (!sim_->scene().movable(p)) {
    std::snprintf(error, size, "dt.part: '%s' is fixed", name);
    return false;
  }
  sim_->scene().set_world_pose(p, X);
  return true;
}

const MateSpec* Runner::mate(const std::string& name) const {
  for (const MateSpec& m : scenario_.mates) {
    if (m.mate.name == name) return &m;
  }
  return nullptr;
}

void Runner::build() {
  engine::Scene scene;
  for (const PartSpec& p : scenario_.parts) {
    engine::PartDef desc;
    desc.name = p.name;
    desc.tags = p.tags;
    desc.X_QP = p.X_WP;
    desc.movable = !p.fixed;
    desc.render_mesh = p.mesh;
    desc.color = p.color;
    scene.add_part(desc);
  }
  for (const PartSpec& p : scenario_.parts) {
    if (!p.attached_to.empty()) scene.set_parent(scene.get(p.name), scene.get(p.attached_to), true);
  }
  engine::SimulationSettings settings;
  settings.time_step = scenario_.time_step;
  settings.collision_threads = options_.threads;
  settings.method = options_.method;
  settings.tolerance = options_.tolerance_m.value_or(scenario_.tolerance_m);
  if (options_.capture_dir) {
    capture_ = std::make_unique<collision::CaptureSink>(*options_.capture_dir);
    settings.capture = capture_.get();
    settings.cross_check = options_.cross_check;
  }
  sim_ = std::make_unique<engine::Simulation>(std::move(scene), settings);
  // Actions of the last frame, then moves in progress: before the hand and grasping.
  sim_->set_frame_hook(
      [this](engine::Simulation&, std::uint64_t frame, double t) { start_frame(frame, t); });

  if (scenario_.glove || options_.trace) {
    const GloveSpec glove = scenario_.glove.value_or(GloveSpec{});
    const std::shared_ptr<const interaction::GloveSource> source =
        glove_source(scenario_, options_.trace);
    interaction::HandSettings hand_settings;
    hand_settings.model.hand_length = glove.hand_length;
    // Every sample is kept only when the run is recorded (a simulated hour is 80 MB of them).
    hand_settings.record = options_.record.has_value();
    hand_ = std::make_unique<interaction::Hand>(*sim_, source, hand_settings);
    grasping_ = std::make_unique<interaction::Grasping>(*sim_, *hand_);
    // In the file's order: a released sub-assembly is seated by the first
    // of its mates within tolerance (the scenario's mates are in name order).
    std::vector<const MateSpec*> in_file_order;
    for (const MateSpec& m : scenario_.mates) in_file_order.push_back(&m);
    std::stable_sort(
        in_file_order.begin(), in_file_order.end(),
        [](const MateSpec* a, const MateSpec* b) { return a->where.line < b->where.line; });
    for (const MateSpec* m : in_file_order) grasping_->add_mate(m->mate);
    if (!glove.holding.empty()) grasping_->hold(glove.holding, glove.grasp);
    warn_about_glove(glove, *source);
  }
  if (options_.record && !hand_) {
    throw ScenarioError(file_.string() +
                        ": --record: the scenario has no glove, so there are no samples to record");
  }
  // After the hand: a region may watch its segments.
  for (const RegionSpec& r : scenario_.regions) {
    sim_->add_region(with_hand_segments(r.region, interaction::kDefaultHandName));
  }
  // Mates snapped by a rule appear among the frame's events.
  sim_->add_event_filter([this](engine::Simulation&, std::vector<Event>& events) {
    events.insert(events.end(), injected_.begin(), injected_.end());
    injected_.clear();
  });
}

void Runner::warn_about_glove(const GloveSpec& glove, const interaction::GloveSource& source) {
  const std::string who = options_.trace ? options_.trace->string() : glove.where.str() + ": glove";
  const std::filesystem::path trace = options_.trace ? *options_.trace : glove.trace;
  for (std::string& w : glove_warnings(scenario_, glove, source, who, trace)) {
    out_.warnings.push_back(std::move(w));
  }
}

void Runner::start_frame(std::uint64_t, double t) {
  std::vector<std::pair<const Clause*, double>> actions;
  actions.swap(pending_);
  for (const auto& [action, fired] : actions) apply(*action, t);
  engine::Scene& scene = sim_->scene();
  for (auto it = motions_.begin(); it != motions_.end();) {
    const PartId p = scene.find(it->part);
    const double s = it->t1 > it->t0 ? std::clamp((t - it->t0) / (it->t1 - it->t0), 0.0, 1.0) : 1.0;
    if (p.valid()) {
      Transform X = scene.world_pose(p);
      X.t = it->from + (it->to - it->from) * s;
      scene.set_world_pose(p, X);
    }
    if (s >= 1) {
      if (p.valid()) arrived_.push_back(it->part);
      it = motions_.erase(it);
    } else {
      ++it;
    }
  }
}

void Runner::apply(const Clause& action, double now) {
  engine::Scene& scene = sim_->scene();
  const std::string_view w = action.word->name;
  const std::string& a = action.args[0].text;
  current_where_ = action.where;
  if (w == "highlight") {
    scene.set_highlight(scene.get(a), action.args[1].given ? action.args[1].color : kHighlight);
  } else if (w == "unhighlight") {
    scene.set_highlight(scene.get(a), std::nullopt);
  } else if (w == "show" || w == "hide") {
    scene.set_visible(scene.get(a), w == "show");
  } else if (w == "move") {
    const PartId p = scene.get(a);
    if (!scene.movable(p)) {
      out_.messages.push_back({now, "warn", "move: '" + a + "' is fixed and stays", action.where});
      return;
    }
    // A later move replaces an earlier one; two in one frame are two rules
    // at odds, and the one written last wins.
    for (const Motion& m : motions_) {
      if (m.part == a && m.t0 == now) {
        out_.messages.push_back({now, "warn",
                                 "move: '" + a + "' was sent somewhere else in this frame too (" +
                                     m.where.str() + "); this move, written later, wins",
                                 action.where});
      }
    }
    std::erase_if(motions_, [&](const Motion& m) { return m.part == a; });
    const double over = action.args[2].given ? action.args[2].number : 0;
    motions_.push_back(
        {a, scene.world_pose(p).t, action.args[1].vector, now, now + over, action.where});
  } else if (w == "attach") {
    const std::string& to = action.args[1].text;
    if (scene.descends_from(scene.get(to), scene.get(a))) {
      out_.messages.push_back({now, "warn",
                               "attach: '" + to + "' moves with '" + a + "' already; attaching '" +
                                   a + "' to it would make a cycle, so it stays as it was",
                               action.where});
      return;
    }
    scene.set_parent(scene.get(a), scene.get(to), true);
  } else if (w == "detach") {
    scene.set_parent(scene.get(a), PartId{}, true);
  } else if (w == "snap") {
    const interaction::Mate& m = mate(a)->mate;
    const Transform X_WP = scene.world_pose(m.part), X_WO = scene.world_pose(m.other);
    // A fit made already, neither part moved since, stays as it is: `mated`
    // fires once for it.
    if (const auto seated = seated_.find(m.name); seated != seated_.end() &&
                                                  same(seated->second.first, X_WP) &&
                                                  same(seated->second.second, X_WO)) {
      return;
    }
    scene.set_world_pose(scene.get(m.part), interaction::mate_pose(m, X_WP, X_WO));
    injected_.push_back({EventKind::kMate, sim_->frame(), now, m.part, m.other});
  } else if (w == "complete") {
    for (std::size_t i = 0; i < scenario_.steps.size(); ++i) {
      if (scenario_.steps[i].name == a) forced_steps_.push_back(i);
    }
  } else if (w == "custom") {
    action_time_ = now;
    lua_State* L = host_.state();
    lua_rawgeti(L, LUA_REGISTRYINDEX, action.args[0].function_ref);
    push_api(L);
    host_.call(1, 0);
  }
}

bool Runner::near(const interaction::Mate& m) const {
  const engine::Scene& scene = sim_->scene();
  return interaction::within_tolerance(m, scene.world_pose(m.part), scene.world_pose(m.other));
}

bool Runner::holds(const Clause& state) const {
  const std::string_view w = state.word->name;
  const std::string& a = state.args[0].text;
  if (w == "holding") return grasping_ && grasping_->held() && *grasping_->held() == a;
  if (w == "touching") {
    const std::string& b = state.args[1].text;
    if (a == "hand") {
      const auto it = hand_touching_.find(b);
      return it != hand_touching_.end() && it->second > 0;
    }
    const auto it = contact_sources_.find(ordered(a, b));
    return it != contact_sources_.end() && it->second > 0;
  }
  if (w == "near") return near(mate(a)->mate);
  if (w == "done") {
    for (std::size_t i = 0; i < scenario_.steps.size(); ++i) {
      if (scenario_.steps[i].name == a) return step_done_[i].has_value();
    }
    return false;
  }
  if (w == "inside") return inside_.count({a, state.args[1].text}) != 0;
  return false;
}

std::vector<Occurrence> Runner::occurrences(const engine::FrameResult& result) {
  const engine::Scene& scene = sim_->scene();
  std::vector<Occurrence> out;
  // Moves ended at the start of this frame: the parts are where they were sent.
  for (std::string& part : arrived_) out.push_back({Happening::kArrive, std::move(part), ""});
  arrived_.clear();
  for (const Event& e : result.events) {
    switch (e.kind) {
      case EventKind::kContactBegin:
        touching_.insert(ordered(e.a, e.b));
        first_contact_.try_emplace(ordered(e.a, e.b), e.time);
        if (contact_sources_[ordered(e.a, e.b)]++ == 0)
          out.push_back({Happening::kTouch, e.a, e.b});
        break;
      case EventKind::kContactEnd:
        touching_.erase(ordered(e.a, e.b));
        if (--contact_sources_[ordered(e.a, e.b)] == 0)
          out.push_back({Happening::kSeparate, e.a, e.b});
        break;
      case EventKind::kHandContactBegin:
        first_contact_.try_emplace(ordered("hand", e.b), e.time);
        if (hand_touching_[e.b]++ == 0) out.push_back({Happening::kTouch, "hand", e.b});
        break;
      case EventKind::kHandContactEnd:
        if (--hand_touching_[e.b] == 0) out.push_back({Happening::kSeparate, "hand", e.b});
        break;
      case EventKind::kGrasp:
        out.push_back({Happening::kGrasp, e.a, e.b});
        break;
      case EventKind::kRelease:
        out.push_back({Happening::kRelease, e.a, e.b});
        break;
      case EventKind::kSlideBegin:
        // A part sliding along another touches it (the band keeps a skin of
        // micrometres, so the collision layer may see no contact).
        out.push_back({Happening::kSlide, e.a, e.b});
        first_contact_.try_emplace(ordered(e.a, e.b), e.time);
        if (contact_sources_[ordered(e.a, e.b)]++ == 0)
          out.push_back({Happening::kTouch, e.a, e.b});
        break;
      case EventKind::kSlideEnd:
        if (--contact_sources_[ordered(e.a, e.b)] == 0)
          out.push_back({Happening::kSeparate, e.a, e.b});
        break;
      case EventKind::kMate:
        for (const MateSpec& m : scenario_.mates) {
          if (m.mate.part == e.a && m.mate.other == e.b) {
            out.push_back({Happening::kMated, m.mate.name, ""});
            seated_[m.mate.name] = {scene.world_pose(e.a), scene.world_pose(e.b)};
          }
        }
        break;
      case EventKind::kRegionEnter:
        inside_.insert({e.a, e.b});
        out.push_back({Happening::kEnter, e.a, e.b});
        break;
      case EventKind::kRegionLeave:
        inside_.erase({e.a, e.b});
        out.push_back({Happening::kLeave, e.a, e.b});
        break;
      default:
        break;
    }
  }
  return out;
}

bool Runner::matches(const Clause& when, const Occurrence& o) const {
  const std::string_view w = when.word->name;
  const auto& args = when.args;
  switch (o.kind) {
    case Happening::kTouch:
    case Happening::kSeparate:
      if (w != (o.kind == Happening::kTouch ? "touches" : "separates")) return false;
      return ordered(args[0].text, args[1].text) == ordered(o.a, o.b);
    case Happening::kGrasp:
      return w == "grasped" && args[0].text == o.a && (!args[1].given || args[1].text == o.b);
    case Happening::kRelease:
      return w == "released" && args[0].text == o.a;
    case Happening::kSlide:
      return w == "slides" && args[0].text == o.a && (!args[1].given || args[1].text == o.b);
    case Happening::kMated:
      return w == "mated" && args[0].text == o.a;
    case Happening::kEnter:
      return w == "enters" && args[0].text == o.a && args[1].text == o.b;
    case Happening::kLeave:
      return w == "leaves" && args[0].text == o.a && args[1].text == o.b;
    case Happening::kCompleted:
      return w == "completed" && args[0].text == o.a;
    case Happening::kArrive:
      return w == "arrives" && args[0].text == o.a;
  }
  return false;
}

bool Runner::timer_fires(const Clause& when, double now, double previous) const {
  if (past_end_) return false;  // the frame that finishes the last one's actions
  const std::string_view w = when.word->name;
  const double t = when.args[0].number;
  // A frame's time is its number times the step, rounded: 27 * (1/90) may
  // fall a rounding short of 0.3. Within kRounding of a time is at it.
  constexpr double kRounding = 1e-9;
  if (w == "after") return now >= t - kRounding && previous < t - kRounding;
  if (w == "every") {
    if (!(t > 0)) return false;
    const double k = std::floor((now + kRounding) / t);
    return k >= 1 && k > std::floor((previous + kRounding) / t);
  }
  return false;
}

void Runner::complete_step(std::size_t i, double now, std::vector<Occurrence>& occurrences) {
  if (step_done_[i]) return;
  step_done_[i] = now;
  completion_order_.push_back(i);
  for (std::size_t j = 0; j < i; ++j) {
    if (!step_done_[j]) {
      out_.messages.push_back({now, "violation",
                               "step '" + scenario_.steps[i].name + "' completed before step '" +
                                   scenario_.steps[j].name + "'",
                               scenario_.steps[i].where});
      out_.steps[i].out_of_order = true;
      break;
    }
  }
  out_.steps[i].done_at = now;
  occurrences.push_back({Happening::kCompleted, scenario_.steps[i].name, ""});
}

/// The part at the top of the chain of parts that `part` is attached to.
PartId assembly_root(const engine::Scene& scene, PartId part) {
  while (scene.parent(part).valid()) part = scene.parent(part);
  return part;
}

void Runner::measure_penetration(double now) {
  const engine::Scene& scene = sim_->scene();
  for (const auto& [a, b] : touching_) {
    const PartId pa = scene.find(a), pb = scene.find(b);
    if (!pa.valid() || !pb.valid()) continue;
    // Parts attached to each other (directly, through others or to one part) move as one:
    // their overlap is how they were put together (a press fit), not a collision.
    if (assembly_root(scene, pa) == assembly_root(scene, pb)) continue;
    const auto& ma = scene.collision_mesh(pa);
    const auto& mb = scene.collision_mesh(pb);
    if (!ma || !mb) continue;
    const Transform X_WA = scene.world_pose(pa), X_WB = scene.world_pose(pb);
    // Parts that have not moved since they were last measured overlap as deep as then.
    auto& last = measured_[{a, b}];
    if (last && last->first.R == X_WA.R && last->first.t == X_WA.t && last->second.R == X_WB.R &&
        last->second.t == X_WB.t) {
      continue;
    }
    last = std::pair(X_WA, X_WB);
    const double depth = overlap_.depth(ma, X_WA, mb, X_WB);
    if (depth > out_.max_penetration) {
      out_.max_penetration = depth;
      out_.max_penetration_time = now;
      out_.max_penetration_a = a;
      out_.max_penetration_b = b;
    }
  }
}

/// Who would overlap in a refused snap: "it", or "'washer', moved with it".
std::string overlapper(const interaction::RefusedSnap& r) {
  return r.overlapping == r.part ? "it" : "'" + r.overlapping + "', moved with it,";
}

std::string Runner::also_touched_then(const std::string& part) const {
  const std::optional<double> when = grasping_->closest_try_time(part);
  if (!when) return "";
  // The hand's contacts with other parts at that time, from the timeline.
  std::map<std::string, std::set<std::string>> touching;  // part -> segments
  for (const engine::Event& e : sim_->report().events) {
    if (e.time > *when + 1e-9) break;
    if (e.b == part) continue;
    const std::string segment = e.a.substr(e.a.find('.') + 1);
    if (e.kind == EventKind::kHandContactBegin) touching[e.b].insert(segment);
    if (e.kind == EventKind::kHandContactEnd) {
      touching[e.b].erase(segment);
      if (touching[e.b].empty()) touching.erase(e.b);
    }
  }
  if (touching.empty()) return "";
  std::string text;
  for (const auto& [other, segments] : touching) {
    std::string list;
    for (const std::string& s : segments) list += (list.empty() ? "" : ", ") + s;
    text += (text.empty() ? "" : " and ") + ("'" + other + "' (" + list + ")");
  }
  return "; then the hand touched " + text + " too, and a finger stops at the first part it meets";
}

std::string Runner::why_not_snapped(const MateSpec& m) const {
  if (grasping_) {
    const auto& refused = grasping_->refused_snaps();
    for (auto it = refused.rbegin(); it != refused.rend(); ++it) {
      if (it->mate != m.mate.name) continue;
      return ": released within its tolerances at t=" + format_time(it->time) +
             " s, but in place " + overlapper(*it) + " would overlap '" + it->blocker + "' by " +
             format_length(it->depth_m, out_);
    }
  }
  const auto i = static_cast<std::size_t>(&m - scenario_.mates.data());
  if (i >= closest_.size() || !closest_[i].seen) return "";
  const Closest& c = closest_[i];
  // A part snaps when the hand lets it go (or by a rule's snap): one the hand
  // never held could not, however close it came.
  const bool held = carried_ever_.count(m.mate.part) != 0;
  std::string never_held =
      held ? ""
           : "; the hand never held it, and a part snaps when the hand lets it go (or by a "
             "rule's snap)";
  // Carried to the end: never let go, so never snapped.
  if (held && carried_now_.count(m.mate.part) != 0 &&
      !(i < released_.size() && released_[i].seen)) {
    never_held =
        "; the hand still held it when the run ended, and a part snaps when the hand lets it go";
  }
  // Rounded to a millionth of a degree: turns given in degrees leave ~1e-15.
  const auto degrees = [](const interaction::MateOffset& offset) {
    char text[64];
    std::snprintf(text, sizeof text, "%.3g degrees", std::round(offset.angle_deg * 1e6) / 1e6);
    return std::string(text);
  };
  const std::string angle = degrees(c.offset);
  // How far, and which way: short of its place along the axis, or off it.
  const auto placed = [&](const interaction::MateOffset& offset) {
    std::string text = format_length(offset.distance_m, out_) + " from its place";
    if (!(offset.distance_m > 0)) return text;
    // Below a nanometre is rounding (a part moved exactly along its axis).
    constexpr double kRounding = 1e-9;
    const std::string along = std::abs(offset.along_m) <= kRounding
                                  ? "level with it along the axis"
                                  : format_length(std::abs(offset.along_m), out_) +
                                        (offset.along_m > 0 ? " short of it" : " past it") +
                                        " along the axis";
    const std::string across = offset.across_m <= kRounding
                                   ? "on the axis"
                                   : format_length(offset.across_m, out_) + " off the axis";
    return text + " (" + along + ", " + across + ")";
  };
  char tolerance[64];
  std::snprintf(tolerance, sizeof tolerance, "%.3g degrees", m.mate.angle_tolerance_deg);
  std::string at_release;
  if (i < released_.size() && released_[i].seen) {
    const Closest& r = released_[i];
    // How it was let go, and what it rested on then (what stopped it).
    const std::vector<engine::Event>& events = sim_->report().events;
    std::string how = "the hand let it go";
    // What the part, or a part attached to it and carried with it, slid on
    // then: (its part, the part it slid on) -> since when.
    const engine::Scene& scene = sim_->scene();
    const PartId carried = scene.find(m.mate.part);
    const auto moved_with = [&](const std::string& name) {
      const PartId q = scene.find(name);
      return name == m.mate.part ||
             (carried.valid() && q.valid() && scene.descends_from(q, carried));
    };
    std::map<std::pair<std::string, std::string>, double> resting;
    for (const engine::Event& e : events) {
      if (e.time > r.time + 1e-9) break;
      if (e.kind == engine::EventKind::kRelease && e.a == m.mate.part &&
          std::abs(e.time - r.time) < 1e-9 && e.b == "overstretched") {
        how = "the rubber band overstretched and let it go";
      }
      if (e.kind != engine::EventKind::kSlideBegin && e.kind != engine::EventKind::kSlideEnd) {
        continue;
      }
      const bool a_moved = moved_with(e.a), b_moved = moved_with(e.b);
      if (a_moved == b_moved) continue;
      const auto key = a_moved ? std::pair(e.a, e.b) : std::pair(e.b, e.a);
      if (e.kind == engine::EventKind::kSlideBegin) resting.emplace(key, e.time);
      if (e.kind == engine::EventKind::kSlideEnd && e.time < r.time - 1e-9) resting.erase(key);
    }
    std::string on;
    for (const auto& [pair, since] : resting) {
      const auto& [mine, other] = pair;
      on += (on.empty() ? ", resting against '" : " and '") + other + "' (" +
            (mine == m.mate.part ? "" : "'" + mine + "', moved with it, ") +
            "sliding on it from t=" + format_time(since) + " s)";
    }
    at_release = ": when " + how + " at t=" + format_time(r.time) + " s it was " +
                 placed(r.offset) + ", its axis " + degrees(r.offset) + " off" + on + ";";
  }
  // An axis turned end for end is most likely a sign: axis = "z" for "-z".
  const std::string reversed =
      c.offset.angle_deg > 175
          ? "; its axis points the opposite way to the other's: is one of the mate's axis and "
            "along given the wrong way round (\"z\" for \"-z\")?"
          : "";
  return at_release + (at_release.empty() ? ": the" : " the") + " closest it came was " +
         placed(c.offset) + ", its axis " + angle + " off, at t=" + format_time(c.time) +
         " s (a snap needs the part released within " +
         format_length(m.mate.position_tolerance, out_) + " and " + tolerance + ")" + reversed +
         never_held;
}

void Runner::watch_mates(double now) {
  const engine::Scene& scene = sim_->scene();
  closest_.resize(scenario_.mates.size());
  for (std::size_t i = 0; i < scenario_.mates.size(); ++i) {
    const interaction::Mate& m = scenario_.mates[i].mate;
    const PartId p = scene.find(m.part), o = scene.find(m.other);
    if (!p.valid() || !o.valid()) continue;
    const interaction::MateOffset offset =
        interaction::mate_offset(m, scene.world_pose(p), scene.world_pose(o));
    Closest& c = closest_[i];
    if (!c.seen || offset.distance_m < c.offset.distance_m) c = {offset, now, true};
  }
  if (!grasping_) return;
  const auto& refused = grasping_->refused_snaps();
  for (; refusals_seen_ < refused.size(); ++refusals_seen_) {
    const interaction::RefusedSnap& r = refused[refusals_seen_];
    const MateSpec* m = mate(r.mate);
    out_.messages.push_back({r.time, "warn",
                             "'" + r.part + "' was released within the tolerances of mate '" +
                                 r.mate + "' but not snapped: in place " + overlapper(r) +
                                 " would overlap '" + r.blocker + "' by " +
                                 format_length(r.depth_m, out_),
                             m ? m->where : SourceLocation{}});
  }
}

void Runner::end_frame(const engine::FrameResult& result, double previous_time) {
  const double now = result.time;
  std::vector<Occurrence> happened = occurrences(result);
  measure_penetration(now);
  watch_mates(now);
  // Where the mates' parts were when the hand let them go (they were carried
  // up to the last frame), and the parts the hand carries now (the held one
  // and its sub-assembly), for mate_made.
  const engine::Scene& scene = sim_->scene();
  for (const Event& e : result.events) {
    if (e.kind != EventKind::kRelease) continue;
    released_.resize(scenario_.mates.size());
    for (std::size_t i = 0; i < scenario_.mates.size(); ++i) {
      const interaction::Mate& m = scenario_.mates[i].mate;
      if (!carried_now_.count(m.part)) continue;
      const PartId p = scene.find(m.part), o = scene.find(m.other);
      if (!p.valid() || !o.valid()) continue;
      released_[i] = {interaction::mate_offset(m, scene.world_pose(p), scene.world_pose(o)), now,
                      true};
    }
  }
  carried_now_.clear();
  if (grasping_ && grasping_->carried()) {
    const PartId root = scene.find(*grasping_->carried());
    for (const PartId p : scene.parts()) {
      if (root.valid() && scene.descends_from(p, root)) carried_now_.insert(scene.name(p));
    }
    carried_ever_.insert(carried_now_.begin(), carried_now_.end());
  }
  // Steps first: their completions are events the rules of this frame see.
  for (const std::size_t i : forced_steps_) complete_step(i, now, happened);
  forced_steps_.clear();
  for (std::size_t i = 0; i < scenario_.steps.size(); ++i) {
    const auto& done = scenario_.steps[i].done;
    if (!done || step_done_[i]) continue;
    const bool fired = timer_fires(*done, now, previous_time) ||
                       std::any_of(happened.begin(), happened.end(),
                                   [&](const Occurrence& o) { return matches(*done, o); });
    if (fired) complete_step(i, now, happened);
  }
  // Rules in file order; their actions apply at the start of the next frame.
  for (std::size_t r = 0; r < scenario_.rules.size(); ++r) {
    const RuleSpec& rule = scenario_.rules[r];
    const bool fired = timer_fires(rule.when, now, previous_time) ||
                       std::any_of(happened.begin(), happened.end(),
                                   [&](const Occurrence& o) { return matches(rule.when, o); });
    if (!fired) continue;
    if (rule.once && rule_last_[r]) continue;
    if (rule_last_[r] && now - *rule_last_[r] < rule.cooldown - 1e-9) continue;
    if (rule.unless && holds(*rule.unless)) continue;
    if (rule.only_if && !holds(*rule.only_if)) continue;
    rule_last_[r] = now;
    ++out_.rules_fired;
    for (const Clause& action : rule.act) {
      const std::string_view w = action.word->name;
      if (w == "log" || w == "warn" || w == "fail") {
        out_.messages.push_back({now, std::string(w), action.args[0].text, action.where});
        if (w == "fail") failed_by_rule_ = true;
      } else {
        pending_.push_back({&action, now});
      }
    }
  }
}

void Runner::take_picture(std::uint64_t frame, double time) {
  engine::RenderScene scene = engine::render_scene(sim_->scene());
  if (scenario_.camera) scene.cameras.push_back({kScenarioCamera, *scenario_.camera});
  out_.picture = RunOutcome::Picture{std::move(scene), time, frame, hand_ != nullptr};
}

void Runner::render(const std::filesystem::path& path, bool final_picture) {
  // The parts in their own colours and the rules' highlights (contacts are not marked).
  engine::RenderScene scene = engine::render_scene(sim_->scene());
  const double aspect = static_cast<double>(options_.render_width) / options_.render_height;
  engine::Camera camera;
  if (scenario_.camera) {
    camera = *scenario_.camera;
  } else if (final_picture) {
    camera = engine::auto_camera(scene, aspect);
  } else {
    if (!camera_) camera_ = engine::auto_camera(scene, aspect);
    camera = *camera_;
  }
  scene.cameras.push_back({"dovetail.run", camera});
  engine::RenderSettings settings;
  settings.width = options_.render_width;
  settings.height = options_.render_height;
  settings.camera = "dovetail.run";
  try {
    engine::write_png(engine::render(scene, settings), path);
  } catch (const std::exception& e) {
    throw ScenarioError(path.string() + ": the frame at t=" + format_time(sim_->time()) +
                        " s cannot be drawn: " + e.what());
  }
}

void Runner::evaluate_expectations() {
  for (const Clause& c : scenario_.expectations) {
    ExpectationOutcome e{c.text, c.where, true, ""};
    const std::string_view w = c.word->name;
    const auto& args = c.args;
    if (w == "steps_in_order") {
      std::optional<double> last;
      std::size_t last_order = 0;
      std::string previous;
      for (const std::string& name : args[0].names) {
        std::size_t i = 0;
        while (scenario_.steps[i].name != name) ++i;
        if (!step_done_[i]) {
          e.passed = false;
          e.detail = "step '" + name + "' was never completed";
          break;
        }
        const std::size_t order = static_cast<std::size_t>(
            std::find(completion_order_.begin(), completion_order_.end(), i) -
            completion_order_.begin());
        if (last && order < last_order) {
          e.passed = false;
          e.detail = "step '" + name + "' was completed at t=" + format_time(*step_done_[i]) +
                     " s, before step '" + previous + "' (t=" + format_time(*last) + " s)";
          break;
        }
        if (out_.steps[i].out_of_order) {
          e.passed = false;
          e.detail = "step '" + name +
                     "' was completed out of order at t=" + format_time(*step_done_[i]) + " s";
          break;
        }
        last = step_done_[i];
        last_order = order;
        previous = name;
      }
      if (e.passed && last) e.detail = "last step completed at t=" + format_time(*last) + " s";
    } else if (w == "finished_within") {
      for (std::size_t i = 0; i < scenario_.steps.size() && e.passed; ++i) {
        if (!step_done_[i]) {
          e.passed = false;
          e.detail = "step '" + scenario_.steps[i].name + "' was never completed (run ended at t=" +
                     format_time(static_cast<double>(
                                     std::max<std::uint64_t>(sim_->report().frames, 1) - 1) *
                                 scenario_.time_step) +
                     " s)";
        } else if (*step_done_[i] > args[0].number) {
          e.passed = false;
          e.detail = "step '" + scenario_.steps[i].name +
                     "' was completed at t=" + format_time(*step_done_[i]) + " s, after " +
                     format_time(args[0].number) + " s";
        }
      }
    } else if (w == "max_penetration") {
      e.passed = out_.max_penetration <= args[0].number;
      e.detail = out_.max_penetration > 0
                     ? "'" + out_.max_penetration_a + "' and '" + out_.max_penetration_b +
                           "' overlapped " + format_length(out_.max_penetration, out_) +
                           " at t=" + format_time(out_.max_penetration_time) + " s (allowed " +
                           format_length(args[0].number, out_) + ")"
                     : "no overlap was measured";
      // A depth against an open or wrongly wound surface may read 0 or far too deep.
      for (const std::string* part : {&out_.max_penetration_a, &out_.max_penetration_b}) {
        const PartId p = part->empty() ? PartId{} : sim_->scene().find(*part);
        if (!p.valid() || !sim_->scene().collision_mesh(p)) continue;
        if (const auto flaw = interaction::surface_flaw(*sim_->scene().collision_mesh(p))) {
          e.detail += "; '" + *part + "' is no closed surface (" + *flaw +
                      "), so this depth is not to be trusted";
        }
      }
    } else if (w == "no_contact") {
      const auto it = first_contact_.find(ordered(args[0].text, args[1].text));
      if (it != first_contact_.end()) {
        e.passed = false;
        e.detail = "'" + args[0].text + "' touched '" + args[1].text +
                   "' at t=" + format_time(it->second) + " s";
      }
    } else if (w == "warnings_at_most") {
      // Loading's and set-up's first (a glove in other units), then the run's.
      const auto limit = static_cast<std::size_t>(args[0].number);
      std::size_t count = 0;
      for (const std::string& text : out_.warnings) {
        if (++count > limit && e.passed) {
          e.passed = false;
          e.detail = "warning before the run: " + text;
        }
      }
      for (const Message& m : out_.messages) {
        if (m.level != "warn") continue;
        if (++count > limit && e.passed) {
          e.passed = false;
          e.detail =
              "warning at t=" + format_time(m.time) + " s (" + m.where.str() + "): " + m.text;
        }
      }
      if (!e.passed)
        e.detail = std::to_string(count) + (count == 1 ? " warning" : " warnings") +
                   "; first over the limit: " + e.detail;
    } else if (w == "mate_made") {
      const MateSpec* m = mate(args[0].text);
      bool mated = false;
      double at = 0;
      for (const Event& ev : sim_->report().events) {
        if (ev.kind == EventKind::kMate && ev.a == m->mate.part && ev.b == m->mate.other) {
          mated = true;
          at = ev.time;
        }
      }
      if (!mated) {
        e.passed = false;
        e.detail = "'" + m->mate.part + "' never snapped into '" + m->mate.other + "'" +
                   why_not_snapped(*m);
      } else if (!near(m->mate)) {
        e.passed = false;
        e.detail = "'" + m->mate.part + "' snapped at t=" + format_time(at) +
                   " s but was moved out of place";
      } else {
        e.detail = "snapped at t=" + format_time(at) + " s";
      }
    } else if (w == "grasped_as") {
      // The timeline's grasp events: a = the part, b = the grasp type.
      const Event* as_asked = nullptr;
      const Event* other = nullptr;
      for (const Event& ev : sim_->report().events) {
        if (ev.kind != EventKind::kGrasp || ev.a != args[0].text) continue;
        if (ev.b == args[1].text) {
          as_asked = &ev;
          break;
        }
        if (!other) other = &ev;
      }
      if (as_asked) {
        e.detail = "at t=" + format_time(as_asked->time) + " s";
      } else {
        e.passed = false;
        e.detail =
            "'" + args[0].text + "' was never grasped as " + args[1].text +
            (other ? "; it was grasped as " + other->b + " at t=" + format_time(other->time) + " s"
             : grasping_
                 ? "; " + grasping_->why_not_grasped(args[0].text) + also_touched_then(args[0].text)
                 : std::string());
      }
    }
    out_.expectations.push_back(std::move(e));
  }
}

std::optional<std::string> Runner::output_read() const {
  std::vector<std::filesystem::path> reads = files_read_;
  if (options_.trace) reads.push_back(*options_.trace);
  std::vector<std::filesystem::path> writes = options_.outputs;
  if (options_.record) writes.push_back(*options_.record);
  for (const std::filesystem::path& w : writes) {
    for (const std::filesystem::path& r : reads) {
      if (engine::same_file(w, r)) {
        // Named once when both name it alike, else both ways (a link, another path).
        const std::string which = w == r ? "'" + w.string() + "'"
                                         : "'" + w.string() + "' (which is '" + r.string() + "')";
        return "the output " + which + " is a file the run reads; it would be overwritten";
      }
    }
  }
  return std::nullopt;
}

void Runner::refuse_outputs() {
  if (const std::optional<std::string> clash = output_read()) {
    out_.outputs_refused = true;
    throw ScenarioError(file_.string() + ": " + *clash);
  }
}

void Runner::run() {
  const auto start = std::chrono::steady_clock::now();
  out_.file = file_;
  out_.name = file_.stem().string();
  try {
    scenario_ = load_scenario(host_, file_, &files_read_, options_.trace.has_value());
    refuse_outputs();
    out_.name = scenario_.name;
    out_.units = scenario_.units;
    out_.metres_per_unit = scenario_.metres_per_unit;
    out_.warnings = scenario_.warnings;
    host_.run_string("math.randomseed(" + std::to_string(scenario_.seed) + ")", "seed", 0);
    lua_pushlightuserdata(host_.state(), this);
    lua_setfield(host_.state(), LUA_REGISTRYINDEX, kRunnerKey);
    for (const StepSpec& s : scenario_.steps) out_.steps.push_back({s.name, std::nullopt, false});
    step_done_.assign(scenario_.steps.size(), std::nullopt);
    rule_last_.assign(scenario_.rules.size(), std::nullopt);
    build();
  } catch (const std::exception& e) {
    out_.status = RunOutcome::Status::kError;
    out_.error = e.what();
    // Loading may have failed after reading files an output would overwrite.
    if (const std::optional<std::string> clash = output_read(); clash && !out_.outputs_refused) {
      out_.outputs_refused = true;
      out_.error += "\n" + file_.string() + ": nothing written: " + *clash;
    }
    out_.wall_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return;
  }
  const bool from_trace = options_.trace || (scenario_.glove && !scenario_.glove->trace.empty());
  const double end_time = run_end_time(scenario_, hand_ ? &hand_->source() : nullptr, from_trace);
  const std::uint64_t frames = frame_count(scenario_, end_time);
  const double last_time = last_frame_time(scenario_, end_time);
  for (std::string& w : never_after(scenario_, last_time)) out_.warnings.push_back(std::move(w));
  if (options_.picture_at && *options_.picture_at > last_time + 1e-9) {
    out_.status = RunOutcome::Status::kError;
    out_.error = file_.string() + ": no frame at t=" + format_time(*options_.picture_at) +
                 " s: the run's last frame is at t=" + format_time(last_time) + " s (" +
                 (scenario_.duration ? "its duration"
                  : from_trace       ? "the end of its glove's trace"
                  : hand_ ? "the end of its glove's plan, and a second for the hand to come to rest"
                          : "1 s, as a scenario without a glove or duration runs") +
                 ")";
    out_.wall_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return;
  }
  // Frames an earlier run left are not to be mixed with this run's.
  if (options_.render_dir) {
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(*options_.render_dir, ec)) {
      if (entry.is_symlink(ec) || !entry.is_regular_file(ec)) continue;
      if (!is_frame_file_name(entry.path().filename().string())) continue;
      out_.old_frames_removed += std::filesystem::remove(entry.path(), ec) ? 1 : 0;
    }
  }
  std::optional<engine::ProgressMeter> meter;
  if (options_.progress) meter.emplace(frames);
  const auto loop_start = std::chrono::steady_clock::now();
  try {
    double previous = -1;
    for (std::uint64_t f = 0; f < frames && !failed_by_rule_; ++f) {
      const engine::FrameResult& result = sim_->step();
      end_frame(result, previous);
      previous = result.time;
      if (options_.render_dir && options_.render_every > 0 && f % options_.render_every == 0) {
        char name[32];
        std::snprintf(name, sizeof name, "frame_%06llu.png", static_cast<unsigned long long>(f));
        render(*options_.render_dir / name, false);
      }
      if (meter) meter->update(f + 1);
      if (options_.picture_at && result.time >= *options_.picture_at - 1e-9) {
        take_picture(f, result.time);
        break;
      }
    }
    if (options_.picture_at) {
      if (meter) meter->finish();
      out_.loop_seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - loop_start).count();
      // The picture is what was asked for: the expectations are not judged.
      out_.status = RunOutcome::Status::kPassed;
      if (!out_.picture) {
        // A rule's fail ended the run before: which, where and why.
        std::string why = "a rule failed the run";
        for (const Message& m : out_.messages) {
          if (m.level == "fail") {
            why = m.where.str() + ": a rule failed the run at t=" + format_time(m.time) +
                  " s: " + m.text;
          }
        }
        out_.status = RunOutcome::Status::kError;
        out_.error =
            file_.string() + ": no frame at t=" + format_time(*options_.picture_at) + " s: " + why;
      }
      out_.report = sim_->report();
      out_.wall_seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      return;
    }
    // Actions of rules that fired in the last frame are done at the start of
    // the next: one frame more, a whole one (its contacts found, its events
    // and steps counted, the state hashed), so that no action is lost.
    if (!failed_by_rule_ && !pending_.empty()) {
      past_end_ = true;
      const engine::FrameResult& result = sim_->step();
      end_frame(result, previous);
    }
    // Moves still under way when the run ends do not arrive, and are said so.
    for (const Motion& m : motions_) {
      out_.messages.push_back({m.t0, "warn",
                               "move: '" + m.part +
                                   "' had not arrived when the run ended (it "
                                   "would at t=" +
                                   format_time(m.t1) + " s)",
                               m.where});
    }
    // What rules of that frame left for another is not done, and said so.
    for (const auto& [action, fired] : pending_) {
      out_.messages.push_back(
          {fired, "warn",
           std::string(action->word->name) + ": not done: its rule fired in the run's last frame",
           action->where});
    }
    pending_.clear();
    if (meter) meter->finish();
    out_.loop_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - loop_start).count();
    evaluate_expectations();
    out_.status = RunOutcome::Status::kPassed;
    if (failed_by_rule_) out_.status = RunOutcome::Status::kFailed;
    for (const ExpectationOutcome& e : out_.expectations) {
      if (!e.passed) out_.status = RunOutcome::Status::kFailed;
    }
  } catch (const ScriptError& e) {
    // A script's error during the run: when, in simulated time, on its first line.
    out_.status = RunOutcome::Status::kError;
    out_.error = e.what();
    out_.error.insert(std::min(out_.error.find('\n'), out_.error.size()),
                      " (at t=" + format_time(sim_->time()) + " s)");
  } catch (const std::exception& e) {
    out_.status = RunOutcome::Status::kError;
    out_.error = e.what();
  }
  out_.report = sim_->report();
  const engine::Scene& scene = sim_->scene();
  for (const PartId p : scene.parts()) {
    if (scene.has_tag(p, "hand")) continue;
    const Transform X = scene.world_pose(p);
    out_.final_poses.push_back({scene.name(p), X.t, engine::quaternion_from_rotation(X.R)});
  }
  // An output that cannot be made is the run's error; the report still
  // holds everything simulated.
  const auto output = [&](const auto& make) {
    try {
      make();
    } catch (const std::exception& e) {
      out_.status = RunOutcome::Status::kError;
      out_.error += (out_.error.empty() ? "" : "\n") + std::string(e.what());
    }
  };
  if (options_.record && hand_) {
    output([&] { interaction::write_trace(*options_.record, hand_->recorded()); });
  }
  if (options_.render_dir) {
    output([&] {
      const std::filesystem::path final_frame = *options_.render_dir / "final.png";
      render(final_frame, true);
      out_.final_frame = final_frame;
    });
  }
  if (capture_) {
    out_.captures = capture_->files();
    out_.suspect_queries = capture_->recorded();
  }
  out_.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

bool is_frame_file_name(std::string_view name) {
  constexpr std::string_view kPrefix = "frame_", kSuffix = ".png";
  if (!name.starts_with(kPrefix) || !name.ends_with(kSuffix)) return false;
  const std::string_view digits =
      name.substr(kPrefix.size(), name.size() - kPrefix.size() - kSuffix.size());
  return digits.size() >= 6 &&
         std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; });
}

std::string_view status_name(RunOutcome::Status status) {
  switch (status) {
    case RunOutcome::Status::kPassed:
      return "passed";
    case RunOutcome::Status::kFailed:
      return "failed";
    case RunOutcome::Status::kError:
      return "error";
  }
  return "error";
}

std::string RunOutcome::to_json() const {
  using engine::json_number;
  using engine::json_string;
  std::string out = "{\n  \"format\": \"dovetail-scenario-report\",\n  \"version\": " +
                    std::to_string(kScenarioReportVersion) + ",\n";
  out += "  \"scenario\": " + json_string(name) + ",\n";
  out += "  \"file\": " + json_string(file.generic_string()) + ",\n";
  out += "  \"outcome\": " + json_string(status_name(status)) + ",\n";
  if (!error.empty()) out += "  \"error\": " + json_string(error) + ",\n";
  out += "  \"units\": " + json_string(units) + ",\n";
  out += "  \"expectations\": [";
  for (std::size_t i = 0; i < expectations.size(); ++i) {
    const ExpectationOutcome& e = expectations[i];
    out += (i ? ",\n    " : "\n    ") + std::string("{\"expect\": ") + json_string(e.text) +
           ", \"where\": " + json_string(e.where.str()) +
           ", \"passed\": " + (e.passed ? "true" : "false") +
           ", \"detail\": " + json_string(e.detail) + "}";
  }
  out += expectations.empty() ? "],\n" : "\n  ],\n";
  out += "  \"steps\": [";
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const StepOutcome& s = steps[i];
    out += (i ? ",\n    " : "\n    ") + std::string("{\"name\": ") + json_string(s.name) +
           ", \"done_at\": " + (s.done_at ? json_number(*s.done_at) : "null") +
           ", \"out_of_order\": " + (s.out_of_order ? "true" : "false") + "}";
  }
  out += steps.empty() ? "],\n" : "\n  ],\n";
  out += "  \"messages\": [";
  for (std::size_t i = 0; i < messages.size(); ++i) {
    const Message& m = messages[i];
    out += (i ? ",\n    " : "\n    ") + std::string("{\"time\": ") + json_number(m.time) +
           ", \"level\": " + json_string(m.level) + ", \"text\": " + json_string(m.text) +
           ", \"where\": " + json_string(m.where.str()) + "}";
  }
  out += messages.empty() ? "],\n" : "\n  ],\n";
  out += "  \"warnings\": [";
  for (std::size_t i = 0; i < warnings.size(); ++i)
    out += (i ? ", " : "") + json_string(warnings[i]);
  out += "],\n";
  out += "  \"rules_fired\": " + std::to_string(rules_fired) + ",\n";
  // No two parts ever overlapped: a depth of 0, and no time or parts.
  const bool overlapped = !max_penetration_a.empty();
  out += "  \"max_penetration\": {\"depth\": " + json_number(max_penetration / metres_per_unit) +
         ", \"time\": " + (overlapped ? json_number(max_penetration_time) : "null") +
         ", \"a\": " + (overlapped ? json_string(max_penetration_a) : "null") +
         ", \"b\": " + (overlapped ? json_string(max_penetration_b) : "null") + "},\n";
  out += "  \"final_poses\": [";
  for (std::size_t i = 0; i < final_poses.size(); ++i) {
    const PartPose& p = final_poses[i];
    const collision::Vec3 at = p.position / metres_per_unit;
    const engine::Quaternion& q = p.rotation;
    out += (i ? ",\n    " : "\n    ") + std::string("{\"part\": ") + json_string(p.part) +
           ", \"position\": [" + json_number(at.x()) + ", " + json_number(at.y()) + ", " +
           json_number(at.z()) + "], \"rotation\": [" + json_number(q.w) + ", " + json_number(q.x) +
           ", " + json_number(q.y) + ", " + json_number(q.z) + "]}";
  }
  out += final_poses.empty() ? "],\n" : "\n  ],\n";
  std::string simulation = report.to_json();
  while (!simulation.empty() && simulation.back() == '\n') simulation.pop_back();
  out += "  \"simulation\": " + simulation + "\n}\n";
  return out;
}

std::string RunOutcome::failure_summary() const {
  std::string out;
  if (status == Status::kError) out += "error: " + error + "\n";
  // A `fail` stops the run, and expectations may fail only because it did:
  // the fail comes first, as the cause.
  for (const Message& m : messages) {
    if (m.level == "fail")
      out += m.where.str() + ": failed at t=" + format_time(m.time) + " s: " + m.text + "\n";
  }
  // Then the expectations on what happened before those on the steps' order
  // and time: a step never done is most often the effect of a part that
  // touched, or never snapped, and the first line is what a summary shows.
  const auto on_steps = [](const ExpectationOutcome& e) {
    return e.text.rfind("steps_in_order(", 0) == 0 || e.text.rfind("finished_within(", 0) == 0;
  };
  for (const bool steps_pass : {false, true}) {
    for (const ExpectationOutcome& e : expectations) {
      if (!e.passed && on_steps(e) == steps_pass)
        out += e.where.str() + ": expectation " + e.text + " failed: " + e.detail + "\n";
    }
  }
  for (const Message& m : messages) {
    if (m.level == "violation")
      out += m.where.str() + ": at t=" + format_time(m.time) + " s: " + m.text + "\n";
  }
  // A script's text never drives the terminal.
  return engine::escape_control_bytes(out, "\n\t");
}

RunOutcome run_scenario(const std::filesystem::path& file, const RunOptions& options) {
  RunOutcome outcome;
  Runner runner(file, options, outcome);
  runner.run();
  return outcome;
}

Scenario check_scenario(const std::filesystem::path& file, const SandboxLimits& limits) {
  LuaHost host(limits, 1);
  Scenario scenario = load_scenario(host, file);
  std::shared_ptr<const interaction::GloveSource> read;
  // The glove's plan or trace is read when the run starts (unless it replays
  // another trace); a check reads it now, and names it missing or wrong.
  if (scenario.glove) {
    const GloveSpec& glove = *scenario.glove;
    const std::filesystem::path& source = glove.plan.empty() ? glove.trace : glove.plan;
    std::error_code ec;
    if (!std::filesystem::is_regular_file(source, ec)) {
      // Relative to the scenario's folder when inside it (as a scenario
      // usually names it), else as the run names it.
      std::filesystem::path shown = source.lexically_relative(file.parent_path());
      if (shown.empty() || *shown.begin() == "..") shown = source;  // outside the folder
      throw ScenarioError(
          glove.where.str() + ": glove: " + shown.string() +
          (std::filesystem::exists(source, ec) ? ": not a file" : ": file not found"));
    }
    // Read as the run reads it, and doubted as the run doubts it.
    read = glove_source(scenario, std::nullopt);
    for (std::string& w :
         glove_warnings(scenario, glove, *read, glove.where.str() + ": glove", glove.trace)) {
      scenario.warnings.push_back(std::move(w));
    }
  }
  // The run's end, as the run finds it: rules that wait past it.
  const double end_time =
      run_end_time(scenario, read.get(), scenario.glove && !scenario.glove->trace.empty());
  for (std::string& w : never_after(scenario, last_frame_time(scenario, end_time))) {
    scenario.warnings.push_back(std::move(w));
  }
  return scenario;
}

}  // namespace dovetail::scripting
