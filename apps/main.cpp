/// \file main.cpp
/// `dovetail <command> ...`: dispatches to the commands, turns every failure
/// into a message on stderr and an exit code, never an uncaught exception.

#include <cstdio>
#include <filesystem>
#include <new>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cli.h"
#include "commands.h"
#include "dovetail/collision/mesh.h"
#include "dovetail/engine/pose_list.h"
#include "dovetail/scripting/lua_host.h"
#include "dovetail/scripting/scenario.h"
#include "dovetail/scripting/vocabulary.h"

namespace {

using dovetail::cli::kExitInputError;
using dovetail::cli::kExitOk;
using dovetail::cli::kExitUsage;

constexpr const char* kUsage =
    R"(usage: dovetail <command> [arguments]

Headless VR assembly simulator: Lua assembly scenarios, a glove-driven hand,
exact collision queries between meshes.

commands:
  run       run a Lua scenario headless (the first shipped one by default)
  replay    run a scenario with a recorded glove trace
  regress   run every scenario of a folder, JUnit XML and an HTML report
  check     load and resolve a scenario without simulating
  new       write a commented starting scenario
  reference the scenario vocabulary as Markdown
  query     test mesh B against mesh A at every pose of a pose list
  inspect   mesh statistics and the size of every method's hierarchy
  poses     write a contact-distance pose list for two meshes
  bench     every collision method against brute force on a peg and a ring
  broadphase  overlapping pairs of moving boxes, frame by frame
  pipeline  the whole collision pipeline on a scene of meshes, frame by frame
  render    draw a mesh or assembly file to PNG (with the hand of a glove trace)
  glove     convert glove recordings, sample glove plans, check traces
  capture   replay failure-capture files written by 'run --capture'
  version   print the version

'dovetail <command> --help' describes a command.
exit codes: 0 success, 1 input error, 2 usage error, 3 failed check.
)";

struct Command {
  std::string_view name;
  int (*run)(std::span<const std::string>);
};

int version_command(std::span<const std::string> args) {
  const dovetail::cli::Args parsed("version", args, {}, {});
  if (parsed.help()) {
    std::fputs("usage: dovetail version\n\nPrints the version of dovetail.\n", stdout);
    return kExitOk;
  }
  parsed.expect_positional(0, "no arguments");
  std::printf("dovetail %s\n", DOVETAIL_VERSION);
  return kExitOk;
}

constexpr Command kCommands[] = {
    {"run", dovetail::cli::run_command},
    {"replay", dovetail::cli::replay_command},
    {"regress", dovetail::cli::regress_command},
    {"check", dovetail::cli::check_command},
    {"new", dovetail::cli::new_command},
    {"reference", dovetail::cli::reference_command},
    {"bench", dovetail::cli::bench_command},
    {"query", dovetail::cli::query_command},
    {"inspect", dovetail::cli::inspect_command},
    {"poses", dovetail::cli::poses_command},
    {"broadphase", dovetail::cli::broadphase_command},
    {"pipeline", dovetail::cli::pipeline_command},
    {"render", dovetail::cli::render_command},
    {"glove", dovetail::cli::glove_command},
    {"capture", dovetail::cli::capture_command},
    {"version", version_command},
};

int dispatch(const std::vector<std::string>& args) {
  if (args.empty()) {
    std::fputs(kUsage, stderr);
    return kExitUsage;
  }
  const std::string& name = args[0];
  if (name == "--help" || name == "-h" || name == "help") {
    std::fputs(kUsage, stdout);
    return kExitOk;
  }
  if (name == "--version") return version_command({});
  for (const Command& command : kCommands) {
    if (command.name == name) {
      return command.run(std::span<const std::string>(args).subspan(1));
    }
  }
  std::vector<std::string> names;
  for (const Command& command : kCommands) names.emplace_back(command.name);
  const std::string hint = dovetail::scripting::did_you_mean(name, names);
  throw dovetail::cli::UsageError("unknown command '" + name + "'" +
                                  (hint.empty() ? " (see 'dovetail --help')" : hint));
}

/// Prints `message` whole: a control byte a file brought in is written as
/// \xNN (tabs and line ends stay).
int report(const std::string& message, int code) {
  std::fprintf(stderr, "dovetail: %s\n",
               dovetail::engine::escape_control_bytes(message, "\n\t").c_str());
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  int code = kExitOk;
  try {
    code = dispatch(std::vector<std::string>(argv + 1, argv + argc));
  } catch (const dovetail::cli::UsageError& e) {
    code = report(e.what(), kExitUsage);
  } catch (const dovetail::cli::InputError& e) {
    code = report(e.what(), kExitInputError);
  } catch (const dovetail::scripting::ScenarioError& e) {
    code = report(e.what(), kExitInputError);
  } catch (const dovetail::scripting::ScriptError& e) {
    code = report(e.what(), kExitInputError);
  } catch (const dovetail::engine::PoseListError& e) {
    code = report(e.what(), kExitInputError);
  } catch (const dovetail::collision::MeshError& e) {
    code = report(e.what(), kExitInputError);
  } catch (const std::filesystem::filesystem_error& e) {
    // "PATH: File name too long", not the library's "filesystem error: status: ...".
    const std::string path = e.path1().empty() ? std::string() : e.path1().string() + ": ";
    code = report(path + e.code().message(), kExitInputError);
  } catch (const std::bad_alloc&) {
    code = report("out of memory", kExitInputError);
  } catch (const std::exception& e) {
    code = report(e.what(), kExitInputError);
  } catch (...) {
    code = report("unexpected failure", kExitInputError);
  }
  if (std::fflush(stdout) != 0 || std::ferror(stdout)) {
    return report("cannot write to standard output", kExitInputError);
  }
  return code;
}
