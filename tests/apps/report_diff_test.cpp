#include "report_diff.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace dovetail::cli {
namespace {

using json = nlohmann::ordered_json;

/// A small report of the scenario at `file` whose step was done at `done_at`.
json report(const std::string& file, double done_at) {
  const std::string folder = file.substr(0, file.rfind('/') + 1);
  json r;
  r["format"] = "dovetail-scenario-report";
  r["file"] = file;
  r["outcome"] = "passed";
  r["expectations"] = json::array(
      {{{"expect", "steps_in_order({ \"insert\" })"}, {"where", file + ":42"}, {"passed", true}}});
  r["steps"] = json::array({{{"name", "insert"}, {"done_at", done_at}}});
  r["warnings"] = json::array({folder + "../assets/peg.stl: 3 open edges"});
  r["simulation"] = {
      {"state_hash", "0x01"},
      {"events", json::array({{{"frame", 1}, {"kind", "grasped"}, {"a", "peg"}, {"b", "hand"}}})}};
  return r;
}

std::vector<std::string> changes(const json& was, const json& now, double tolerance = 0) {
  std::size_t total = 0;
  std::vector<std::string> out;
  for (const ReportChange& c : report_changes(was, now, 100, total, tolerance)) {
    out.push_back(c.str());
  }
  EXPECT_EQ(total, out.size());
  return out;
}

TEST(ReportDiff, TheSameReportInAnotherFolderHasNoChange) {
  EXPECT_TRUE(
      changes(report("/a/s/peg.lua", 2.5), report("/elsewhere/deeper/s/peg.lua", 2.5)).empty());
}

TEST(ReportDiff, AChangedValueIsNamedByItsPlaceAndBothValues) {
  EXPECT_EQ(changes(report("s/peg.lua", 2.5), report("s/peg.lua", 2.25)),
            std::vector<std::string>{"steps[insert].done_at: 2.25, was 2.5"});
}

TEST(ReportDiff, AnEventMoreIsCountedAndShown) {
  json was = report("peg.lua", 1);
  json now = was;
  now["simulation"]["events"].push_back({{"frame", 9}, {"kind", "released"}, {"a", "peg"}});
  EXPECT_EQ(changes(was, now),
            (std::vector<std::string>{
                "simulation.events entries: 2, was 1",
                R"(simulation.events[1]: {"frame":9,"kind":"released","a":"peg"}, was null)"}));
}

TEST(ReportDiff, AnEventInsertedInTheTimelineIsOneChangeNotAShift) {
  // Ten events; the new run has one more in the middle, one fewer near the
  // end, and one whose frame moved: three differences, the later events
  // matched again rather than each compared with its neighbour.
  json was = report("peg.lua", 1);
  json& events = was["simulation"]["events"];
  events = json::array();
  for (int k = 0; k < 10; ++k) {
    events.push_back({{"frame", 10 * k},
                      {"kind", k % 2 ? "contact_begin" : "contact_end"},
                      {"a", "peg"},
                      {"b", "block"}});
  }
  json now = was;
  json& later = now["simulation"]["events"];
  later.insert(later.begin() + 4, json{{"frame", 35}, {"kind", "released"}, {"a", "peg"}});
  later.erase(later.begin() + 9);  // the baseline's events[8]
  later[2]["frame"] = 21;          // the baseline's events[2], moved a frame
  EXPECT_EQ(
      changes(was, now),
      (std::vector<std::string>{
          "simulation.events[2].frame: 21, was 20",
          R"(simulation.events[4]: {"frame":35,"kind":"released","a":"peg"}, was null)",
          R"(simulation.events[8] of the baseline: gone, was {"frame":80,"kind":"contact_end","a":"peg","b":"block"})"}));
}

TEST(ReportDiff, TwoLongTextsAreShownWhereTheyDiffer) {
  json was = report("peg.lua", 1);
  json now = was;
  const std::string start(300, 'a');
  was["note"] = start + " then one ending";
  now["note"] = start + " then another ending";
  const std::vector<std::string> found = changes(was, now);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_NE(found[0].find("then another ending\", was ...a"), std::string::npos) << found[0];
  EXPECT_NE(found[0].find("then one ending\""), std::string::npos) << found[0];
}

TEST(ReportDiff, AnotherEntryInAListsPlaceIsOneChange) {
  json was = report("peg.lua", 1);
  json now = was;
  now["steps"][0]["name"] = "seat";
  now["steps"][0]["done_at"] = 3;
  EXPECT_EQ(changes(was, now),
            (std::vector<std::string>{
                R"(steps[0]: {"name":"seat","done_at":3}, was {"name":"insert","done_at":1.0})"}));
}

TEST(ReportDiff, AFieldOnlyOneReportHasIsAChange) {
  json was = report("peg.lua", 1);
  json now = was;
  now["error"] = "peg.lua:3: boom";
  was.erase("warnings");
  // The error first, the first thing a change should say; without its line.
  EXPECT_EQ(changes(was, now), (std::vector<std::string>{
                                   R"(error: "peg.lua: boom", was null)",
                                   R"(warnings: ["../assets/peg.stl: 3 open edges"], was null)"}));
}

TEST(ReportDiff, AnErrorOnlyTheBaselineHadComesFirst) {
  json was = report("peg.lua", 1);
  json now = report("peg.lua", 2);
  was["error"] = "peg.lua:3: boom";
  const std::vector<std::string> found = changes(was, now);
  ASSERT_FALSE(found.empty());
  EXPECT_EQ(found.front(), R"(error: null, was "peg.lua: boom")");
}

TEST(ReportDiff, PathsAreReadOnlyWhereTheyBegin) {
  // The folder "s" in "../assets/" is no path: only "s/" starting a path is
  // the scenario's folder. And "." is a folder too.
  for (const std::string& folder : {std::string("s"), std::string(".")}) {
    json was = report(folder + "/plate.lua", 1);
    json now = report("/home/ci/checkout/s/plate.lua", 1);
    was["warnings"] = json::array({folder + "/../assets/plate.gltf: 3 open edges"});
    now["warnings"] = json::array({"/home/ci/checkout/s/../assets/plate.gltf: 3 open edges"});
    EXPECT_TRUE(changes(was, now).empty()) << folder;
  }
}

TEST(ReportDiff, LongTextsAreReadInOnePass) {
  // Equal texts are not read for numbers; a long run of digits is one number.
  json was = report("peg.lua", 1);
  was["messages"] = json::array({{{"text", std::string(200000, '7')}}});
  json now = was;
  EXPECT_TRUE(changes(was, now, 1e-9).empty());
  now["messages"][0]["text"] = std::string(199999, '7') + "8";
  EXPECT_TRUE(changes(was, now, 1e-9).empty());  // 7.7e199999 overflows alike
}

TEST(ReportDiff, ATextNestedDeeperThanAnyReportIsNoReport) {
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  EXPECT_THROW(parse_report(deep), std::runtime_error);
  EXPECT_THROW(parse_report("{"), std::runtime_error);
  EXPECT_TRUE(is_scenario_report(parse_report(R"({"format": "dovetail-scenario-report"})")));
}

TEST(ReportDiff, AClauseMovedToAnotherLineIsNoChange) {
  json was = report("/a/peg.lua", 1);
  json now = report("/a/peg.lua", 1);
  now["expectations"][0]["where"] = "/a/peg.lua:43";
  was["messages"] = json::array({{{"text", "warning at /a/peg.lua:12: x"}}});
  now["messages"] = json::array({{{"text", "warning at /a/peg.lua:13: x"}}});
  EXPECT_TRUE(changes(was, now).empty());
  now["messages"][0]["text"] = "warning at /a/peg.lua:13: y";
  EXPECT_EQ(changes(was, now),
            std::vector<std::string>{
                R"(messages[0].text: "warning at peg.lua: y", was "warning at peg.lua: x")"});
}

TEST(ReportDiff, AToleranceReadsTheNumbersInTexts) {
  json was = report("peg.lua", 1);
  json now = report("peg.lua", 1);
  was["expectations"][0]["detail"] = "'a' and 'b' overlapped 1.214e-14 mm at t=0.5 s";
  now["expectations"][0]["detail"] = "'a' and 'b' overlapped 1.6e-14 mm at t=0.5 s";
  EXPECT_EQ(changes(was, now).size(), 1U);
  EXPECT_TRUE(changes(was, now, 1e-9).empty());
  now["expectations"][0]["detail"] = "'a' and 'b' overlapped 1.6e-14 mm at t=0.6 s";
  EXPECT_EQ(changes(was, now, 1e-9).size(), 1U);  // another time
  now["expectations"][0]["detail"] = "'a' and 'c' overlapped 1.214e-14 mm at t=0.5 s";
  EXPECT_EQ(changes(was, now, 1e-9).size(), 1U);  // another part
}

TEST(ReportDiff, TheOutcomeComesFirst) {
  json was = report("peg.lua", 1);
  json now = report("peg.lua", 2);
  was["scenario"] = "p";
  now["scenario"] = "Peg";
  now["outcome"] = "failed";
  const std::vector<std::string> found = changes(was, now);
  ASSERT_FALSE(found.empty());
  EXPECT_EQ(found.front(), R"(outcome: "failed", was "passed")");
}

TEST(ReportDiff, ATolerancePassesNearNumbersAndTheStateHash) {
  json was = report("peg.lua", 2.5);
  json now = report("peg.lua", 2.5 + 1e-10);
  now["simulation"]["state_hash"] = "0x02";
  EXPECT_EQ(changes(was, now).size(), 2U);  // the time and the hash
  EXPECT_TRUE(changes(was, now, 1e-9).empty());
  EXPECT_EQ(changes(report("peg.lua", 2.5), report("peg.lua", 2.6), 1e-9).size(), 1U);
  // Relative to the larger number, absolute below 1.
  json small_was = json{{"x", 1e-12}};
  EXPECT_TRUE(changes(small_was, json{{"x", 5e-10}}, 1e-9).empty());
  EXPECT_EQ(changes(json{{"x", 1000.0}}, json{{"x", 1000.002}}, 1e-9).size(), 1U);
}

TEST(ReportDiff, OnlyScenarioReportsAreReports) {
  EXPECT_TRUE(is_scenario_report(report("peg.lua", 1)));
  EXPECT_FALSE(is_scenario_report(json::parse(R"({"format": 3})")));
  EXPECT_FALSE(is_scenario_report(json::parse("[1, 2]")));
  EXPECT_FALSE(is_scenario_report(json()));
}

}  // namespace
}  // namespace dovetail::cli
