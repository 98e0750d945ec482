// Scripting overhead: the frame time of a 1,000-part scene that a hand sweeps
// through, with 100 event rules and without any, run interleaved; the median
// of each and their ratio.
//
//   build/bench/scripting_bench [--runs R] [--parts N] [--rules K]

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "bench_util.h"
#include "dovetail/scripting/scenario_run.h"

namespace {

using dovetail::bench::median;

using dovetail::scripting::RunOutcome;

/// A cubic grid of n boxes (10 mm, 30 mm apart) and a hand sweeping through
/// its middle layers; `rules` event rules on the boxes and the hand.
std::string scenario(int n, int rules) {
  const int side = static_cast<int>(std::ceil(std::cbrt(static_cast<double>(n))));
  std::string s =
      "return scenario {\n  name = \"grid\", units = \"mm\", duration = 3,\n  parts = {\n";
  char line[256];
  for (int i = 0; i < n; ++i) {
    const int x = i % side, y = (i / side) % side, z = i / (side * side);
    std::snprintf(
        line, sizeof line,
        "    box_%04d = part { shape = box { size = { 10, 10, 10 } }, at = { %d, %d, %d } },\n", i,
        30 * x, 30 * y, 30 * z);
    s += line;
  }
  s += "  },\n  hand = glove { plan = \"sweep.plan\" },\n  rules = {\n";
  for (int r = 0; r < rules; ++r) {
    const int a = (r * 37) % n, b = (r * 91 + 5) % n;
    switch (r % 5) {
      case 0:
      case 1:
        std::snprintf(line, sizeof line,
                      "    rule { when = touches(\"hand\", \"box_%04d\"), act = { highlight "
                      "\"box_%04d\" } },\n",
                      a, a);
        break;
      case 2:
        std::snprintf(line, sizeof line,
                      "    rule { when = separates(\"hand\", \"box_%04d\"), act = { unhighlight "
                      "\"box_%04d\" } },\n",
                      a, a);
        break;
      case 3:
        std::snprintf(
            line, sizeof line,
            "    rule { when = touches(\"box_%04d\", \"box_%04d\"), act = { log \"touch\" } },\n",
            a, b);
        break;
      default:
        std::snprintf(line, sizeof line,
                      "    rule { when = every(0.25), unless = touching(\"hand\", \"box_%04d\"), "
                      "act = { log \"tick\" } },\n",
                      a);
    }
    s += line;
  }
  s += "  },\n}\n";
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 5, parts = 1000, rules = 100;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--runs") == 0)
      runs = static_cast<int>(
          dovetail::bench::whole("scripting_bench", "--runs", argv[i + 1], 1, 1000));
    if (std::strcmp(argv[i], "--parts") == 0)
      parts = static_cast<int>(
          dovetail::bench::whole("scripting_bench", "--parts", argv[i + 1], 1, 1000000));
    if (std::strcmp(argv[i], "--rules") == 0)
      rules = static_cast<int>(
          dovetail::bench::whole("scripting_bench", "--rules", argv[i + 1], 0, 1000000));
  }
  const auto dir = std::filesystem::temp_directory_path() / "dovetail_scripting_bench";
  std::filesystem::create_directories(dir);
  // The hand sweeps along x through the grid's middle, down a layer, and back.
  std::ofstream(dir / "sweep.plan") << "start -0.08 0.135 0.135  0.7071068 0 0 0.7071068\n"
                                       "reach 1.4 0.36 0.135 0.135  0.7071068 0 0 0.7071068\n"
                                       "reach 0.2 0.36 0.105 0.135  0.7071068 0 0 0.7071068\n"
                                       "reach 1.4 -0.08 0.105 0.135  0.7071068 0 0 0.7071068\n";
  std::ofstream(dir / "with_rules.lua") << scenario(parts, rules);
  std::ofstream(dir / "without_rules.lua") << scenario(parts, 0);
  std::vector<double> with_ms, without_ms;
  std::uint64_t frames = 0, fired = 0;
  std::size_t events = 0;
  for (int r = 0; r < runs; ++r) {
    for (const bool with : {false, true}) {
      const RunOutcome o =
          dovetail::scripting::run_scenario(dir / (with ? "with_rules.lua" : "without_rules.lua"));
      if (o.status == RunOutcome::Status::kError) {
        std::fprintf(stderr, "scripting_bench: %s\n", o.error.c_str());
        return 1;
      }
      frames = o.report.frames;
      (with ? with_ms : without_ms).push_back(1000 * o.loop_seconds / static_cast<double>(frames));
      if (with) {
        fired = o.rules_fired;
        events = o.report.events.size();
      }
    }
  }
  const double a = median(without_ms), b = median(with_ms);
  std::printf("scene: %d parts, a hand sweeping through; %llu frames; %zu timeline events\n", parts,
              static_cast<unsigned long long>(frames), events);
  std::printf("%-24s %10s %10s %10s\n", "", "median ms", "min ms", "max ms");
  std::printf("%-24s %10.3f %10.3f %10.3f\n", "without rules", a,
              *std::min_element(without_ms.begin(), without_ms.end()),
              *std::max_element(without_ms.begin(), without_ms.end()));
  char label[64];
  std::snprintf(label, sizeof label, "with %d rules", rules);
  std::printf("%-24s %10.3f %10.3f %10.3f\n", label, b,
              *std::min_element(with_ms.begin(), with_ms.end()),
              *std::max_element(with_ms.begin(), with_ms.end()));
  std::printf("rules fired: %llu; overhead (median with / median without - 1): %+.1f %%\n",
              static_cast<unsigned long long>(fired), 100 * (b / a - 1));
  std::filesystem::remove_all(dir);
  return 0;
}
