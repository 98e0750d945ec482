/// \file scenario_commands.cpp
/// `dovetail run`, `replay`, `check`, `new` and `reference`: scenarios from
/// the command line (regress_command.cpp runs whole folders of them).

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cli.h"
#include "commands.h"
#include "dovetail/engine/paths.h"
#include "dovetail/engine/pose_list.h"
#include "dovetail/scripting/scenario_run.h"

namespace dovetail::cli {

namespace {

constexpr const char* kRunHelp =
    R"(usage: dovetail run [SCENARIO] [--trace T] [--record T] [--report R.json]
                    [--render DIR [--every N]] [--threads N] [--quiet]
                    [--method METHOD] [--capture DIR [--cross-check METHOD]]

Runs a Lua assembly scenario headless: the scene, the hand driven by the
scenario's glove (or --trace), the rules and steps frame by frame, then checks
the expectations. Prints a summary; exits 0 when every expectation holds,
3 when one fails (the reasons on stderr), 1 when the scenario cannot be loaded
or its script fails. Without SCENARIO, runs the first shipped scenario
(scenarios/ in file-name order).

  --trace T       replay this glove trace instead of the scenario's glove
  --record T      write the glove samples the run used as a trace
  --report R      write the JSON report (also written when the run fails)
  --render DIR    write DIR/final.png, and with --every N every N-th frame
  --threads N     collision worker threads (default 1; the report is the same)
  --quiet         no progress meter and no summary on stdout
  --method METHOD every exact pair on this hierarchy (boxtree, dop6, dop14, dop18,
                  dop26, aabb, obb, brute) instead of the plan the pipeline makes
                  per pair (the report's collision_plans say which and why)
  --capture DIR   failure capture: write every suspect collision query (a search
                  stopped at its iteration cap, a pose that is not finite, a
                  cross-check disagreement) with its inputs to DIR, to be
                  replayed with 'dovetail capture FILE'
  --cross-check METHOD
                  with --capture: decide every exact pair a second time with
                  METHOD (boxtree, dop6, dop14, dop18, dop26, aabb, obb, brute)
)";

constexpr const char* kReplayHelp =
    R"(usage: dovetail replay SCENARIO TRACE [--record T] [--report R.json]
                       [--render DIR [--every N]] [--threads N] [--quiet]
                       [--method METHOD] [--capture DIR [--cross-check METHOD]]

`dovetail run SCENARIO --trace TRACE`: replays a recorded glove trace in the
scenario. A trace recorded by `run --record` gives the identical report.
)";

constexpr const char* kCheckHelp =
    R"(usage: dovetail check SCENARIO

Loads the scenario and resolves every name without simulating: errors with
file and line, warnings for rules that can never fire. Exits 0 when it loads.
)";

constexpr const char* kNewHelp =
    R"(usage: dovetail new NAME [--out FILE]

Writes a commented starting scenario NAME.lua (or FILE) to edit; refuses to
overwrite an existing file.
)";

std::filesystem::path default_scenario() {
  std::vector<std::filesystem::path> folders = {"scenarios"};
#ifdef DOVETAIL_SCENARIO_DIR
  folders.emplace_back(DOVETAIL_SCENARIO_DIR);
#endif
  for (const auto& folder : folders) {
    const std::vector<std::filesystem::path> files = scenario_files(folder);
    if (!files.empty()) return files.front();
  }
  throw UsageError(
      "run: no scenario given and no scenarios/ folder found (see 'dovetail run --help')");
}

/// The run's options from the command line (run and replay share them).
scripting::RunOptions run_options(const Args& args, std::optional<std::filesystem::path> trace) {
  scripting::RunOptions options;
  options.trace = std::move(trace);
  if (auto v = args.value("record")) options.record = *v;
  if (auto v = args.value("render")) options.render_dir = *v;
  if (const std::optional<std::string> every = args.value("every")) {
    std::uint64_t n = 0;
    const auto [end, error] = std::from_chars(every->data(), every->data() + every->size(), n);
    if (error != std::errc() || end != every->data() + every->size() || n == 0) {
      throw UsageError(args.command() +
                       ": --every must be a positive integer (every N-th frame), "
                       "not '" +
                       *every + "'");
    }
    options.render_every = n;
  }
  if (args.value("every") && !options.render_dir)
    throw UsageError(args.command() + ": --every needs --render DIR");
  options.threads = static_cast<int>(args.integer("threads", 0, 1024).value_or(1));
  options.progress = !args.flag("quiet") && stderr_is_terminal();
  if (auto v = args.value("method")) {
    options.method = collision::parse_method(*v);
    if (!options.method)
      throw UsageError(args.command() + ": unknown --method '" + *v + "' (" + method_list() + ")");
  }
  if (auto v = args.value("capture")) options.capture_dir = *v;
  if (auto v = args.value("cross-check")) {
    if (!options.capture_dir)
      throw UsageError(args.command() + ": --cross-check needs --capture DIR");
    options.cross_check = collision::parse_method(*v);
    if (!options.cross_check) {
      throw UsageError(args.command() + ": unknown --cross-check method '" + *v + "' (" +
                       method_list() + ")");
    }
  }
  // The folders last, once every option is known to be right.
  if (options.render_dir) make_folder(*options.render_dir);
  if (options.capture_dir) make_folder(*options.capture_dir);
  return options;
}

/// A scenario's text (its name, a step's, a warning) as the terminal shows
/// it: control bytes as \xNN, so that a script never drives the terminal.
std::string shown(const std::string& text) { return engine::escape_control_bytes(text); }

void write_report(const std::string& path, const scripting::RunOutcome& outcome) {
  std::ofstream out(path, std::ios::binary);
  out << outcome.to_json();
  out.flush();
  if (!out) throw InputError(path + ": cannot be written");
}

/// Warnings, failures and suspect queries, on standard error.
void print_problems(const scripting::RunOptions& options, const scripting::RunOutcome& outcome) {
  if (outcome.old_frames_removed > 0) {
    std::fprintf(stderr, "dovetail: note: removed %zu frame%s an earlier run left in %s\n",
                 outcome.old_frames_removed, outcome.old_frames_removed == 1 ? "" : "s",
                 options.render_dir->string().c_str());
  }
  for (const std::string& w : outcome.warnings) {
    std::fprintf(stderr, "warning: %s\n", shown(w).c_str());
  }
  if (options.capture_dir && outcome.suspect_queries > 0) {
    std::fprintf(stderr, "warning: %zu suspect collision queries, %zu capture files in %s\n",
                 outcome.suspect_queries, outcome.captures.size(),
                 options.capture_dir->string().c_str());
  }
  const std::string failures = outcome.failure_summary();
  if (!failures.empty()) std::fputs(failures.c_str(), stderr);
}

/// The summary on standard output: outcome, steps, state hash, final frame,
/// and for a failure capture that found nothing, that it looked.
void print_summary(const scripting::RunOptions& options, const scripting::RunOutcome& outcome) {
  std::size_t passed = 0;
  for (const auto& e : outcome.expectations) passed += e.passed ? 1 : 0;
  // A run that stopped on an error before the end judged no expectation.
  const bool error =
      outcome.status == scripting::RunOutcome::Status::kError && outcome.expectations.empty();
  const std::string judged = error ? std::string()
                                   : std::to_string(passed) + "/" +
                                         std::to_string(outcome.expectations.size()) +
                                         " expectations, ";
  std::printf("%s: %s (%s%llu frames, %.2f s wall)\n", shown(outcome.name).c_str(),
              std::string(scripting::status_name(outcome.status)).c_str(), judged.c_str(),
              static_cast<unsigned long long>(outcome.report.frames), outcome.wall_seconds);
  // A run that ran no frame did no step: its steps are not listed.
  for (const auto& s :
       outcome.report.frames > 0 ? outcome.steps : std::vector<scripting::StepOutcome>{}) {
    if (s.done_at) {
      std::printf("  step %-20s done at t=%.3f s%s\n", shown(s.name).c_str(), *s.done_at,
                  s.out_of_order ? " (out of order)" : "");
    } else {
      std::printf("  step %-20s not done\n", shown(s.name).c_str());
    }
  }
  // No frame, no state to hash (the scenario or its input was refused).
  if (outcome.report.frames > 0) {
    std::printf("  state_hash 0x%016llx\n",
                static_cast<unsigned long long>(outcome.report.state_hash));
  }
  if (outcome.final_frame)
    std::printf("  final frame: %s\n", outcome.final_frame->string().c_str());
  if (options.capture_dir && outcome.suspect_queries == 0 && outcome.report.frames > 0) {
    std::printf("  capture: no suspect collision query%s\n",
                options.cross_check ? ", every exact pair cross-checked" : "");
  }
}

int exit_code(scripting::RunOutcome::Status status) {
  switch (status) {
    case scripting::RunOutcome::Status::kPassed:
      return kExitOk;
    case scripting::RunOutcome::Status::kFailed:
      return kExitCheckFailed;
    case scripting::RunOutcome::Status::kError:
      return kExitInputError;
  }
  return kExitInputError;
}

/// Whether `file` is one the run writes into `folder`: with `--render`,
/// final.png and frame_NNNNNN.png; with `--capture`, NAME-HASH.capture.
bool written_into(const std::filesystem::path& folder, const std::filesystem::path& file,
                  bool render) {
  const std::filesystem::path parent = file.has_parent_path() ? file.parent_path() : ".";
  if (!engine::same_file(parent, folder)) return false;
  const std::string name = file.filename().string();
  if (!render) return name.ends_with(".capture");
  return name == "final.png" || scripting::is_frame_file_name(name);
}

/// The report and the recording, before the run and before its folders
/// are made: neither an input nor each other, nor the --render or
/// --capture folder or a file the run writes there (usage errors). Files
/// the scenario itself reads are refused by the run (RunOptions::outputs).
void check_outputs(const Args& args, const std::filesystem::path& scenario,
                   const std::optional<std::filesystem::path>& trace) {
  std::vector<std::string> inputs = {scenario.string()};
  if (trace) inputs.push_back(trace->string());
  const std::optional<std::string> report = args.value("report");
  const std::optional<std::string> record = args.value("record");
  const std::optional<std::string> render = args.value("render");
  const std::optional<std::string> capture = args.value("capture");
  const std::string& command = args.command();
  for (const auto& [option, out] : {std::pair{"report", report}, std::pair{"record", record}}) {
    if (!out) continue;
    for (const auto& [folder_option, folder] :
         {std::pair{"render", render}, std::pair{"capture", capture}}) {
      if (!folder) continue;
      if (engine::same_file(*out, *folder)) {
        throw UsageError(command + ": --" + option + " and --" + folder_option +
                         " name the same path '" + *out + "'");
      }
      if (written_into(*folder, *out, std::string_view(folder_option) == "render")) {
        throw UsageError(command + ": --" + option + " '" + *out + "' is a file that --" +
                         folder_option + " " + *folder + " writes");
      }
    }
    refuse_overwriting_input(command, *out, inputs);
  }
  if (report && record && engine::same_file(*report, *record)) {
    throw UsageError(command + ": --report and --record name the same file '" + *report + "'");
  }
}

int run_scenario_command(const Args& args, const std::filesystem::path& scenario,
                         std::optional<std::filesystem::path> trace) {
  // A missing scenario or trace is the run's error, like any other: the
  // report is written with it.
  check_outputs(args, scenario, trace);
  scripting::RunOptions options = run_options(args, std::move(trace));
  // Writable once the folders are made: a report may go into --render's.
  for (const char* option : {"report", "record"}) {
    if (const std::optional<std::string> out = args.value(option)) check_writable(*out);
  }
  if (auto path = args.value("report")) options.outputs.emplace_back(*path);
  const scripting::RunOutcome outcome = scripting::run_scenario(scenario, options);
  if (auto path = args.value("report"); path && !outcome.outputs_refused) {
    write_report(*path, outcome);
  }
  print_problems(options, outcome);
  if (!args.flag("quiet")) print_summary(options, outcome);
  return exit_code(outcome.status);
}

}  // namespace

int run_command(std::span<const std::string> argv) {
  const Args args("run", argv,
                  {"trace", "record", "report", "render", "every", "threads", "method", "capture",
                   "cross-check"},
                  {"quiet"});
  if (args.help()) {
    std::fputs(kRunHelp, stdout);
    return kExitOk;
  }
  if (args.positional().size() > 1)
    throw UsageError("run: one scenario at a time (see 'dovetail regress')");
  const std::filesystem::path scenario =
      args.positional().empty() ? default_scenario() : std::filesystem::path(args.positional()[0]);
  if (args.positional().empty() && !args.flag("quiet")) {
    std::fprintf(stderr, "dovetail: note: running the first shipped scenario, %s\n",
                 scenario.string().c_str());
  }
  std::optional<std::filesystem::path> trace;
  if (auto v = args.value("trace")) trace = *v;
  return run_scenario_command(args, scenario, trace);
}

int replay_command(std::span<const std::string> argv) {
  const Args args(
      "replay", argv,
      {"record", "report", "render", "every", "threads", "method", "capture", "cross-check"},
      {"quiet"});
  if (args.help()) {
    std::fputs(kReplayHelp, stdout);
    return kExitOk;
  }
  args.expect_positional(2, "a scenario and a trace");
  return run_scenario_command(args, args.positional()[0],
                              std::filesystem::path(args.positional()[1]));
}

int check_command(std::span<const std::string> argv) {
  const Args args("check", argv, {}, {});
  if (args.help()) {
    std::fputs(kCheckHelp, stdout);
    return kExitOk;
  }
  args.expect_positional(1, "a scenario");
  const std::filesystem::path file = args.positional()[0];
  if (!std::filesystem::exists(file)) throw InputError(file.string() + ": no such file");
  const scripting::Scenario s = scripting::check_scenario(file);
  for (const std::string& w : s.warnings) std::fprintf(stderr, "warning: %s\n", shown(w).c_str());
  const auto count = [](std::size_t n, const char* one, const char* many) {
    return std::to_string(n) + " " + (n == 1 ? one : many);
  };
  std::printf("%s: ok: '%s', %s, %s, %s, %s, %s%s\n", file.string().c_str(), shown(s.name).c_str(),
              count(s.parts.size(), "part", "parts").c_str(),
              count(s.mates.size(), "mate", "mates").c_str(),
              count(s.steps.size(), "step", "steps").c_str(),
              count(s.rules.size(), "rule", "rules").c_str(),
              count(s.expectations.size(), "expectation", "expectations").c_str(),
              s.glove ? ", a hand" : "");
  return kExitOk;
}

int new_command(std::span<const std::string> argv) {
  const Args args("new", argv, {"out"}, {});
  if (args.help()) {
    std::fputs(kNewHelp, stdout);
    return kExitOk;
  }
  args.expect_positional(1, "a name");
  std::string name = args.positional()[0];
  // "dovetail new peg.lua" means the scenario peg in peg.lua.
  if (name.size() > 4 && name.ends_with(".lua")) name.resize(name.size() - 4);
  if (const std::filesystem::path file = std::filesystem::path(name).filename();
      file.empty() || file == "." || file == "..") {
    throw UsageError("new: the name '" + name + "' names no file: dovetail new my_scenario");
  }
  const std::filesystem::path out = args.value("out").value_or(name + ".lua");
  if (std::filesystem::exists(out)) throw InputError(out.string() + ": exists; not overwritten");
  check_writable(out.string());
  std::ofstream file(out, std::ios::binary);
  file << scripting::starting_scenario(std::filesystem::path(name).filename().string(),
                                       out.string());
  file.flush();
  if (!file) throw InputError(out.string() + ": cannot be written: " + std::strerror(errno));
  // A name a shell would split or expand is quoted, so the hint can be pasted.
  std::string name_in_shell = out.string();
  if (name_in_shell.find_first_not_of(
          "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789._-/+,:@%") !=
      std::string::npos) {
    name_in_shell.insert(name_in_shell.begin(), '"');
    name_in_shell.push_back('"');
  }
  std::printf("wrote %s; try 'dovetail check %s', then 'dovetail run %s'\n", out.string().c_str(),
              name_in_shell.c_str(), name_in_shell.c_str());
  return kExitOk;
}

int reference_command(std::span<const std::string> argv) {
  const Args args("reference", argv, {}, {});
  if (args.help()) {
    std::fputs(
        "usage: dovetail reference\n\nPrints the scenario vocabulary as Markdown "
        "(the reference of docs/authoring.md).\n",
        stdout);
    return kExitOk;
  }
  args.expect_positional(0, "no arguments");
  std::fputs(scripting::reference_markdown().c_str(), stdout);
  return kExitOk;
}

}  // namespace dovetail::cli
