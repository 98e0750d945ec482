// Collision time of whole scenarios: each scenario run with every pair on the
// OBB tree (the pipeline's former default, `dovetail run --method obb`) and
// with the plans the pipeline makes per pair (collision::PairPlan, the
// default), and optionally with a tolerance; runs interleaved. Per scenario:
// the median over the runs of the collision milliseconds of the whole run
// (the pipeline's steps, hull and hierarchy building included: the sum of
// the report's per-frame collision times), and whether the outcome equals
// the first configuration's: status, every expectation's verdict, the events
// (frame, kind, parts), the contact statistics and the state hash.
//
//   build/bench/scenario_bench [--runs R] [--slowest K] [--tolerance-m T]
//                              [SCENARIO.lua ... | FOLDER]
//
// --slowest K adds, per scenario, the median collision time of the run's K
// slowest frames: those that build hulls and hierarchies, as a rule.
//
// Without scenarios: every *.lua in scenarios/.

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "bench_util.h"
#include "dovetail/scripting/scenario_run.h"

namespace {

using dovetail::bench::median;
namespace fs = std::filesystem;
namespace scripting = dovetail::scripting;

struct Config {
  const char* name;
  std::optional<dovetail::collision::Method> method;
  std::optional<double> tolerance_m;
};

double collision_ms(const scripting::RunOutcome& o) {
  double sum = 0;
  for (const auto& t : o.report.timings) sum += t.collision_ms;
  return sum;
}

/// The collision milliseconds of the run's `count` slowest frames (those
/// that build hulls and hierarchies, as a rule).
double slowest_frames_ms(const scripting::RunOutcome& o, std::size_t count) {
  std::vector<double> ms;
  for (const auto& t : o.report.timings) ms.push_back(t.collision_ms);
  count = std::min(count, ms.size());
  std::partial_sort(ms.begin(), ms.begin() + static_cast<std::ptrdiff_t>(count), ms.end(),
                    std::greater<>());
  double sum = 0;
  for (std::size_t i = 0; i < count; ++i) sum += ms[i];
  return sum;
}

/// What must not change when only the collision pipeline's plan does.
bool same_outcome(const scripting::RunOutcome& x, const scripting::RunOutcome& y) {
  if (x.status != y.status || x.expectations.size() != y.expectations.size()) return false;
  for (std::size_t i = 0; i < x.expectations.size(); ++i) {
    if (x.expectations[i].passed != y.expectations[i].passed) return false;
  }
  return x.report.events == y.report.events && x.report.contacts == y.report.contacts &&
         x.report.state_hash == y.report.state_hash;
}

std::vector<fs::path> lua_files(const fs::path& folder) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (entry.is_regular_file() && entry.path().extension() == ".lua")
      files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace

int main(int argc, char** argv) {
  const char* program = "scenario_bench";
  int runs = 5;
  std::size_t slowest = 0;
  std::optional<double> tolerance;
  std::vector<fs::path> scenarios;
  for (int i = 1; i < argc; ++i) {
    const bool has_value = i + 1 < argc;
    if (!std::strcmp(argv[i], "--runs") && has_value) {
      runs = static_cast<int>(dovetail::bench::whole(program, "--runs", argv[++i], 1, 1000));
    } else if (!std::strcmp(argv[i], "--slowest") && has_value) {
      slowest = static_cast<std::size_t>(
          dovetail::bench::whole(program, "--slowest", argv[++i], 1, 1000000));
    } else if (!std::strcmp(argv[i], "--tolerance-m") && has_value) {
      tolerance = dovetail::bench::real(program, "--tolerance-m", argv[++i], 0);
    } else if (argv[i][0] == '-') {
      std::fprintf(
          stderr,
          "usage: %s [--runs R] [--slowest K] [--tolerance-m T] [SCENARIO.lua ... | FOLDER]\n",
          program);
      return 2;
    } else if (fs::is_directory(argv[i])) {
      for (const fs::path& f : lua_files(argv[i])) scenarios.push_back(f);
    } else {
      scenarios.emplace_back(argv[i]);
    }
  }
  if (scenarios.empty()) scenarios = lua_files("scenarios");
  if (scenarios.empty()) {
    std::fprintf(stderr, "%s: no scenarios given and none in scenarios/\n", program);
    return 2;
  }

  std::vector<Config> configs = {{"obb everywhere", dovetail::collision::Method::kObb, 0.0},
                                 {"planned", std::nullopt, 0.0}};
  if (tolerance) configs.push_back({"planned, tolerance", std::nullopt, *tolerance});

  std::printf(
      "# collision ms per run (pipeline steps, hull and hierarchy building included), "
      "median of %d interleaved runs\n",
      runs);
  std::printf("%-32s", "scenario");
  for (const Config& c : configs) std::printf(" %20s", c.name);
  std::printf("  outcome\n");
  std::vector<double> totals(configs.size(), 0);
  bool all_same = true;
  for (const fs::path& file : scenarios) {
    std::vector<std::vector<double>> ms(configs.size()), slow_ms(configs.size());
    std::vector<scripting::RunOutcome> outcomes(configs.size());
    for (int r = 0; r < runs; ++r) {
      for (std::size_t c = 0; c < configs.size(); ++c) {
        scripting::RunOptions options;
        options.method = configs[c].method;
        options.tolerance_m = configs[c].tolerance_m;
        outcomes[c] = scripting::run_scenario(file, options);
        if (outcomes[c].status == scripting::RunOutcome::Status::kError) {
          std::fprintf(stderr, "%s: %s\n", file.string().c_str(), outcomes[c].error.c_str());
          return 1;
        }
        ms[c].push_back(collision_ms(outcomes[c]));
        if (slowest) slow_ms[c].push_back(slowest_frames_ms(outcomes[c], slowest));
      }
    }
    std::printf("%-32s", file.stem().string().c_str());
    for (std::size_t c = 0; c < configs.size(); ++c) {
      const double m = median(ms[c]);
      totals[c] += m;
      std::printf(" %20.2f", m);
    }
    std::string verdict;
    for (std::size_t c = 1; c < configs.size(); ++c) {
      const bool same = same_outcome(outcomes[0], outcomes[c]);
      if (configs[c].tolerance_m.value_or(0) == 0) all_same = all_same && same;
      verdict += std::string(c > 1 ? ", " : "") + (same ? "same" : "DIFFERENT") + " (" +
                 configs[c].name + ")";
    }
    std::printf("  %s\n", verdict.c_str());
    if (slowest) {
      std::printf("%-32s", ("  of which " + std::to_string(slowest) + " slowest frames").c_str());
      for (std::size_t c = 0; c < configs.size(); ++c) std::printf(" %20.2f", median(slow_ms[c]));
      std::printf("\n");
    }
  }
  std::printf("%-32s", "total");
  for (double t : totals) std::printf(" %20.2f", t);
  std::printf("\n");
  for (std::size_t c = 1; c < configs.size(); ++c) {
    std::printf("%s / %s: %.3f (saves %.1f %%)\n", configs[c].name, configs[0].name,
                totals[c] / totals[0], 100 * (1 - totals[c] / totals[0]));
  }
  std::printf("exact outcomes identical: %s\n", all_same ? "yes" : "NO");
  return all_same ? 0 : 1;
}
