// Soak: the engine-piston scene for a long simulated time with a noisy glove
// (0.5 mm, 0.25 degree tracker noise: within the mate guidance's capture, so the
// piston goes in on every cycle instead of jamming once and staying behind)
// that pulls the piston out of its cylinder and pushes it back in every 3 s.
// Each duration runs in its own child process, so its peak memory (maxrss)
// is its own; the longest runs twice and both state hashes are printed.
//
//   build/bench/soak_bench [--minutes 1,10,60] [--threads N]
//
// Not part of CI: an hour of simulated time takes minutes of wall time.

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bench_util.h"
#include "dovetail/scripting/scenario_run.h"

namespace {

constexpr const char* kEngine =
    "/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";

/// The plan: the hand holds the rod with the piston in the bore, then for
/// `minutes` pulls it 150 mm up (1.2 s), waits, brings it back down (1.2 s), waits.
std::string plan(double minutes) {
  const char* q = "0.7071067811865476 0 0 -0.7071067811865476";
  std::ostringstream out;
  out << "start 0.020 0.075 0.380  " << q << " power\n";
  const int cycles = static_cast<int>(minutes * 60 / 3.0);
  for (int i = 0; i < cycles; ++i) {
    out << "reach 1.2  0.020 0.225 0.380  " << q << "\nwait 0.3\n";
    out << "reach 1.2  0.020 0.0755 0.380  " << q << "\nwait 0.3\n";
  }
  return out.str();
}

std::string scenario(const std::filesystem::path& parts, double minutes) {
  std::ostringstream s;
  s << "return scenario {\n  name = \"soak\", units = \"mm\", duration = " << minutes * 60 << ",\n"
    << "  parts = {\n"
    << "    engine = part { mesh = \"" << kEngine << "\", fixed = true },\n"
    << "    bench = part { shape = box { size = { 1000, 40, 800 } }, at = { 0, -201, 150 }, fixed "
       "= true },\n"
    << "    cylinder = part { shape = block_with_hole { size = { 140, 130, 140 }, hole = 93.6, "
       "depth = 100, "
       "sides = 96 }, at = { 0, -116, 320 }, fixed = true },\n"
    << "    piston_rod = part { mesh = \"" << (parts / "piston_rod.obj").string()
    << "\", at = { 0, -150.5, 320 }, turn = { x = -90 } },\n  },\n"
    << "  mates = { piston_in_cylinder = mate { part = \"piston_rod\", point = { 0, 0, 0 }, axis = "
       "\"-z\",\n"
    << "            into = \"cylinder\", at = { 0, -35, 0 }, along = \"-y\" } },\n"
    << "  hand = glove { plan = \"soak.plan\", holding = \"piston_rod\",\n"
    << "                 noise = { position = 0.5, angle = 0.25, joints = 0.5, seed = 7 } },\n"
    << "  expect = { max_penetration(0.01), no_contact(\"piston_rod\", \"engine\") },\n}\n";
  return s.str();
}

struct Result {
  double minutes = 0;
  double wall_s = 0;
  long maxrss_kb = 0;
  std::string line;  ///< what the child printed
};

Result run_child(const std::filesystem::path& dir, const std::filesystem::path& parts,
                 double minutes, int threads) {
  char name[32];
  std::snprintf(name, sizeof name, "m%d", static_cast<int>(minutes * 10));
  const std::filesystem::path sub = dir / name;
  std::filesystem::create_directories(sub);
  std::ofstream(sub / "soak.plan") << plan(minutes);
  std::ofstream(sub / "soak.lua") << scenario(parts, minutes);
  int fds[2];
  if (pipe(fds) != 0) std::exit(1);
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    dovetail::scripting::RunOptions options;
    options.threads = threads;
    const auto o = dovetail::scripting::run_scenario(sub / "soak.lua", options);
    std::size_t releases = 0, slides = 0;
    for (const auto& e : o.report.events) {
      releases += e.kind == dovetail::engine::EventKind::kRelease;
      slides += e.kind == dovetail::engine::EventKind::kSlideBegin;
    }
    char line[512];
    std::snprintf(line, sizeof line,
                  "status %s, frames %" PRIu64 ", state_hash 0x%016" PRIx64
                  ", slides %zu, releases %zu, deepest overlap %.4g mm%s%s",
                  std::string(dovetail::scripting::status_name(o.status)).c_str(), o.report.frames,
                  o.report.state_hash, slides, releases, o.max_penetration * 1000,
                  o.error.empty() ? "" : ", error: ", o.error.c_str());
    if (write(fds[1], line, std::strlen(line)) < 0) _exit(2);
    _exit(0);
  }
  close(fds[1]);
  Result r;
  r.minutes = minutes;
  char buffer[512];
  ssize_t n;
  while ((n = read(fds[0], buffer, sizeof buffer)) > 0)
    r.line.append(buffer, static_cast<std::size_t>(n));
  close(fds[0]);
  int status = 0;
  struct rusage usage {};
  wait4(pid, &status, 0, &usage);
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.maxrss_kb = usage.ru_maxrss;
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<double> minutes = {1, 10, 60};
  int threads = 1;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--minutes") == 0) {
      minutes.clear();
      std::stringstream list(argv[i + 1]);
      std::string item;
      while (std::getline(list, item, ',')) {
        minutes.push_back(dovetail::bench::real("soak_bench", "--minutes", item.c_str(), 0));
      }
    } else if (std::strcmp(argv[i], "--threads") == 0) {
      threads =
          static_cast<int>(dovetail::bench::whole("soak_bench", "--threads", argv[i + 1], 0, 1024));
    }
  }
  if (!std::filesystem::exists(kEngine)) {
    std::fprintf(stderr, "soak_bench: %s (assimp-testmodels) is not installed\n", kEngine);
    return 1;
  }
  const std::filesystem::path parts =
      std::filesystem::path(DOVETAIL_SOURCE_DIR) / "assets" / "parts";
  const auto dir = std::filesystem::temp_directory_path() / "dovetail_soak";
  std::filesystem::create_directories(dir);
  std::printf("%-10s %10s %14s  %s\n", "simulated", "wall s", "peak RSS MiB", "result");
  std::vector<double> all = minutes;
  all.push_back(minutes.back());  // the longest once more: the same hash?
  for (const double m : all) {
    const Result r = run_child(dir, parts, m, threads);
    std::printf("%6.1f min %10.1f %14.1f  %s\n", m, r.wall_s,
                static_cast<double>(r.maxrss_kb) / 1024, r.line.c_str());
    std::fflush(stdout);
  }
  std::filesystem::remove_all(dir);
  return 0;
}
