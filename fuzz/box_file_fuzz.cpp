// Box files of `dovetail broadphase`: the command runs on the input (the
// first byte picks the broad phase) and either succeeds or throws InputError
// naming the bad line. The reader lives in apps/broadphase_command.cpp.

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "cli.h"
#include "commands.h"
#include "fuzz_support.h"

using namespace dovetail;

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // The command prints a JSON summary per run; keep libFuzzer's output readable.
  if (std::freopen("/dev/null", "w", stdout) == nullptr) std::perror("freopen");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const char* const kMethods[] = {"grid", "sap", "octree", "brute"};
  const std::string method = kMethods[data[0] % 4];
  const std::filesystem::path path = fuzz::scratch_dir() / "boxes.txt";
  const std::filesystem::path pairs = fuzz::scratch_dir() / "pairs.txt";
  fuzz::write_file(path, fuzz::as_text(data + 1, size - 1));
  const std::vector<std::string> argv = {"--boxes", path.string(), "--method", method, "--out",
                                         pairs.string()};
  try {
    fuzz::require(cli::broadphase_command(argv) == cli::kExitOk, "broadphase succeeds or throws");
  } catch (const cli::InputError&) {
  }
  return 0;
}
