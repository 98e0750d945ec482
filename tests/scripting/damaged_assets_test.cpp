// Every shipped asset, trace, plan and scenario, truncated or with bytes
// overwritten, either still reads or fails with the reader's own error naming
// the file: never a crash, a hang or an unnamed failure.

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "../support/temp_dir.h"
#include "dovetail/engine/mesh_import.h"
#include "dovetail/interaction/glove_plan.h"
#include "dovetail/interaction/glove_trace.h"
#include "dovetail/scripting/lua_host.h"
#include "dovetail/scripting/scenario_run.h"

namespace dovetail::scripting {
namespace {

const std::filesystem::path kSource = std::filesystem::path(DOVETAIL_SCENARIO_DIR).parent_path();

std::string read_all(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

/// Damaged copies of `bytes`: cut at 1/8 ... 7/8, and with 16 bytes
/// overwritten by 0xff or by a NUL at five places.
std::vector<std::pair<std::string, std::string>> damaged(const std::string& bytes) {
  std::vector<std::pair<std::string, std::string>> out;
  for (int k = 1; k < 8; ++k) {
    out.emplace_back("cut at " + std::to_string(k) + "/8", bytes.substr(0, bytes.size() * k / 8));
  }
  for (int k = 1; k <= 5; ++k) {
    for (const char c : {'\xff', '\0'}) {
      std::string copy = bytes;
      const std::size_t at = bytes.size() * k / 6;
      for (std::size_t i = at; i < std::min(copy.size(), at + 16); ++i) copy[i] = c;
      out.emplace_back(std::string("16 bytes of ") + (c == '\0' ? "NUL" : "0xff") + " at " +
                           std::to_string(k) + "/6",
                       copy);
    }
  }
  return out;
}

std::vector<std::filesystem::path> files_in(const std::filesystem::path& folder,
                                            const std::string& extension) {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.path().extension() == extension) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

/// Runs `read` on every damaged copy of every file; it must return or throw
/// an exception whose message names the copy's file.
template <typename Read>
void check_damaged(const std::filesystem::path& folder, const std::string& extension, Read read) {
  const test::TempDir dir("dovetail_damaged");
  const auto files = files_in(folder, extension);
  ASSERT_FALSE(files.empty()) << folder;
  std::size_t errors = 0, copies = 0;
  for (const auto& file : files) {
    for (const auto& [how, bytes] : damaged(read_all(file))) {
      const auto copy = dir / ("damaged_" + file.filename().string());
      std::ofstream(copy, std::ios::binary) << bytes;
      ++copies;
      try {
        read(copy);
      } catch (const std::exception& e) {
        ++errors;
        EXPECT_NE(std::string(e.what()).find(copy.filename().string()), std::string::npos)
            << file.filename() << ", " << how << ": " << e.what();
      }
    }
  }
  EXPECT_GT(errors, 0u) << "no damaged copy of " << folder << "/*" << extension << " was refused";
  ::testing::Test::RecordProperty("copies", static_cast<int>(copies));
}

TEST(DamagedAssets, GlovePlans) {
  check_damaged(kSource / "assets" / "glove", ".plan",
                [](const std::filesystem::path& p) { interaction::read_plan(p); });
}

TEST(DamagedAssets, GloveTraces) {
  check_damaged(kSource / "assets" / "traces", ".csv",
                [](const std::filesystem::path& p) { interaction::read_trace(p); });
}

TEST(DamagedAssets, Meshes) {
  check_damaged(kSource / "assets" / "parts", ".obj",
                [](const std::filesystem::path& p) { engine::import_mesh(p); });
}

TEST(DamagedAssets, Scenarios) {
  // Checked, not run: relative asset paths no longer resolve from the temp folder,
  // which is one more error that must name the file.
  check_damaged(kSource / "scenarios", ".lua", [](const std::filesystem::path& p) {
    SandboxLimits limits;
    limits.instructions_per_call = 2'000'000;
    check_scenario(p, limits);
  });
}

}  // namespace
}  // namespace dovetail::scripting
