// Scenarios (scripting::check_scenario): the input is a scenario script,
// loaded and resolved in the Lua sandbox with small limits. Either it checks
// or it throws ScenarioError or ScriptError; nothing else may escape.
//
// The script is written to <scratch>/scenarios/fuzz.lua next to a link
// <scratch>/assets to the project's assets, so that the `../assets/...`
// paths of the seed scenarios resolve and the fuzzer gets past part loading.

#include <cstddef>
#include <cstdint>
#include <filesystem>

#include "dovetail/scripting/lua_host.h"
#include "dovetail/scripting/scenario.h"
#include "dovetail/scripting/scenario_run.h"
#include "fuzz_support.h"

#ifndef DOVETAIL_ASSETS_DIR
#error "DOVETAIL_ASSETS_DIR must name the project's assets folder"
#endif

using namespace dovetail;

namespace {

std::filesystem::path scenario_path() {
  const std::filesystem::path root = fuzz::scratch_dir();
  std::filesystem::create_directories(root / "scenarios");
  std::error_code ec;
  std::filesystem::create_directory_symlink(DOVETAIL_ASSETS_DIR, root / "assets", ec);
  return root / "scenarios" / "fuzz.lua";
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path path = scenario_path();
  fuzz::write_file(path, fuzz::as_text(data, size));
  scripting::SandboxLimits limits;
  limits.instructions_per_call = 2'000'000;
  limits.memory_bytes = std::size_t{32} << 20;
  limits.wall_seconds_per_call = 1.0;
  try {
    (void)scripting::check_scenario(path, limits);
  } catch (const scripting::ScenarioError&) {
  } catch (const scripting::ScriptError&) {
  }
  return 0;
}
