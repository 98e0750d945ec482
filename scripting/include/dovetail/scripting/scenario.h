#pragma once
/// \file scenario.h
/// An assembly scenario as loaded from its Lua file: parts, mates, regions,
/// the hand and its glove, steps, rules and expectations, every name
/// resolved.
///
/// Why: a scenario is data the file returns (`return scenario { ... }`), not
/// a program that runs alongside the simulation. Loading it runs the file
/// once in the sandbox, reads the tables the vocabulary's constructors built,
/// checks every argument against the vocabulary and resolves every name
/// before the first frame, so a misspelt part is an error with its file and
/// line and a "did you mean ...?", never a rule that silently never fires.

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "dovetail/collision/mesh.h"
#include "dovetail/engine/camera.h"
#include "dovetail/engine/simulation.h"
#include "dovetail/interaction/glove_source.h"
#include "dovetail/interaction/grasping.h"
#include "dovetail/scripting/vocabulary.h"

namespace dovetail::scripting {

class LuaHost;
using collision::Transform;
using collision::Vec3;

/// Thrown for a scenario that cannot be loaded; what() starts with
/// `file:line: ` (or `file: ` when there is no line).
class ScenarioError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Where something was written: `file:line`.
struct SourceLocation {
  std::string file{};
  int line = 0;
  std::string str() const { return line > 0 ? file + ":" + std::to_string(line) : file; }
};

/// One argument of a clause, read according to its Param's type.
struct Arg {
  bool given = false;
  std::string text{};                ///< names, texts, grasp types, colours by name
  double number = 0;                 ///< seconds, counts, numbers, lengths (in metres)
  Vec3 vector = Vec3::Zero();        ///< vectors (metres), directions (unit)
  std::array<float, 3> color{};      ///< colours
  std::vector<std::string> names{};  ///< name lists
  int function_ref = -1;             ///< a function in the Lua registry (custom)
};

/// A use of an event, state, action or expectation word.
struct Clause {
  const Word* word = nullptr;
  SourceLocation where{};
  std::vector<Arg> args{};  ///< one per word->params, in order
  /// As written, for messages: `touches("peg", "block")`.
  std::string text{};
};

struct PartSpec {
  std::string name{};
  SourceLocation where{};
  std::shared_ptr<const collision::Mesh> mesh{};  ///< in metres
  std::string file{};        ///< the mesh file as the scenario names it; empty for a shape
  std::string file_units{};  ///< the unit of the file's numbers when the part gives it, or empty
  Transform X_WP{};
  bool fixed = false;
  std::string attached_to{};  ///< the part it moves with from the start, or empty
  std::optional<std::array<float, 3>> color{};
  std::vector<std::string> tags{};
};

struct MateSpec {
  interaction::Mate mate{};  ///< in metres
  SourceLocation where{};
};

struct RegionSpec {
  engine::Region region{};  ///< in metres
  SourceLocation where{};
};

struct GloveSpec {
  SourceLocation where{};
  std::filesystem::path plan{};   ///< empty unless a plan
  std::filesystem::path trace{};  ///< empty unless a trace
  std::string holding{};          ///< a part held from the start, or empty
  interaction::GraspType grasp = interaction::GraspType::kPower;
  std::optional<interaction::GloveNoise> noise{};
  double hand_length = 0;  ///< metres; 0: the model's default (190 mm)
};

struct StepSpec {
  std::string name{};
  std::string text{};
  std::optional<Clause> done{};
  SourceLocation where{};
};

struct RuleSpec {
  Clause when{};
  std::optional<Clause> unless{};
  std::optional<Clause> only_if{};
  std::vector<Clause> act{};
  double cooldown = 0.1;
  bool once = false;
  SourceLocation where{};
};

/// A loaded scenario; lengths are in metres whatever the file's units.
/// The longest a run may last, in simulated seconds: a scenario's duration,
/// or without one its glove's plan or trace.
inline constexpr double kMaxRunSeconds = 3600;

struct Scenario {
  std::filesystem::path file{};
  std::string name{};
  std::string units = "mm";
  double metres_per_unit = 0.001;
  std::uint64_t seed = 1;
  std::optional<double> duration{};
  double time_step = 1.0 / 90.0;
  /// The collision accuracy the scenario asks for, in metres: 0, exact (the
  /// default); > 0, a tolerance (collision::WorldSettings::tolerance).
  double tolerance_m = 0;
  std::vector<PartSpec> parts{};  ///< in name order
  std::vector<MateSpec> mates{};  ///< in name order
  std::vector<RegionSpec> regions{};
  std::optional<GloveSpec> glove{};
  std::vector<StepSpec> steps{};  ///< in the file's order
  std::vector<RuleSpec> rules{};  ///< in the file's order
  std::vector<Clause> expectations{};
  /// The camera of rendered frames; none: auto_camera of the first frame rendered.
  std::optional<engine::Camera> camera{};
  /// Things that load but look wrong (a rule that can never fire), `file:line: ...`.
  std::vector<std::string> warnings{};
};

/// Loads the scenario at `file` in `host` (which must stay alive while
/// custom actions may run). Throws ScenarioError for anything wrong with
/// the scenario, and ScriptError (lua_host.h) for a script that fails.
/// `files_read`, when given, gets every file the scenario names as it goes:
/// itself, its meshes and what they refer to, its glove's plan or trace (a
/// run refuses to write over any of them), also when loading fails part-way.
/// `hand_given`: a hand comes from elsewhere (a trace replayed with a
/// scenario that has no glove), so events of the hand can happen.
Scenario load_scenario(LuaHost& host, const std::filesystem::path& file,
                       std::vector<std::filesystem::path>* files_read = nullptr,
                       bool hand_given = false);

/// A commented starting scenario named `name`, to be written to `file` (as
/// its comments tell to run it), for `dovetail new`.
std::string starting_scenario(const std::string& name, const std::string& file);

}  // namespace dovetail::scripting
