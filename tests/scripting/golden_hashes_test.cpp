// Golden hashes: every shipped scenario ends with the state hash written in
// scenarios/golden_hashes.txt, at 1, 2 and 8 collision threads and when run
// again in the same process. A scenario in the folder but not in the list
// fails, as does one in the list but not in the folder.
//
// DOVETAIL_UPDATE_GOLDEN=1 rewrites the list instead (GoldenHashes.UpdateWhenAsked),
// after checking that every scenario gives one hash at every thread count.

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "dovetail/scripting/scenario_run.h"

namespace dovetail::scripting {
namespace {

const std::filesystem::path kScenarios = DOVETAIL_SCENARIO_DIR;
const std::filesystem::path kGoldenFile = kScenarios / "golden_hashes.txt";
constexpr int kThreadCounts[] = {1, 2, 8, 1};  // the last: again, in the same process

const char* const kGoldenHeader =
    R"(# The final state hash of every shipped scenario (scenarios/*.lua), one line
# each: <file name> 0x<16 hex digits>. tests/scripting/golden_hashes_test.cpp
# runs each scenario at 1, 2 and 8 collision threads and again at 1, and
# requires every run to end with the hash written here; a scenario missing
# from this list fails.
#
# To update after a deliberate change of results (new physics, a new or
# changed scenario), from a Release build:
#   DOVETAIL_UPDATE_GOLDEN=1 build/tests/scripting/scripting_tests --gtest_filter='GoldenHashes.*'
# and commit this file in the same commit as the change, with the reason the
# results changed in the commit message.
)";

bool updating() {
  const char* value = std::getenv("DOVETAIL_UPDATE_GOLDEN");
  return value != nullptr && std::string(value) == "1";
}

std::string hex(std::uint64_t value) {
  char text[19];
  std::snprintf(text, sizeof text, "0x%016llx", static_cast<unsigned long long>(value));
  return text;
}

/// The golden list: file name to hash. Lines that are not `<name> 0x<16 hex>`
/// (comments and blank lines aside) go into `malformed`.
struct GoldenList {
  std::map<std::string, std::uint64_t> hashes{};
  std::vector<std::string> malformed{};
  bool found = false;
};

GoldenList read_golden() {
  GoldenList list;
  std::ifstream in(kGoldenFile);
  list.found = static_cast<bool>(in);
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string name, hash, rest;
    fields >> name >> hash;
    const bool hex_ok =
        hash.size() == 18 && hash.compare(0, 2, "0x") == 0 &&
        std::all_of(hash.begin() + 2, hash.end(), [](unsigned char c) { return std::isxdigit(c); });
    if (name.empty() || !hex_ok || (fields >> rest)) {
      list.malformed.push_back(kGoldenFile.filename().string() + ":" + std::to_string(number) +
                               ": '" + line + "'");
      continue;
    }
    list.hashes[name] = std::stoull(hash.substr(2), nullptr, 16);
  }
  return list;
}

std::set<std::string> shipped_scenarios() {
  std::set<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(kScenarios)) {
    if (entry.is_regular_file() && entry.path().extension() == ".lua") {
      names.insert(entry.path().filename().string());
    }
  }
  return names;
}

/// Every scenario in the folder or in the list.
std::vector<std::string> scenarios_to_check() {
  std::set<std::string> names = shipped_scenarios();
  for (const auto& [name, hash] : read_golden().hashes) names.insert(name);
  return {names.begin(), names.end()};
}

std::string threads_text(int threads) {
  return std::to_string(threads) + (threads == 1 ? " thread" : " threads");
}

std::uint64_t final_hash(const std::string& name, int threads) {
  RunOptions options;
  options.threads = threads;
  return run_scenario(kScenarios / name, options).report.state_hash;
}

TEST(GoldenHashes, TheListIsWellFormedAndNamesEveryShippedScenario) {
  if (updating()) GTEST_SKIP() << "DOVETAIL_UPDATE_GOLDEN=1: the list is being rewritten";
  const GoldenList golden = read_golden();
  ASSERT_TRUE(golden.found) << kGoldenFile << " is missing";
  for (const auto& line : golden.malformed)
    ADD_FAILURE() << "not '<file name> 0x<16 hex>': " << line;
  for (const auto& name : shipped_scenarios()) {
    EXPECT_TRUE(golden.hashes.contains(name))
        << name << " has no golden hash in " << kGoldenFile
        << " (DOVETAIL_UPDATE_GOLDEN=1 adds it; see the file's header)";
  }
}

/// Rewrites the list from runs at every thread count; runs only when asked.
TEST(GoldenHashes, UpdateWhenAsked) {
  if (!updating()) GTEST_SKIP() << "set DOVETAIL_UPDATE_GOLDEN=1 to rewrite " << kGoldenFile;
  std::string text = kGoldenHeader;
  for (const auto& name : shipped_scenarios()) {
    const std::uint64_t first = final_hash(name, kThreadCounts[0]);
    for (const int threads : std::span(kThreadCounts).subspan(1)) {
      const std::uint64_t hash = final_hash(name, threads);
      ASSERT_EQ(hash, first) << name << " at " << threads_text(threads) << ": state hash "
                             << hex(hash) << ", at " << threads_text(kThreadCounts[0]) << " "
                             << hex(first) << "; not writing " << kGoldenFile;
    }
    text += name + " " + hex(first) + "\n";
  }
  std::ofstream out(kGoldenFile, std::ios::binary | std::ios::trunc);
  out << text;
  ASSERT_TRUE(out.good()) << kGoldenFile << " cannot be written";
}

class GoldenHashes : public testing::TestWithParam<std::string> {};

TEST_P(GoldenHashes, TheFinalStateHashIsTheGoldenOneAtOneTwoAndEightThreads) {
  if (updating()) GTEST_SKIP() << "DOVETAIL_UPDATE_GOLDEN=1: the list is being rewritten";
  const std::string& name = GetParam();
  const GoldenList golden = read_golden();
  const auto listed = golden.hashes.find(name);
  ASSERT_NE(listed, golden.hashes.end()) << name << " has no golden hash in " << kGoldenFile;
  ASSERT_TRUE(std::filesystem::exists(kScenarios / name))
      << name << " is in " << kGoldenFile << " but not in " << kScenarios;
  for (const int threads : kThreadCounts) {
    const std::uint64_t hash = final_hash(name, threads);
    EXPECT_EQ(hash, listed->second) << name << " at " << threads_text(threads) << ": state hash "
                                    << hex(hash) << ", golden " << hex(listed->second);
  }
}

std::string test_name(const testing::TestParamInfo<std::string>& info) {
  std::string name = std::filesystem::path(info.param).stem().string();
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

INSTANTIATE_TEST_SUITE_P(Shipped, GoldenHashes, testing::ValuesIn(scenarios_to_check()), test_name);

}  // namespace
}  // namespace dovetail::scripting
