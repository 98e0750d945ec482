// Scenarios: loading (errors with file, line and "did you mean"), running
// (rules, steps, expectations), failing for the right reason, and the same
// report bits at any thread count and on replay.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <lua.hpp>
#include <map>
#include <regex>

#include "../support/temp_dir.h"
#include "dovetail/engine/mesh_import.h"
#include "dovetail/scripting/lua_host.h"
#include "dovetail/scripting/scenario_run.h"

namespace dovetail::scripting {
namespace {

const std::filesystem::path kScenarios = DOVETAIL_SCENARIO_DIR;

std::filesystem::path write(const test::TempDir& dir, const std::string& name,
                            const std::string& text) {
  const auto path = dir / name;
  std::ofstream(path) << text;
  return path;
}

/// The loader's error for `file`: a ScenarioError's message, or a test
/// failure and "" when the file loads.
std::string load_error(const std::filesystem::path& file) {
  LuaHost host({}, 1);
  try {
    load_scenario(host, file);
  } catch (const ScenarioError& e) {
    return e.what();
  }
  ADD_FAILURE() << file << " loaded";
  return "";
}

/// The run's log messages, (time, text), in order.
std::vector<std::pair<double, std::string>> logged_messages(const RunOutcome& o) {
  std::vector<std::pair<double, std::string>> logged;
  for (const Message& m : o.messages) {
    if (m.level == "log") logged.emplace_back(m.time, m.text);
  }
  return logged;
}

/// The texts of the run's log messages, in order.
std::vector<std::string> logged_texts(const RunOutcome& o) {
  std::vector<std::string> texts;
  for (const auto& [time, text] : logged_messages(o)) texts.push_back(text);
  return texts;
}

/// A scene without a hand: the peg is moved into the hole by a rule.
std::string moved_peg(const std::string& rules, const std::string& expect,
                      const std::string& extra = "") {
  return R"(return scenario {
  name = "moved peg", units = "mm", duration = 1,
  parts = {
    block = part { shape = block_with_hole { size = { 80, 60, 80 }, hole = 20.5, depth = 40 }, fixed = true },
    peg = part { shape = cylinder { diameter = 20, length = 60 }, at = { 0, 100, 0 }, turn = { x = 90 } },
    lid = part { shape = box { size = { 10, 10, 10 } }, at = { 100, 0, 0 }, fixed = true },
  },
  mates = {
    peg_in_hole = mate { part = "peg", point = { 0, 0, 60 }, axis = "z",
                         into = "block", at = { 0, -10, 0 }, along = "-y" },
  },
  steps = {
    step { "insert", done = mated "peg_in_hole" },
    step { "check", done = after(0.5) },
  },
  rules = {
)" + rules +
         R"(
  },
  expect = {
)" + expect +
         R"(
  },
)" + extra +
         "}\n";
}

TEST(Vocabulary, OfEquallyNearNamesTheOneSharingTheLongestStartIsSuggested) {
  const std::vector<std::string> nodes = {"nodes[25]_3", "nodes[5]_2"};
  EXPECT_EQ(nearest_name("nodes[5]_3", nodes), "nodes[5]_2");
  const std::vector<std::string> reversed = {"nodes[5]_2", "nodes[25]_3"};
  EXPECT_EQ(nearest_name("nodes[5]_3", reversed), "nodes[5]_2");
  // Too far from every name: none.
  const std::vector<std::string> far = {"bracket", "nut"};
  EXPECT_EQ(nearest_name("piston", far), std::nullopt);
}

TEST(ScenarioLoad, AMisspeltPartIsAnErrorWithFileLineAndASuggestion) {
  const test::TempDir dir("dovetail_scenario");
  const auto file =
      write(dir, "bad.lua",
            moved_peg("    rule { when = touches(\"peg\", \"blok\"), act = { log \"x\" } },", ""));
  const std::string what = load_error(file);
  EXPECT_NE(what.find("bad.lua:17: touches: no part 'blok' (did you mean 'block'?)"),
            std::string::npos)
      << what;
}

TEST(ScenarioLoad, AttachingAFixedPartOrAPartToItselfIsAnError) {
  // A fixed part never moves, so it cannot move with another; the other way
  // round is fine.
  const test::TempDir dir("dovetail_scenario");
  const std::string fixed = load_error(
      write(dir, "fixed.lua",
            moved_peg("    rule { when = after(0), act = { attach(\"block\", \"peg\") } },", "")));
  EXPECT_NE(fixed.find("fixed.lua:17: attach: 'block' is fixed, so it cannot move with 'peg' "
                       "(attach 'peg' to it instead)"),
            std::string::npos)
      << fixed;
  const std::string itself = load_error(
      write(dir, "itself.lua",
            moved_peg("    rule { when = after(0), act = { attach(\"peg\", \"peg\") } },", "")));
  EXPECT_NE(itself.find("itself.lua:17: attach: 'peg' cannot be attached to itself"),
            std::string::npos)
      << itself;
}

TEST(ScenarioLoad, TheScenarioTablesOwnFieldsAreNamedAtTheirLines) {
  // `return scenario { ... }` is a tail call, which keeps no line: the
  // loader finds the line of the file's `return scenario`, and below it the
  // field's own.
  const test::TempDir dir("dovetail_scenario");
  const std::string what = load_error(
      write(dir, "own.lua",
            "-- return scenario in a comment\n" + moved_peg("", "", "  durration = 1,\n")));
  EXPECT_NE(what.find("own.lua:23: scenario: unknown field 'durration' (did you mean 'duration'?)"),
            std::string::npos)
      << what;
}

TEST(ScenarioLoad, ACheckWarnsOfARuleAfterTheRunsEndAsTheRunDoes) {
  // A plan of 0.5 s: the run ends a second after it, at t=1.5 s.
  const test::TempDir dir("dovetail_scenario");
  write(dir, "short.plan", "start 0 0.2 0  1 0 0 0\nwait 0.5\n");
  const std::string file = write(dir, "late.lua", R"(return scenario {
  name = "late",
  parts = { a = part { shape = box { size = { 0.1, 0.1, 0.1 } } } },
  hand = glove { plan = "short.plan" },
  rules = { rule { when = after(99), act = warn("late") } },
})");
  const Scenario checked = check_scenario(file);
  const RunOutcome run = run_scenario(file, {});
  const auto late = [](const std::vector<std::string>& warnings) {
    return std::count_if(warnings.begin(), warnings.end(), [](const std::string& w) {
      return w.find("late.lua:5: rule: after(99) can never happen: the run ends at t=1.500 s") !=
             std::string::npos;
    });
  };
  EXPECT_EQ(late(checked.warnings), 1);
  EXPECT_EQ(late(run.warnings), 1);
}

TEST(ScenarioLoad, ACamerasMistakeIsNamedAtItsLine) {
  const test::TempDir dir("dovetail_scenario");
  const auto camera = [&](const std::string& name, const std::string& value) {
    return load_error(write(dir, name,
                            "return scenario {\n  name = \"c\",\n  parts = { a = part { shape = "
                            "box { size = { 1, 1, 1 } } } },\n\n  camera = " +
                                value + ",\n}\n"));
  };
  std::string what = camera("same.lua", "{ from = { 0, 5, 0 }, to = { 0, 5, 0 } }");
  EXPECT_NE(what.find("same.lua:5: scenario: camera 'from' and 'to' are the same point"),
            std::string::npos)
      << what;
  what = camera("up.lua", "{ from = { 0, 5, 5 }, to = { 0, 0, 0 }, up = { 0, 1, 0 } }");
  EXPECT_NE(what.find("up.lua:5: scenario: camera has no field 'up' (did you mean 'to'?)"),
            std::string::npos)
      << what;
}

TEST(ScenarioLoad, AMistakeInAFieldIsNamedAtTheFieldsLine) {
  // Lua keeps no line for a table's fields: the loader finds the line that
  // assigns the field, below the line its declaration opens.
  const test::TempDir dir("dovetail_scenario");
  const std::string pin = R"(return scenario {
  name = "lines", units = "mm",
  parts = {
    block = part {
      shape = box { size = { 40, 40, 40 } },  -- at = { 1 } in a comment is no field
      fixed = true,
    },
    pin = part {
      shape = cylinder { diameter = 10, length = 60 },
      at = { 0, 60 },
    },
  },
}
)";
  EXPECT_NE(load_error(write(dir, "at.lua", pin))
                .find("at.lua:10: part 'pin' 'at' must be three numbers"),
            std::string::npos)
      << load_error(write(dir, "at.lua", pin));
  const std::string mate = R"(return scenario {
  name = "lines", units = "mm",
  parts = {
    block = part { shape = box { size = { 40, 40, 40 } }, fixed = true },
    pin = part { shape = cylinder { diameter = 10, length = 60 }, at = { 0, 60, 0 } },
  },
  mates = {
    pin_home = mate {
      part = "pin",
      point = { 0, 0, 44 },
      axis = "z",
      into = "blok",
      at = { 0, 0, 33 },
      along = "z",
      tolerence = 1,
    },
  },
}
)";
  const std::string what = load_error(write(dir, "mate.lua", mate));
  const std::size_t into = what.find("mate.lua:12: mate 'pin_home': ");
  const std::size_t tolerance =
      what.find("mate.lua:15: mate 'pin_home': unknown field 'tolerence'");
  EXPECT_NE(into, std::string::npos) << what;
  EXPECT_NE(tolerance, std::string::npos) << what;
  EXPECT_LT(into, tolerance) << "in the order of the file: " << what;
}

TEST(ScenarioRun, AMisspeltNameOfTheCustomActionsApiGetsTheNearestOne) {
  const test::TempDir dir("dovetail_scenario");
  const auto run = [&](const std::string& name, const std::string& call) {
    return run_scenario(write(dir, name, R"(return scenario {
  name = "api", units = "mm", duration = 0.2,
  parts = { a = part { shape = box { size = { 10, 10, 10 } } } },
  rules = { rule { when = after(0.1), act = { custom(function(dt)
    )" + call + R"( end) } } },
})"));
  };
  const RunOutcome method = run("method.lua", "dt.part(\"a\"):set_translaton(1, 2, 3)");
  ASSERT_EQ(method.status, RunOutcome::Status::kError);
  EXPECT_NE(method.error.find("method.lua:5: a part has no 'set_translaton' (did you mean "
                              "'set_translation'?)"),
            std::string::npos)
      << method.error;
  const RunOutcome function = run("function.lua", "dt.Part(\"a\")");
  ASSERT_EQ(function.status, RunOutcome::Status::kError);
  EXPECT_NE(function.error.find("function.lua:5: dt has no 'Part' (did you mean 'part'?)"),
            std::string::npos)
      << function.error;
  EXPECT_EQ(run("right.lua", "dt.part(\"a\"):set_translation(1, 2, 3)").status,
            RunOutcome::Status::kPassed);
  const RunOutcome part = run("part.lua", "dt.part(\"aa\"):translation()");
  ASSERT_EQ(part.status, RunOutcome::Status::kError);
  EXPECT_NE(part.error.find("part.lua:5: dt.part: no part 'aa' (did you mean 'a'?)"),
            std::string::npos)
      << part.error;
}

TEST(ScenarioLoad, AFieldsLineIsFoundInItsOwnDeclarationOnly) {
  // A part built from a table elsewhere is named at its declaration, not at
  // the next part's field of that name; fields in comments, strings and
  // nested tables are no fields of the declaration.
  const test::TempDir dir("dovetail_scenario");
  const std::string what = load_error(
      write(dir, "own.lua", R"(local spec = { shape = box { size = { 10, 10, 10 } }, fixed = "yes" }
return scenario {
  name = "own", units = "mm",
  parts = {
    peg = part(spec),
    other = part {
      --[[ at = { 1 } in a comment ]] shape = box { size = { 10, 10, 10 } }, tags = { "at = 1" },
      fixed = true,
      at = { 0, 0 },
    },
  },
})"));
  EXPECT_NE(what.find("own.lua:5: part 'peg' 'fixed' must be true or false"), std::string::npos)
      << what;
  EXPECT_NE(what.find("own.lua:9: part 'other' 'at' must be three numbers"), std::string::npos)
      << what;
}

TEST(ScenarioLoad, MistakesInOptionalFieldsAreNamedAllAtOnce) {
  // Once, each of these ended the check on its own: fixing them took four
  // checks. An optional field's mistake now leaves the field unread and
  // reading goes on.
  const test::TempDir dir("dovetail_scenario");
  const std::string what = load_error(write(dir, "many.lua", R"(return scenario {
  name = "many", units = "mm",
  parts = {
    b = part { shape = box { size = { 10, 10, 10 } }, turn = { X = 90 } },
    a = part { shape = box { size = { 10, 10, 10 } }, at = { x = 50, y = 0, z = 0 } },
    c = part { shape = box { size = { 10, 10, 10 } }, at = { 0, 0, 80, 7 },
               tags = { 1, 2 } },
  },
})"));
  const std::vector<std::string> expected = {
      "many.lua:4: part 'b' 'turn': unknown axis 'X'",
      "many.lua:5: part 'a' 'at' must be three numbers { x, y, z }",
      "many.lua:6: part 'c' 'at' must be exactly three numbers",
      "many.lua:7: part 'c' 'tags' must be a list of names"};
  std::size_t from = 0;
  for (const std::string& line : expected) {
    const std::size_t at = what.find(line, from);
    EXPECT_NE(at, std::string::npos) << line << " in the order of the file, in:\n" << what;
    if (at != std::string::npos) from = at;
  }
}

TEST(ScenarioLoad, APartThatCannotBeReadLeavesTheOthersToBeChecked) {
  // A mistake in a required field (a box's size, a missing mesh file) ended
  // the check at the first part. Now the part stands by its name alone and
  // reading goes on: every part's mistake in one check, and what names the
  // broken part (a mate, a rule) adds no error of its own.
  const test::TempDir dir("dovetail_scenario");
  const std::string what = load_error(write(dir, "parts.lua", R"(return scenario {
  name = "parts", units = "mm",
  parts = {
    a = part { shape = box { size = { 10, 10 } } },
    b = part { shape = cylinder { diameter = "wide", length = 5 } },
    c = part { mesh = "nowhere.stl" },
    d = part { shape = box { size = { 5, 5, 5 } }, fixed = true },
  },
  mates = { m = mate { part = "a", point = { 0, 0, 0 }, axis = "z",
                       into = "b", at = { 0, 0, 0 }, along = "y" } },
  rules = { rule { when = touches("a", "c"), act = { log "x" } },
            rule { when = touches("a", "e"), act = { log "x" } } },
})"));
  const std::vector<std::string> expected = {
      "parts.lua:4: box 'size' must be three numbers { x, y, z }",
      "parts.lua:5: cylinder 'diameter' must be a number, not \"wide\"",
      "parts.lua:6: part 'c': ", "nowhere.stl: file not found",
      "parts.lua:12: touches: no part 'e'"};
  std::size_t from = 0;
  for (const std::string& line : expected) {
    const std::size_t at = what.find(line, from);
    EXPECT_NE(at, std::string::npos) << line << " in the order of the file, in:\n" << what;
    if (at != std::string::npos) from = at;
  }
  EXPECT_EQ(std::count(what.begin(), what.end(), '\n') + 1, 4) << what;
}

TEST(ScenarioLoad, TheScenarioFieldsOutOfRangeAreNamedAllAtTheirLines) {
  // They were named at the `return scenario` line, one per check, and a
  // second on the same line was lost.
  const test::TempDir dir("dovetail_scenario");
  const std::string what = load_error(write(dir, "range.lua", R"(return scenario {
  name = "range",
  units = "inch",
  time_step = 2, duration = 99999,
  accuracy = "fine",
  parts = { a = part { shape = box { size = { 10, 10, 10 } } } },
})"));
  const std::vector<std::string> expected = {
      "range.lua:3: scenario: units must be \"mm\", \"cm\" or \"m\", not \"inch\"",
      "range.lua:4: scenario: time_step must be in [0.0001, 1] s, not 2",
      "range.lua:4: scenario: duration must be at most 3600 s",
      "range.lua:5: scenario: accuracy must be \"exact\" or a length > 0"};
  for (const std::string& line : expected) {
    EXPECT_NE(what.find(line), std::string::npos) << line << " in:\n" << what;
  }
}

TEST(ScenarioLoad, CoordinatesBeyondTheLimitAreErrors) {
  // 1e300 squared overflows: refused as a pose list refuses it, at load and
  // in a custom action.
  const test::TempDir dir("dovetail_scenario");
  const std::string at = load_error(write(dir, "far.lua", R"(return scenario {
  name = "far", units = "mm",
  parts = { a = part { shape = box { size = { 10, 10, 10 } }, at = { 1e300, 0, 0 } } },
})"));
  EXPECT_NE(at.find("far.lua:3: part 'a' 'at': 1e+300 is beyond the coordinate limit of 1e+33 mm"),
            std::string::npos)
      << at;
  const RunOutcome moved = run_scenario(write(dir, "moved.lua", R"(return scenario {
  name = "far", units = "mm", duration = 0.2,
  parts = { a = part { shape = box { size = { 10, 10, 10 } } } },
  rules = { rule { when = after(0.1), act = { custom(function(dt)
    dt.part("a"):set_translation(1e300, 2, 3) end) } } },
})"));
  ASSERT_EQ(moved.status, RunOutcome::Status::kError);
  EXPECT_NE(moved.error.find("set_translation: a coordinate is beyond the limit of 1e30 m"),
            std::string::npos)
      << moved.error;
}

TEST(ScenarioLoad, AMateAngleOutsideItsRangeIsNamed) {
  const test::TempDir dir("dovetail_scenario");
  for (const char* angle : {"-5", "0", "720"}) {
    std::string text = moved_peg("", "");
    const std::string along = "along = \"-y\" }";
    text.replace(text.find(along), along.size(),
                 std::string("along = \"-y\", angle = ") + angle + " }");
    const std::string what = load_error(write(dir, "angle.lua", text));
    EXPECT_NE(what.find("angle.lua:9: mate 'peg_in_hole': angle must be above 0 and at most 180 "
                        "degrees, not " +
                        std::string(angle)),
              std::string::npos)
        << what;
  }
}

TEST(ScenarioLoad, AMisspeltWordAndAWordWithoutArgumentsAreNamed) {
  const test::TempDir dir("dovetail_scenario");
  // A call of an unknown name that is nearly a word: the word.
  const auto call_file =
      write(dir, "call.lua",
            moved_peg("    rule { when = touchs(\"peg\", \"block\"), act = { log \"x\" } },", ""));
  std::string call;
  try {
    LuaHost host({}, 1);
    load_scenario(host, call_file);
    ADD_FAILURE() << "loaded";
  } catch (const ScriptError& e) {  // a Lua error, not a scenario mistake
    call = e.what();
  }
  EXPECT_NE(call.find("call.lua:17: unknown name 'touchs' (did you mean 'touches'?)"),
            std::string::npos)
      << call;
  // A word written without its arguments, with "an" before a vowel.
  const std::string bare = load_error(write(dir, "bare.lua", moved_peg("", "    mate_made,")));
  EXPECT_NE(bare.find("expect item 1 is the word 'mate_made' without its arguments: write, say, "
                      "mate_made \"peg_in_hole\""),
            std::string::npos)
      << bare;
  const std::string kind = load_error(write(dir, "kind.lua", moved_peg("", "    after(1),")));
  EXPECT_NE(kind.find("must be an expectation; 'after' is an event"), std::string::npos) << kind;
}

TEST(ScenarioLoad, AWordWithoutItsQuotesIsAnUnknownNameNotAnUnsetField) {
  // Lua reads an unknown name as nil, which would leave the field unset:
  // steps_in_order { insert } would check no step, units = m the scenario's
  // units, fixed = yes a movable part.
  const test::TempDir dir("dovetail_scenario");
  const auto error_of = [&](const char* name, const std::string& text) {
    try {
      LuaHost host({}, 1);
      load_scenario(host, write(dir, name, text));
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("loaded");
  };
  const std::string steps = error_of("steps.lua", moved_peg("", "    steps_in_order { insert },"));
  EXPECT_NE(steps.find("steps.lua:20: unknown name 'insert' (a name is given in quotes, "
                       "\"insert\"; true and false without)"),
            std::string::npos)
      << steps;
  const std::string fixed =
      error_of("fixed.lua",
               std::regex_replace(moved_peg("", ""), std::regex("fixed = true"), "fixed = yes"));
  EXPECT_NE(fixed.find("fixed.lua:4: unknown name 'yes'"), std::string::npos) << fixed;
  EXPECT_EQ(fixed.find("metamethod"), std::string::npos) << fixed;  // the script's lines only
  // Nearly a word: the word.
  const std::string word = error_of("word.lua", moved_peg("", "    mate_mad \"peg_in_hole\","));
  EXPECT_NE(word.find("word.lua:20: unknown name 'mate_mad' (did you mean 'mate_made'?)"),
            std::string::npos)
      << word;
  // An empty list names nothing: said, not taken as every step or part.
  const std::string none =
      load_error(write(dir, "none.lua", moved_peg("", "    steps_in_order {},")));
  EXPECT_NE(none.find("none.lua:20: steps_in_order: name at least one step"), std::string::npos)
      << none;
  const std::string twice =
      load_error(write(dir, "twice.lua",
                       moved_peg("", "    steps_in_order { \"insert\", \"check\", \"insert\" },")));
  EXPECT_NE(twice.find("twice.lua:20: steps_in_order: step 'insert' is named twice; a step is "
                       "completed once"),
            std::string::npos)
      << twice;
  const std::string region = load_error(
      write(dir, "region.lua",
            moved_peg("", "",
                      "  regions = { r = region { min = { 0, 0, 0 }, max = { 1, 1, 1 },\n"
                      "    parts = {} } },\n")));
  EXPECT_NE(region.find("region.lua:23: region 'r': parts is empty; leave it out to watch every "
                        "part and the hand"),
            std::string::npos)
      << region;
}

TEST(ScenarioLoad, AFileThatFailsLeavesUnknownNamesNilOnItsHost) {
  // The error for an unknown name holds while a file is read, also one that
  // fails: the host's globals read as Lua's after.
  const test::TempDir dir("dovetail_scenario");
  LuaHost host({}, 1);
  EXPECT_THROW(load_scenario(host, write(dir, "bad.lua", "return scenario { name = nameless }\n")),
               ScriptError);
  host.run_string("return nameless", "after", 1);
  EXPECT_TRUE(lua_isnil(host.state(), -1));
  lua_pop(host.state(), 1);
}

TEST(ScenarioLoad, APartACustomFunctionSpellsOutIsChecked) {
  // The run would stop with an error when the function runs; a check says so
  // before. Names the function computes are not seen.
  const test::TempDir dir("dovetail_scenario");
  const Scenario s =
      check_scenario(write(dir, "custom.lua",
                           moved_peg("    rule { when = after(0.1), act = { custom(function(dt)\n"
                                     "      local x, y, z = dt.part(\"pge\"):translation()\n"
                                     "      dt.part 'peg':set_translation(x, y, z)\n"
                                     "      dt.part(\"l\" .. \"id\"):translation()\n"
                                     "    end) } },",
                                     "")));
  ASSERT_EQ(s.warnings.size(), 1u) << testing::PrintToString(s.warnings);
  EXPECT_NE(s.warnings[0].find("custom.lua:18: custom: no part 'pge' (did you mean 'peg'?): the "
                               "run stops with an error if the function asks for it"),
            std::string::npos)
      << s.warnings[0];
}

TEST(ScenarioRun, ACustomActionReadsAGlobalNotYetSetAsNil) {
  // Unknown names are errors while the file is read, not in custom actions
  // run later, which may keep a count in a global as Lua allows.
  const test::TempDir dir("dovetail_scenario");
  const auto file = write(dir, "count.lua",
                          moved_peg("    rule { when = every(0.25), act = { custom(function(dt)\n"
                                    "      count = (count or 0) + 1\n"
                                    "      dt.log(tostring(count))\n"
                                    "    end) }, cooldown = 0 },",
                                    ""));
  const RunOutcome o = run_scenario(file);
  ASSERT_EQ(o.status, RunOutcome::Status::kPassed) << o.failure_summary() << o.error;
  EXPECT_EQ(logged_texts(o), (std::vector<std::string>{"1", "2", "3", "4"})) << o.to_json();
}

TEST(ScenarioLoad, AnUnknownFieldAndAWrongKindAreNamed) {
  const test::TempDir dir("dovetail_scenario");
  const auto typo =
      write(dir, "typo.lua",
            moved_peg("    rule { when = after(1), act = { log \"x\" }, cooldwn = 1 },", ""));
  const std::string typo_error = load_error(typo);
  EXPECT_NE(typo_error.find("unknown field 'cooldwn' (did you mean 'cooldown'?)"),
            std::string::npos)
      << typo_error;
  const auto kind =
      write(dir, "kind.lua",
            moved_peg("    rule { when = highlight \"peg\", act = { log \"x\" } },", ""));
  const std::string kind_error = load_error(kind);
  EXPECT_NE(kind_error.find("kind.lua:17: rule 1: when must be an event; 'highlight' is an action"),
            std::string::npos)
      << kind_error;
}

TEST(ScenarioLoad, EveryUnknownFieldAndNameIsNamedAtOnceInLineOrder) {
  // An unknown name on line 17, an unknown field on line 18 and another
  // unknown name in an expectation on line 21: one error naming all three,
  // one line each, in the order of the file, though the names are resolved
  // after every table has been read.
  const test::TempDir dir("dovetail_scenario");
  const auto file = write(dir, "three.lua",
                          moved_peg("    rule { when = touches(\"peg\", \"blok\"), act = { log "
                                    "\"x\" } },\n    rule { when = after(1), act = { log \"x\" }, "
                                    "cooldwn = 1 },",
                                    "    mate_made \"peg_in_hoel\","));
  const std::string what = load_error(file);
  const std::string expected =
      ".*three.lua:17: touches: no part 'blok' \\(did you mean 'block'\\?\\)\n"
      ".*three.lua:18: rule 2: unknown field 'cooldwn' \\(did you mean 'cooldown'\\?\\)\n"
      ".*three.lua:21: mate_made: no mate 'peg_in_hoel' \\(did you mean 'peg_in_hole'\\?\\)";
  EXPECT_TRUE(std::regex_match(what, std::regex(expected))) << what;
}

TEST(ScenarioLoad, ARuleThatCanNeverFireIsAWarning) {
  const test::TempDir dir("dovetail_scenario");
  const auto file =
      write(dir, "never.lua",
            moved_peg("    rule { when = touches(\"block\", \"lid\"), act = { log \"x\" } },", ""));
  LuaHost host({}, 1);
  const Scenario s = load_scenario(host, file);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("never.lua:17: rule: touches(\"block\", \"lid\") can never happen"),
            std::string::npos)
      << s.warnings[0];
}

TEST(ScenarioLoad, TheHandNamedWhereOnlyAPartGoesIsSaidSo) {
  const test::TempDir dir("dovetail_scenario");
  write(dir, "hand.plan", "start 0 0.2 0  1 0 0 0\nwait 0.1\n");
  const std::string glove = "  hand = glove { plan = \"hand.plan\" },\n";
  const std::string second = load_error(
      write(dir, "second.lua",
            moved_peg("    rule { when = touches(\"peg\", \"hand\"), act = { log \"x\" } },", "",
                      glove)));
  EXPECT_NE(second.find("second.lua:17: touches: the hand is named first: touches(\"hand\", "
                        "\"peg\")"),
            std::string::npos)
      << second;
  const std::string grasped = load_error(
      write(dir, "grasped.lua",
            moved_peg("    rule { when = grasped \"hand\", act = { log \"x\" } },", "", glove)));
  EXPECT_NE(grasped.find("grasped.lua:17: grasped: 'hand' is no part (the hand is named first in "
                         "touches, separates, enters, leaves, touching, inside, no_contact)"),
            std::string::npos)
      << grasped;
}

TEST(ScenarioLoad, ANameGivenTwiceInOneTableIsAWarning) {
  // Lua keeps the later of two equal keys without a word: the earlier part
  // or region would vanish. Parts made by a function for many are fine.
  const test::TempDir dir("dovetail_scenario");
  LuaHost host({}, 1);
  const Scenario s = load_scenario(host, write(dir, "twice.lua", R"(local function brick(x)
  return part { shape = box { size = { 10, 10, 10 } }, at = { x, 0, 0 } }
end
local spare = part { shape = box { size = { 1, 1, 1 } } }
return scenario {
  name = "twice", units = "mm",
  parts = {
    a = brick(0), b = brick(20),
    lid = part { shape = box { size = { 5, 5, 5 } }, at = { 0, 50, 0 } },
    ["lid"] = part { shape = box { size = { 6, 6, 6 } }, at = { 0, 80, 0 } },
  },
  regions = {
    tray = region { min = { 0, 0, 0 }, max = { 1, 1, 1 } },
    tray = region { min = { 0, 0, 0 }, max = { 2, 2, 2 } },
  },
})"));
  ASSERT_EQ(s.parts.size(), 3u);
  std::vector<std::string> warnings = s.warnings;
  std::sort(warnings.begin(), warnings.end());
  // A line far longer than a pattern match could take: read by hand.
  const Scenario long_line = load_scenario(
      host, write(dir, "long.lua",
                  "local t = { [\"" + std::string(200000, 'a') +
                      "\"] = 1 }; local spare = part { shape = box { size = { 1, 1, 1 } } }\n"
                      "return scenario { name = \"l\", parts = { a = part { shape = box { size "
                      "= { 1, 1, 1 } } } } }\n"));
  ASSERT_EQ(long_line.warnings.size(), 1u) << testing::PrintToString(long_line.warnings);
  EXPECT_NE(long_line.warnings[0].find("long.lua:1: this part { ... } is in none"),
            std::string::npos);
  ASSERT_EQ(warnings.size(), 3u) << testing::PrintToString(warnings);
  EXPECT_NE(warnings[0].find("twice.lua:13: region 'tray' is declared again at line 14, which "
                             "replaces this one: give each region a name of its own"),
            std::string::npos)
      << warnings[0];
  EXPECT_NE(warnings[1].find("twice.lua:4: this part { ... } is in none of the scenario's parts "
                             "(is its name given twice?)"),
            std::string::npos)
      << warnings[1];
  EXPECT_NE(warnings[2].find("twice.lua:9: part 'lid' is declared again at line 10"),
            std::string::npos)
      << warnings[2];
}

TEST(ScenarioRun, APlanLongerThanTheDurationIsAWarningAndTheRunEndsAtItsLastFrame) {
  const test::TempDir dir("dovetail_scenario");
  write(dir, "long.plan", "start 0 0.3 0  1 0 0 0\nwait 2\n");
  const auto file =
      write(dir, "short.lua",
            moved_peg("", "    finished_within(5),", "  hand = glove { plan = \"long.plan\" },\n"));
  const std::string expected =
      "short.lua:22: glove: the plan runs to t=2.000 s, past the scenario's duration (1.000 s): "
      "the run ends before the hand has done it";
  const Scenario checked = check_scenario(file);
  ASSERT_EQ(checked.warnings.size(), 1u);
  EXPECT_NE(checked.warnings[0].find(expected), std::string::npos) << checked.warnings[0];
  const RunOutcome o = run_scenario(file);
  ASSERT_EQ(o.warnings.size(), 1u);
  EXPECT_NE(o.warnings[0].find(expected), std::string::npos) << o.warnings[0];
  // 91 frames, the last at t = 1 s: the run ended there, not a frame later.
  ASSERT_EQ(o.expectations.size(), 1u);
  EXPECT_EQ(o.expectations[0].detail, "step 'insert' was never completed (run ended at t=1.000 s)");
}

TEST(ScenarioLoad, AHandMisspeltOrTooLongIsNamedInTheScenariosTerms) {
  const test::TempDir dir("dovetail_scenario");
  write(dir, "hand.plan", "start 0 0.2 0  1 0 0 0\nwait 0.1\n");
  const std::string glove = "  hand = glove { plan = \"hand.plan\" },\n";
  const std::string rule = load_error(
      write(dir, "rule.lua",
            moved_peg("    rule { when = touches(\"hnad\", \"peg\"), act = { log \"x\" } },", "",
                      glove)));
  EXPECT_NE(rule.find("rule.lua:17: touches: no part 'hnad' (did you mean 'hand'?)"),
            std::string::npos)
      << rule;
  const std::string region = load_error(
      write(dir, "region.lua",
            moved_peg("", "",
                      glove + "  regions = { r = region { min = { 0, 0, 0 }, max = { 1, 1, 1 }, "
                              "parts = { \"hnad\" } } },\n")));
  EXPECT_NE(region.find("region 'r': no part 'hnad' (did you mean 'hand'?)"), std::string::npos)
      << region;
  // A hand of 190 cm in a scenario in cm: the range in cm, and what was read.
  const std::string cm =
      load_error(write(dir, "cm.lua",
                       std::regex_replace(moved_peg("", "",
                                                    "  hand = glove { plan = \"hand.plan\",\n"
                                                    "    hand_length = 190 },\n"),
                                          std::regex("units = \"mm\""), "units = \"cm\"")));
  EXPECT_NE(
      cm.find("cm.lua:23: glove: hand_length must be 12 to 26 cm (120 to 260 mm), not 190 cm"),
      std::string::npos)
      << cm;
}

TEST(ScenarioRun, EveryTicksAtEachMultipleOfItsPeriod) {
  // Frame 27's time, 27 * (1/90), falls a rounding short of 0.3: the tick of
  // every(0.1) there came a frame late, and the default cooldown of 0.1 s then
  // kept the next tick from firing.
  const test::TempDir dir("dovetail_scenario");
  const auto file = write(dir, "ticks.lua", R"(return scenario {
  name = "ticks", units = "mm", duration = 3,
  parts = { a = part { shape = box { size = { 10, 10, 10 } } } },
  rules = {
    rule { when = every(0.1), act = { log "tick" } },
    rule { when = after(0.3), act = { log "after" } },
    rule { when = every(0.05), cooldown = 0.1, act = { log "slow" } },
  },
})");
  const Scenario checked = check_scenario(file);
  ASSERT_EQ(checked.warnings.size(), 1u);
  EXPECT_NE(checked.warnings[0].find("ticks.lua:7: rule: every(0.05) fires at most once every "
                                     "0.1 s, the rule's cooldown: not at every tick"),
            std::string::npos)
      << checked.warnings[0];
  const RunOutcome o = run_scenario(file);
  ASSERT_EQ(o.status, RunOutcome::Status::kPassed) << o.error;
  std::vector<double> ticks;
  std::optional<double> after;
  for (const Message& m : o.messages) {
    if (m.text == "tick") ticks.push_back(m.time);
    if (m.text == "after") after = m.time;
  }
  ASSERT_EQ(ticks.size(), 30u);
  for (std::size_t k = 0; k < ticks.size(); ++k) {
    EXPECT_NEAR(ticks[k], 0.1 * static_cast<double>(k + 1), 1e-9) << k;
  }
  ASSERT_TRUE(after);
  EXPECT_EQ(*after, ticks[2]);
}

TEST(ScenarioLoad, AShapeTooLargeOrTooSmallIsNamedAtItsLine) {
  const test::TempDir dir("dovetail_scenario");
  const auto shape = [&](const std::string& name, const std::string& text) {
    return write(dir, name,
                 "return scenario {\n  name = \"s\",\n  parts = {\n    a = part { shape = " + text +
                     " },\n  },\n}\n");
  };
  EXPECT_EQ(load_error(shape("huge.lua", "box { size = { 1e308, 1, 1 } }")),
            (dir / "huge.lua").string() +
                ":4: box 'size': 1e+308 is beyond the coordinate limit of 1e+33 mm");
  EXPECT_EQ(load_error(shape("tiny.lua", "cylinder { diameter = 1e-300, length = 1e-300 }")),
            (dir / "tiny.lua").string() + ":4: cylinder: all 256 triangles are degenerate");
}

TEST(ScenarioLoad, AnEmptyPartNameIsNamedAndACameraStraightDownHasAnUp) {
  const test::TempDir dir("dovetail_scenario");
  const auto empty = write(dir, "empty.lua",
                           "return scenario {\n  name = \"s\",\n  parts = {\n    [\"\"] = part { "
                           "shape = box { size = { 1, 1, 1 } } },\n  },\n}\n");
  EXPECT_NE(load_error(empty).find("empty.lua:1: parts: a part's name may not be empty"),
            std::string::npos);
  // Looking down the y axis, the default up (y) is along the view: -z is up
  // on the picture, as for `render --camera top`.
  const auto down = write(dir, "down.lua",
                          "return scenario {\n  name = \"s\",\n  parts = {\n    a = part { shape = "
                          "box { size = { 1, 1, 1 } } },\n  },\n  camera = { from = { 0, 100, 0 }, "
                          "to = { 0, 0, 0 } },\n}\n");
  LuaHost host({}, 1);
  const Scenario s = load_scenario(host, down);
  ASSERT_TRUE(s.camera.has_value());
  EXPECT_EQ(s.camera->up, -collision::Vec3::UnitZ());
}

TEST(ScenarioLoad, AMissingCommaAndAnUnknownColourGetAHint) {
  const test::TempDir dir("dovetail_scenario");
  const auto comma = write(dir, "comma.lua",
                           "return scenario {\n  name = \"s\",\n  parts = {\n"
                           "    a = part { shape = box { size = { 1, 1, 1 } } }\n"
                           "    b = part { shape = box { size = { 1, 1, 1 } } },\n  },\n}\n");
  std::string syntax;
  try {
    LuaHost host({}, 1);
    load_scenario(host, comma);
  } catch (const ScriptError& e) {
    syntax = e.what();
  }
  EXPECT_NE(syntax.find("comma.lua:5: '}' expected (to close '{' at line 3) near 'b' "
                        "(is a comma missing at the end of the field before?)"),
            std::string::npos);
  const auto colour =
      write(dir, "colour.lua",
            "return scenario {\n  name = \"s\",\n  parts = {\n"
            "    a = part { shape = box { size = { 1, 1, 1 } }, color = \"oak\" },\n"
            "  },\n}\n");
  EXPECT_NE(load_error(colour).find("unknown colour 'oak' (a colour is one of black, blue, brass, "
                                    "gray, green, grey, orange, purple, red, steel, white, yellow, "
                                    "or {r, g, b} in [0, 1])"),
            std::string::npos);
}

TEST(ScenarioLoad, TheFileMustReturnAScenario) {
  const test::TempDir dir("dovetail_scenario");
  LuaHost host({}, 1);
  EXPECT_THROW(load_scenario(host, write(dir, "plain.lua", "return { name = 'x' }")),
               ScenarioError);
  LuaHost host2({}, 1);
  EXPECT_THROW(load_scenario(host2, write(dir, "syntax.lua", "return scenario {")), ScriptError);
}

TEST(ScenarioRun, RulesStepsAndExpectationsOfAMovedPeg) {
  const test::TempDir dir("dovetail_scenario");
  const auto file = write(
      dir, "moved.lua",
      moved_peg(
          "    rule { when = after(0.2), act = { snap \"peg_in_hole\" } },\n"
          "    rule { when = mated \"peg_in_hole\", act = { highlight \"block\", "
          "log \"seated\" } },",
          "    steps_in_order { \"insert\", \"check\" }, finished_within(0.6),\n"
          "    mate_made \"peg_in_hole\", max_penetration(0.01), no_contact(\"peg\", \"lid\"),"));
  const RunOutcome o = run_scenario(file);
  ASSERT_EQ(o.status, RunOutcome::Status::kPassed) << o.failure_summary();
  ASSERT_EQ(o.steps.size(), 2u);
  // after(0.2) fires in frame 18 (t = 0.2); the snap applies at the start of frame 19.
  EXPECT_DOUBLE_EQ(*o.steps[0].done_at, 19.0 / 90.0);
  ASSERT_FALSE(o.messages.empty());
  EXPECT_EQ(o.messages[0].text, "seated");
  EXPECT_EQ(o.messages[0].where.line, 18);
  // The peg snapped in without touching the hole's wall: nothing overlapped.
  EXPECT_NE(o.to_json().find("\"max_penetration\": {\"depth\": 0, \"time\": null, \"a\": null, "
                             "\"b\": null}"),
            std::string::npos)
      << o.to_json();
}

TEST(ScenarioRun, ASnapOfAPartInPlaceAlreadyFiresNoSecondMated) {
  const test::TempDir dir("dovetail_scenario");
  const auto file =
      write(dir, "twice.lua",
            moved_peg("    rule { when = after(0.2), act = { snap \"peg_in_hole\" } },\n"
                      "    rule { when = after(0.3), act = { snap \"peg_in_hole\" } },\n"
                      "    rule { when = mated \"peg_in_hole\", act = { log \"seated\" } },",
                      "    mate_made \"peg_in_hole\","));
  const RunOutcome o = run_scenario(file);
  ASSERT_EQ(o.status, RunOutcome::Status::kPassed) << o.failure_summary();
  const auto seated = std::count_if(o.messages.begin(), o.messages.end(),
                                    [](const auto& m) { return m.text == "seated"; });
  EXPECT_EQ(seated, 1);
}

TEST(ScenarioRun, AnAfterPastTheRunsEndIsAWarning) {
  const test::TempDir dir("dovetail_scenario");
  const auto file = write(dir, "late.lua", R"(return scenario {
  name = "late", units = "mm", duration = 0.3,
  parts = { a = part { shape = box { size = { 10, 10, 10 } } } },
  rules = {
    rule { when = after(0.3), act = { log "at the end" } },
    rule { when = after(1e9), act = { log "never" } },
  },
})");
  const RunOutcome o = run_scenario(file);
  ASSERT_EQ(o.status, RunOutcome::Status::kPassed) << o.failure_summary() << o.error;
  ASSERT_EQ(o.warnings.size(), 1u);
  EXPECT_NE(
      o.warnings[0].find("late.lua:6: rule: after(1000000000) can never happen: the run ends at "
                         "t=0.300 s"),
      std::string::npos)
      << o.warnings[0];
  ASSERT_EQ(o.messages.size(), 1u);
  EXPECT_EQ(o.messages[0].text, "at the end");
}

TEST(ScenarioRun, TwoMovesOfAPartInOneFrameAreAWarning) {
  const test::TempDir dir("dovetail_scenario");
  const auto file = write(dir, "two.lua", R"(return scenario {
  name = "two", units = "mm", duration = 0.3,
  parts = { a = part { shape = box { size = { 10, 10, 10 } } } },
  rules = {
    rule { when = after(0.1), act = { move("a", { 0, 30, 0 }) } },
    rule { when = after(0.1), act = { move("a", { 0, 70, 0 }) } },
  },
})");
  const RunOutcome o = run_scenario(file);
  ASSERT_EQ(o.status, RunOutcome::Status::kPassed) << o.failure_summary() << o.error;
  ASSERT_EQ(o.messages.size(), 1u) << o.to_json();
  EXPECT_EQ(o.messages[0].level, "warn");
  EXPECT_NE(o.messages[0].text.find("move: 'a' was sent somewhere else in this frame too (" +
                                    file.string() + ":5); this move, written later, wins"),
            std::string::npos)
      << o.messages[0].text;
  EXPECT_EQ(o.messages[0].where.line, 6);
  ASSERT_EQ(o.final_poses.size(), 1u);
  EXPECT_NEAR(o.final_poses[0].position.y(), 0.070, 1e-12);
}

TEST(ScenarioRun, AFailedStepsOrderComesAfterWhatWentWrong) {
  // The peg never snaps, so its step is never done: the summary's first
  // line (what regress shows) is the mate, not the steps' order.
  const test::TempDir dir("dovetail_scenario");
  const auto file = write(dir, "cause.lua",
                          moved_peg("",
                                    "    steps_in_order { \"insert\", \"check\" },\n"
                                    "    mate_made \"peg_in_hole\","));
  const RunOutcome o = run_scenario(file);
  ASSERT_EQ(o.status, RunOutcome::Status::kFailed);
  const std::string summary = o.failure_summary();
  EXPECT_EQ(summary.rfind(file.string() + ":21: expectation mate_made(\"peg_in_hole\") failed", 0),
            0u)
      << summary;
  EXPECT_NE(summary.find("expectation steps_in_order"), std::string::npos) << summary;
}

TEST(ScenarioRun, AStepOutOfOrderFailsNamingTheStepsAndTimes) {
  const test::TempDir dir("dovetail_scenario");
  const auto file =
      write(dir, "order.lua",
            moved_peg("    rule { when = after(0.7), act = { snap \"peg_in_hole\" } },",
                      "    steps_in_order { \"insert\", \"check\" },"));
  const RunOutcome o = run_scenario(file);
  ASSERT_EQ(o.status, RunOutcome::Status::kFailed);
  const std::string summary = o.failure_summary();
  EXPECT_NE(summary.find("steps_in_order"), std::string::npos) << summary;
  EXPECT_NE(
      summary.find("step 'check' was completed at t=0.500 s, before step 'insert' (t=0.711 s)"),
      std::string::npos)
      << summary;
  EXPECT_NE(summary.find("order.lua:14: at t=0.500 s: step 'check' completed before step 'insert'"),
            std::string::npos)
      << summary;
}

TEST(ScenarioRun, APartPushedThroughAnotherFailsMaxPenetrationNamingThePartsAndTime) {
  const test::TempDir dir("dovetail_scenario");
  const auto file = write(
      dir, "through.lua",
      moved_peg("    rule { when = after(0.1), act = { move(\"peg\", { 0, -60, 0 }, 0.5) } },",
                "    max_penetration(0.01),"));
  const RunOutcome o = run_scenario(file);
  ASSERT_EQ(o.status, RunOutcome::Status::kFailed);
  ASSERT_EQ(o.expectations.size(), 1u);
  EXPECT_FALSE(o.expectations[0].passed);
  EXPECT_NE(o.expectations[0].detail.find("'block' and 'peg' overlapped"), std::string::npos)
      << o.expectations[0].detail;
  EXPECT_GT(o.max_penetration, 0.001);
  EXPECT_NE(o.to_json().find("\"a\": \"block\", \"b\": \"peg\"}"), std::string::npos)
      << o.to_json();
}

TEST(ScenarioRun, AFailingCustomActionEndsWithAnErrorAndAReport) {
  const test::TempDir dir("dovetail_scenario");
  const auto file = write(dir, "custom.lua",
                          moved_peg("    rule { when = after(0.1), act = { custom(function(dt)\n"
                                    "      dt.part(\"peg\"):set_translation(0, 120, 0)\n"
                                    "      while true do end end) } },",
                                    "    max_penetration(0.01),"));
  RunOptions options;
  options.limits.instructions_per_call = 100000;
  const RunOutcome o = run_scenario(file, options);
  ASSERT_EQ(o.status, RunOutcome::Status::kError);
  EXPECT_NE(o.error.find("custom.lua:19"), std::string::npos) << o.error;
  EXPECT_GT(o.report.frames, 9u);
  EXPECT_NE(o.to_json().find("\"outcome\": \"error\""), std::string::npos);
}

TEST(ScenarioRun, CustomActionsUseTheLowLevelApi) {
  const test::TempDir dir("dovetail_scenario");
  const auto file =
      write(dir, "api.lua",
            moved_peg("    rule { when = after(0.1), act = { custom(function(dt)\n"
                      "      local x, y, z = dt.part(\"peg\"):translation()\n"
                      "      dt.log(string.format(\"%g %g %g\", x, y, z))\n"
                      "      local m = dt.part(\"peg\"):matrix()\n"
                      "      m[8] = 250\n"
                      "      dt.part(\"peg\"):set_matrix(m)\n"
                      "    end) } },\n"
                      "    rule { when = after(0.2), act = { custom(function(dt)\n"
                      "      dt.log(string.format(\"%g %g %g\", dt.part(\"peg\"):translation()))\n"
                      "    end) } },",
                      ""));
  const RunOutcome o = run_scenario(file);
  ASSERT_EQ(o.status, RunOutcome::Status::kPassed) << o.failure_summary() << o.error;
  EXPECT_EQ(logged_texts(o), (std::vector<std::string>{"0 100 0", "0 250 0"})) << o.to_json();
}

TEST(ScenarioRun, ARuleFiredInTheLastFrameGetsOneFrameMoreForItsActions) {
  // The run is 1 s long (91 frames); after(1) fires in its last frame, whose
  // actions are done at the start of a 92nd: the custom function runs, the
  // snap is an event and mate_made sees it, the state hash includes it.
  const test::TempDir dir("dovetail_scenario");
  const auto logs = write(dir, "last.lua",
                          moved_peg("    rule { when = after(1), act = { custom(function(dt)\n"
                                    "      dt.log(string.format(\"at %.6f\", dt.time())) end),\n"
                                    "      snap \"peg_in_hole\" } },",
                                    "    mate_made \"peg_in_hole\","));
  const RunOutcome o = run_scenario(logs);
  ASSERT_EQ(o.status, RunOutcome::Status::kPassed) << o.failure_summary() << o.error;
  EXPECT_EQ(logged_texts(o), (std::vector<std::string>{"at 1.011111"})) << o.to_json();
  EXPECT_EQ(o.report.frames, 92u);
  EXPECT_TRUE(o.warnings.empty());

  const auto fails = write(dir, "last_error.lua",
                           moved_peg("    rule { when = after(1), act = { custom(function(dt)\n"
                                     "      error(\"boom\") end) } },",
                                     ""));
  const RunOutcome e = run_scenario(fails);
  ASSERT_EQ(e.status, RunOutcome::Status::kError) << e.failure_summary();
  EXPECT_NE(e.error.find("boom (at t=1.011 s)\n"), std::string::npos) << e.error;

  // A rule on an event of the 92nd frame (the snap's) leaves a move for a
  // 93rd: not done, said.
  const auto chained =
      write(dir, "chained.lua",
            moved_peg("    rule { when = after(1), act = { snap \"peg_in_hole\" } },\n"
                      "    rule { when = mated \"peg_in_hole\", act = { move(\"peg\", { 0, 200, 0 "
                      "}) } },",
                      ""));
  const auto not_done = [](const RunOutcome& run) {
    int count = 0;
    for (const Message& msg : run.messages) {
      count += msg.level == "warn" &&
               msg.text == "move: not done: its rule fired in the run's last frame";
    }
    return count;
  };
  const RunOutcome m = run_scenario(chained);
  EXPECT_EQ(not_done(m), 1) << m.to_json();

  // Timers are past the run's end in the 92nd frame: a rule firing every
  // frame leaves nothing undone there.
  const auto every =
      write(dir, "every.lua",
            moved_peg("    rule { when = every(1 / 90), cooldown = 0, act = { move(\"peg\", { 0, "
                      "200, 0 }) } },",
                      ""));
  const RunOutcome r = run_scenario(every);
  EXPECT_EQ(not_done(r), 0) << r.to_json();
}

TEST(ScenarioRun, ARunReachesItsDurationWhenItIsNoMultipleOfTheTimeStep) {
  // 1.234567 s at 90 Hz: frames up to t = 112/90 = 1.2444 s, the first at or
  // after the end, where after(1.234567) fires. Before, the run stopped at
  // 111/90 = 1.2333 s and the rule never fired.
  const test::TempDir dir("dovetail_scenario");
  const auto file =
      write(dir, "odd.lua",
            std::regex_replace(
                moved_peg("    rule { when = after(1.234567), act = { log \"end\" } },", ""),
                std::regex("duration = 1,"), "duration = 1.234567,"));
  const RunOutcome o = run_scenario(file);
  ASSERT_EQ(o.status, RunOutcome::Status::kPassed) << o.failure_summary() << o.error;
  EXPECT_EQ(o.report.frames, 113u);
  EXPECT_EQ(logged_texts(o), (std::vector<std::string>{"end"})) << o.to_json();
}

TEST(ScenarioRun, AMoveStillUnderWayWhenTheRunEndsIsAWarning) {
  const test::TempDir dir("dovetail_scenario");
  const auto file = write(
      dir, "late.lua",
      moved_peg("    rule { when = after(0.9), act = { move(\"peg\", { 0, 150, 0 }, 0.5) } },",
                ""));
  const RunOutcome o = run_scenario(file);
  bool said = false;
  for (const Message& m : o.messages) {
    said = said || (m.level == "warn" && m.where.line == 17 &&
                    m.text ==
                        "move: 'peg' had not arrived when the run ended (it would at "
                        "t=1.411 s)");
  }
  EXPECT_TRUE(said) << o.to_json();
}

TEST(ScenarioRun, AFailIsTheFirstReasonGivenBeforeExpectationsItCutShort) {
  const test::TempDir dir("dovetail_scenario");
  const auto file =
      write(dir, "fail.lua",
            moved_peg("    rule { when = after(0.1), act = { fail \"the peg was dropped\" } },",
                      "    steps_in_order { \"insert\", \"check\" },"));
  const RunOutcome o = run_scenario(file);
  ASSERT_EQ(o.status, RunOutcome::Status::kFailed);
  const std::string summary = o.failure_summary();
  EXPECT_EQ(summary.rfind(file.string() + ":17: failed at t=0.100 s: the peg was dropped\n", 0), 0u)
      << summary;
  EXPECT_NE(summary.find("steps_in_order"), std::string::npos) << summary;
}

TEST(ScenarioRun, AGraspMadeAsTheFingersBarelyMovedIsReleasedWhenTheHandOpens) {
  // The palm comes against a vertical bar and the fingers stop on it a few
  // degrees into the close; opening the hand must let the bar go, which a
  // release 8 degrees below the flexion at the grasp never could.
  const test::TempDir dir("dovetail_scenario");
  write(dir, "vbar.plan",
        "start -0.070 0.060 0.080  0.7071067811865476 0 0 0.7071067811865476\n"
        "reach 0.6  -0.010 0.060 0.080  0.7071067811865476 0 0 0.7071067811865476\n"
        "close 0.4 power\n"
        "reach 1.0  -0.010 0.110 0.080  0.7071067811865476 0 0 0.7071067811865476\n"
        "open 0.3\n"
        "reach 1.0  -0.010 0.160 0.080  0.7071067811865476 0 0 0.7071067811865476\n");
  const auto file = write(dir, "vbar.lua", R"(return scenario {
  name = "vertical bar", units = "mm",
  parts = {
    bar = part { shape = cylinder { diameter = 40, length = 120 }, at = { 0, 120, 0 }, turn = { x = 90 } },
  },
  hand = glove { plan = "vbar.plan" },
  rules = {
    rule { when = grasped "bar", act = { log "grasped" } },
    rule { when = released "bar", act = { log "released" } },
  },
  expect = { grasped_as("bar", "power") },
}
)");
  const RunOutcome o = run_scenario(file);
  ASSERT_EQ(o.status, RunOutcome::Status::kPassed) << o.failure_summary() << o.error;
  const auto logged = logged_messages(o);
  ASSERT_EQ(logged.size(), 2u) << o.to_json();
  EXPECT_EQ(logged[1].second, "released");
  // Opened over 2.0-2.3 s, released 50 ms after a digit opened far enough.
  EXPECT_GT(logged[1].first, 2.0);
  EXPECT_LT(logged[1].first, 2.4);
  // Carried up 50 mm while held, left there when the hand went on up.
  ASSERT_EQ(o.final_poses.size(), 1u);
  EXPECT_NEAR(o.final_poses[0].position.y(), 0.170, 1e-4);
}

/// A collar pressed on a shaft, grasped by the collar and carried 85 mm down
/// by `collar.plan`; `mates` and `rules` go into the scenario.
std::filesystem::path collar_on_shaft(const test::TempDir& dir, const std::string& name,
                                      const std::string& mates, const std::string& rules) {
  write(dir, "collar.plan",
        "start -0.070 0.125 0.080  0.7071067811865476 0 0 0.7071067811865476\n"
        "reach 0.6  -0.010 0.125 0.080  0.7071067811865476 0 0 0.7071067811865476\n"
        "close 0.4 power\n"
        "reach 2.0  -0.010 0.040 0.080  0.7071067811865476 0 0 0.7071067811865476\n"
        "open 0.3\n"
        "reach 0.5  -0.070 0.040 0.080  0.7071067811865476 0 0 0.7071067811865476\n");
  return write(dir, name, R"(return scenario {
  name = "collar on a shaft", units = "mm",
  parts = {
    shaft = part { shape = cylinder { diameter = 24, length = 50 }, at = { 0, 150, 0 }, turn = { x = 90 } },
    collar = part { shape = tube { outer = 40, inner = 23.9, length = 10 }, at = { 0, 150, 0 },
                    turn = { x = 90 }, attached_to = "shaft" },
    base = part { shape = box { size = { 20, 20, 20 } }, at = { 200, 0, 0 }, fixed = true },
  },
  mates = { )" + mates + R"( },
  rules = { )" + rules + R"( },
  hand = glove { plan = "collar.plan" },
})");
}

TEST(ScenarioRun, GraspingAPartAttachedToAnotherCarriesTheWholeSubAssembly) {
  // The hand closes on a collar pressed on a shaft (attached to it) and
  // carries both 85 mm down; before, the collar was held against its own
  // shaft and nothing moved until the hand let go of it, overstretched.
  const test::TempDir dir("dovetail_scenario");
  const RunOutcome o = run_scenario(collar_on_shaft(dir, "collar.lua", "", ""));
  ASSERT_EQ(o.status, RunOutcome::Status::kPassed) << o.failure_summary() << o.error;
  std::vector<std::string> grasps;
  for (const engine::Event& e : o.report.events) {
    if (e.kind == engine::EventKind::kGrasp || e.kind == engine::EventKind::kRelease) {
      grasps.push_back(e.a + " " + e.b);
    }
  }
  EXPECT_EQ(grasps, (std::vector<std::string>{"collar power", "collar opened"}));
  std::map<std::string, Vec3> at;
  for (const auto& pose : o.final_poses) at[pose.part] = pose.position;
  for (const std::string part : {"shaft", "collar"}) {
    // Both went down with the hand (the hand's grip shifts them a little sideways).
    EXPECT_NEAR(at[part].y(), 0.065, 1e-4) << part;
    EXPECT_NEAR(at[part].x(), 0, 1e-3) << part;
  }
  // The collar where it was on the shaft.
  EXPECT_LT((at["shaft"] - at["collar"]).norm(), 1e-12);
}

TEST(ScenarioRun, TheFinalPictureIsTheSameWithOrWithoutFrames) {
  // No scenario camera: the frames share one camera fitted to the first; the
  // final picture is fitted to the final scene either way (the peg moves 60 mm).
  const test::TempDir dir("dovetail_scenario");
  const auto file = write(
      dir, "pictures.lua",
      moved_peg("    rule { when = after(0.1), act = { move(\"peg\", { 0, 160, 0 }, 0.2) } },",
                ""));
  auto final_png = [&](const std::string& folder, std::uint64_t every) {
    RunOptions options;
    options.render_dir = dir / folder;
    std::filesystem::create_directories(*options.render_dir);
    options.render_every = every;
    options.render_width = 160;
    options.render_height = 120;
    const RunOutcome o = run_scenario(file, options);
    EXPECT_EQ(o.status, RunOutcome::Status::kPassed) << o.failure_summary() << o.error;
    std::ifstream in(dir / folder / "final.png", std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  const std::string alone = final_png("alone", 0);
  const std::string with_frames = final_png("frames", 30);
  EXPECT_FALSE(alone.empty());
  EXPECT_EQ(alone, with_frames);
  EXPECT_TRUE(std::filesystem::exists(dir / "frames" / "frame_000030.png"));
}

TEST(ScenarioLoad, AMeshFileInOtherUnitsThanTheScenarioIsAWarning) {
  // A 60 x 5 x 60 mm plate written in metres, in a scenario in millimetres:
  // 0.085 mm across, where the other parts are some 66 mm.
  const test::TempDir dir("dovetail_scenario");
  write(dir, "plate_m.obj",
        "v -0.03 0 -0.03\nv 0.03 0 -0.03\nv 0.03 0 0.03\nv -0.03 0 0.03\n"
        "v -0.03 0.005 -0.03\nv 0.03 0.005 -0.03\nv 0.03 0.005 0.03\nv -0.03 0.005 0.03\n"
        "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\n"
        "f 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n");
  const auto file =
      write(dir, "plate.lua",
            std::regex_replace(moved_peg("", ""), std::regex("    lid = part"),
                               "    plate = part { mesh = \"plate_m.obj\", at = { 0, 200, 0 } },\n"
                               "    lid = part"));
  const Scenario s = check_scenario(file);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("plate.lua:6: part 'plate' (plate_m.obj) is 0.085 mm across, "
                               "1/780 of the other parts (a median of 66.3 mm)"),
            std::string::npos)
      << s.warnings[0];
  EXPECT_NE(s.warnings[0].find("is the file in other units? Its numbers are read in mm; if they "
                               "are in m, give the part units = \"m\""),
            std::string::npos)
      << s.warnings[0];
  // Said so, the plate is 60 mm across and nothing is out of place.
  const Scenario in_metres = check_scenario(write(
      dir, "plate_in_m.lua",
      std::regex_replace(moved_peg("", ""), std::regex("    lid = part"),
                         "    plate = part { mesh = \"plate_m.obj\", units = \"m\", at = { 0, "
                         "200, 0 } },\n    lid = part")));
  EXPECT_TRUE(in_metres.warnings.empty()) << in_metres.warnings[0];
  const auto plate = std::find_if(in_metres.parts.begin(), in_metres.parts.end(),
                                  [](const PartSpec& p) { return p.name == "plate"; });
  ASSERT_NE(plate, in_metres.parts.end());
  EXPECT_NEAR(plate->mesh->vertices[1].x(), 0.03, 1e-9);  // metres (the file is read in floats)
  EXPECT_EQ(plate->file_units, "m");
}

TEST(ScenarioLoad, APartsUnitsAreAMeshFilesAndOneOfThree) {
  const test::TempDir dir("dovetail_scenario");
  const auto with_lid = [&](const char* name, const std::string& lid) {
    return write(dir, name,
                 std::regex_replace(moved_peg("", ""), std::regex("    lid = part \\{"),
                                    "    lid = part { " + lid));
  };
  const std::string shape = load_error(with_lid("shape.lua", "units = \"m\","));
  EXPECT_NE(shape.find("shape.lua:6: part 'lid': units are a mesh file's; a shape's lengths are "
                       "in the scenario's units"),
            std::string::npos)
      << shape;
  write(dir, "cube.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n"
        "f 1 3 2\nf 2 3 4\nf 5 6 7\nf 6 8 7\nf 1 2 5\nf 2 6 5\nf 3 7 4\nf 4 7 8\n"
        "f 1 5 3\nf 3 5 7\nf 2 4 6\nf 4 8 6\n");
  const std::string inches =
      load_error(write(dir, "inches.lua",
                       "return scenario {\n  name = \"u\",\n  parts = {\n    c = part { mesh = "
                       "\"cube.obj\",\n      units = \"in\" },\n  },\n}\n"));
  EXPECT_NE(inches.find("inches.lua:5: part 'c': units must be \"mm\", \"cm\" or \"m\", not "
                        "\"in\""),
            std::string::npos)
      << inches;
  // One file in two units is two meshes, not one shared.
  LuaHost host({}, 1);
  const Scenario two = load_scenario(
      host, write(dir, "two.lua",
                  "return scenario {\n  name = \"u\", units = \"mm\",\n  parts = {\n"
                  "    a = part { mesh = \"cube.obj\", units = \"cm\" },\n"
                  "    b = part { mesh = \"cube.obj\", at = { 100, 0, 0 } },\n"
                  "    c = part { mesh = \"cube.obj\", units = \"mm\", at = { 200, 0, 0 } },\n"
                  "  },\n}\n"));
  ASSERT_EQ(two.parts.size(), 3u);
  EXPECT_EQ(two.parts[0].mesh->vertices[7], Vec3(0.01, 0.01, 0.01));
  EXPECT_EQ(two.parts[1].mesh->vertices[7], Vec3(0.001, 0.001, 0.001));
  EXPECT_NE(two.parts[0].mesh, two.parts[1].mesh);
  EXPECT_EQ(two.parts[1].mesh, two.parts[2].mesh);  // the scenario's units, said or not
}

TEST(ScenarioLoad, PartsFromMeshFilesFarFromTheHandsSizeAreAWarning) {
  // A whole product exported in metres (a 60 mm and an 80 mm box) read in a
  // scenario in millimetres: the parts agree with each other, but are
  // 0.1 mm across beside a 190 mm hand. In metres, the same files pass.
  const test::TempDir dir("dovetail_scenario");
  const auto box = [](double a) {
    std::string text;
    for (int i = 0; i < 8; ++i) {
      text += "v " + std::to_string(i & 1 ? a : 0) + " " + std::to_string(i & 2 ? a : 0) + " " +
              std::to_string(i & 4 ? a : 0) + "\n";
    }
    return text +
           "f 1 3 2\nf 2 3 4\nf 5 6 7\nf 6 8 7\nf 1 2 5\nf 2 6 5\nf 3 7 4\nf 4 7 8\n"
           "f 1 5 3\nf 3 5 7\nf 2 4 6\nf 4 8 6\n";
  };
  write(dir, "small.obj", box(0.06));
  write(dir, "large.obj", box(0.08));
  write(dir, "hand.plan", "start 0 0.2 0  1 0 0 0\nwait 0.1\n");
  const auto scenario = [&](const char* units) {
    return write(dir, std::string(units) + ".lua",
                 "return scenario {\n  name = \"units\", units = \"" + std::string(units) +
                     "\",\n  parts = { a = part { mesh = \"small.obj\" }, b = part { mesh = "
                     "\"large.obj\", at = { 1, 0, 0 } } },\n  hand = glove { plan = "
                     "\"hand.plan\" },\n}\n");
  };
  const Scenario mm = check_scenario(scenario("mm"));
  ASSERT_EQ(mm.warnings.size(), 1u);
  EXPECT_NE(mm.warnings[0].find("mm.lua:4: the parts from mesh files are a median of 0.139 mm "
                                "across, 1/1371 of the hand (190 mm): are the files in other "
                                "units? Their numbers are read in mm; if they are in m, give "
                                "the parts units = \"m\""),
            std::string::npos)
      << mm.warnings[0];
  EXPECT_TRUE(check_scenario(scenario("m")).warnings.empty());
  // Parts in millimetres read in metres, 25 and 30 m beside the hand: mm,
  // not the cm that would bring them nearest the hand's length.
  write(dir, "small.obj", box(25));
  write(dir, "large.obj", box(30));
  // (They overlap too, 1 m apart: a warning of its own.)
  const std::string m = testing::PrintToString(check_scenario(scenario("m")).warnings);
  EXPECT_NE(m.find("m.lua:4: the parts from mesh files are a median of 52 m across, 273 times "
                   "the hand (0.19 m): are the files in other units? Their numbers are read in m; "
                   "if they are in mm, give the parts units = \\\"mm\\\""),
            std::string::npos)
      << m;
}

TEST(ScenarioLoad, AnOpenOrWronglyWoundMeshIsAWarningThatCounts) {
  // A 20 mm box without its top (two triangles, four open edges), and one
  // with a face's two triangles wound inwards (four wrongly wound edges).
  const test::TempDir dir("dovetail_scenario");
  const std::string corners =
      "v 0 0 0\nv 20 0 0\nv 20 20 0\nv 0 20 0\nv 0 0 20\nv 20 0 20\nv 20 20 20\nv 0 20 20\n";
  const std::string sides =
      "f 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";
  write(dir, "open.obj", corners + "f 1 3 2\nf 1 4 3\n" + sides);
  write(dir, "flipped.obj", corners + "f 1 3 2\nf 1 4 3\nf 5 7 6\nf 5 8 7\n" + sides);
  write(dir, "closed.obj", corners + "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\n" + sides);
  const auto file = write(dir, "open.lua", R"(return scenario {
  name = "open", units = "mm",
  parts = {
    box = part { mesh = "open.obj", fixed = true },
    lid = part { mesh = "flipped.obj", at = { 0, 0, 40 } },
    peg = part { mesh = "closed.obj", at = { 0, 0, 80 } },
  },
  expect = { warnings_at_most(0) },
  duration = 0.1,
})");
  const Scenario s = check_scenario(file);
  ASSERT_EQ(s.warnings.size(), 2u);
  EXPECT_NE(s.warnings[0].find("open.lua:4: part 'box' (open.obj) is not a closed surface: 4 "
                               "open edges (a hole or a missing face); penetration depth "
                               "(max_penetration, a snap's overlap check) and inside tests need "
                               "a closed, consistently wound surface"),
            std::string::npos)
      << s.warnings[0];
  EXPECT_NE(s.warnings[1].find("open.lua:5: part 'lid' (flipped.obj) is not a closed surface: 4 "
                               "wrongly wound edges"),
            std::string::npos)
      << s.warnings[1];
  const RunOutcome o = run_scenario(file);
  EXPECT_EQ(o.warnings, s.warnings);
  ASSERT_EQ(o.status, RunOutcome::Status::kFailed) << o.failure_summary() << o.error;
  ASSERT_EQ(o.expectations.size(), 1u);
  EXPECT_NE(o.expectations[0].detail.find("2 warnings"), std::string::npos)
      << o.expectations[0].detail;

  // A part declared open_surface = true is known to be open: no warning of it.
  const auto declared = write(dir, "declared.lua", R"(return scenario {
  name = "open", units = "mm",
  parts = {
    box = part { mesh = "open.obj", fixed = true, open_surface = true },
    lid = part { mesh = "flipped.obj", at = { 0, 0, 40 } },
  },
})");
  const Scenario d = check_scenario(declared);
  ASSERT_EQ(d.warnings.size(), 1u);
  EXPECT_NE(d.warnings[0].find("part 'lid'"), std::string::npos) << d.warnings[0];

  // A depth measured against the open box is said not to be trusted, where
  // the failure gave it alone (and open_surface = true does not change that).
  const auto moved = write(dir, "moved.lua", R"(return scenario {
  name = "open", units = "mm", duration = 0.6,
  parts = {
    box = part { mesh = "open.obj", fixed = true, open_surface = true },
    peg = part { mesh = "closed.obj", at = { 0, 0, 60 } },
  },
  rules = { rule { when = after(0.1), act = { move("peg", { 5, 5, 5 }, 0.3) } } },
  expect = { max_penetration(0.01) },
})");
  const RunOutcome m = run_scenario(moved);
  ASSERT_EQ(m.status, RunOutcome::Status::kFailed) << m.failure_summary() << m.error;
  EXPECT_NE(m.expectations[0].detail.find("'box' is no closed surface (4 open edges"),
            std::string::npos)
      << m.expectations[0].detail;
  EXPECT_NE(m.expectations[0].detail.find("so this depth is not to be trusted"), std::string::npos)
      << m.expectations[0].detail;
}

TEST(ScenarioLoad, CheckWarnsOfAPlanInOtherUnitsAsTheRunDoes) {
  // A plan in millimetres: the hand goes some 100 m from the parts.
  const test::TempDir dir("dovetail_scenario");
  write(dir, "mm.plan", "start 0 100 0 1 0 0 0\nreach 1.0 0 60 0 1 0 0 0\n");
  const auto file =
      write(dir, "mm.lua", moved_peg("", "", "  hand = glove { plan = \"mm.plan\" },\n"));
  const Scenario s = check_scenario(file);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("glove: the hand is 9.99e+04 mm from every part at t=0.000 s; "
                               "plans and traces are in metres"),
            std::string::npos)
      << s.warnings[0];
  EXPECT_EQ(run_scenario(file).warnings, s.warnings);
}

TEST(ScenarioLoad, APartNamedWhereAMateBelongsIsSaidToBeAPart) {
  const test::TempDir dir("dovetail_scenario");
  const std::string what =
      load_error(write(dir, "kinds.lua", moved_peg("", "    mate_made \"peg\",")));
  EXPECT_NE(what.find("kinds.lua:20: mate_made: no mate 'peg' ('peg' is a part; mates: "
                      "peg_in_hole)"),
            std::string::npos)
      << what;
}

TEST(ScenarioRun, AMateOfAPartTheHandNeverHeldSaysWhyItCouldNotSnap) {
  // The peg is moved next to its place by a rule, never held: it cannot snap.
  const test::TempDir dir("dovetail_scenario");
  const auto file =
      write(dir, "unheld.lua",
            moved_peg("    rule { when = after(0.1), act = { move(\"peg\", { 0, 21, 0 }) } },",
                      "    mate_made \"peg_in_hole\","));
  const RunOutcome o = run_scenario(file);
  ASSERT_EQ(o.status, RunOutcome::Status::kFailed) << o.error;
  ASSERT_EQ(o.expectations.size(), 1u);
  EXPECT_NE(o.expectations[0].detail.find("; the hand never held it, and a part snaps when the "
                                          "hand lets it go (or by a rule's snap)"),
            std::string::npos)
      << o.expectations[0].detail;
}

TEST(ScenarioRun, AMateInsideTheCarriedSubAssemblyNeitherGuidesNorSnapsIt) {
  // The collar's mate into its own shaft is always in place, as both move
  // together: it must not draw the carried pair onto itself, nor take the
  // release's snap.
  const test::TempDir dir("dovetail_scenario");
  const RunOutcome plain = run_scenario(collar_on_shaft(dir, "plain.lua", "", ""));
  const RunOutcome inner = run_scenario(collar_on_shaft(
      dir, "inner.lua",
      "collar_on_shaft = mate { part = \"collar\", point = { 0, 0, 0 }, axis = \"z\", "
      "into = \"shaft\", at = { 0, 0, 0 }, along = \"z\" }",
      ""));
  ASSERT_EQ(plain.status, RunOutcome::Status::kPassed) << plain.error;
  ASSERT_EQ(inner.status, RunOutcome::Status::kPassed) << inner.error;
  EXPECT_EQ(inner.report.state_hash, plain.report.state_hash);
  for (const engine::Event& e : inner.report.events) {
    EXPECT_NE(e.kind, engine::EventKind::kMate) << e.a << " " << e.b;
  }
}

TEST(ScenarioRun, AReleasedSubAssemblyMakesEveryFitThatHoldsWhereItIsSeated) {
  // The shaft and its collar are carried down together and let go where
  // both fit the base. The first mate in the file seats them; the other
  // holds there too and fires. Once, only the first in name order fired,
  // the other's expectation failed "0 mm from its place", and renaming a
  // mate changed which one seated the pair.
  const test::TempDir dir("dovetail_scenario");
  const auto mates = [](const std::string& first, const std::string& second) {
    return first +
           " = mate { part = \"shaft\", point = { 0, 0, 0 }, axis = \"z\", into = \"base\", "
           "at = { -200, 65, 0 }, along = \"-y\" },\n    " +
           second +
           " = mate { part = \"collar\", point = { 0, 0, 0 }, axis = \"z\", into = \"base\", "
           "at = { -200, 65.5, 0 }, along = \"-y\" }";
  };
  const RunOutcome a =
      run_scenario(collar_on_shaft(dir, "a.lua", mates("shaft_fit", "collar_fit"), ""));
  const RunOutcome b =
      run_scenario(collar_on_shaft(dir, "b.lua", mates("z_shaft_fit", "a_collar_fit"), ""));
  for (const RunOutcome* o : {&a, &b}) {
    ASSERT_EQ(o->status, RunOutcome::Status::kPassed) << o->failure_summary() << o->error;
    std::vector<std::string> mated;
    for (const engine::Event& e : o->report.events) {
      if (e.kind == engine::EventKind::kMate) mated.push_back(e.a + " " + e.b);
    }
    EXPECT_EQ(mated, (std::vector<std::string>{"collar base", "shaft base"}));  // sorted in a frame
  }
  // The shaft's fit, first in the file, seated the pair whatever the names.
  EXPECT_EQ(a.report.state_hash, b.report.state_hash);
  std::map<std::string, Vec3> at;
  for (const auto& pose : a.final_poses) at[pose.part] = pose.position;
  EXPECT_NEAR(at["shaft"].y(), 0.065, 1e-12);
  EXPECT_NEAR(at["shaft"].x(), 0, 1e-12);
}

TEST(ScenarioRun, AStillClosedHandWithGloveNoiseGraspsNothing) {
  // The hand closes in the air, then comes down onto a bar and slides along
  // it, closed and still, with 0.5 degrees of noise on every joint. The
  // noise of 15 joints swings their sum by about 2 degrees a frame, which
  // the onset once took for closing: every seed grasped the bar as the hand
  // came down on it. Without the noise, no seed ever did.
  const test::TempDir dir("dovetail_scenario");
  write(dir, "slide.plan",
        "start -0.030 0.1108 0.080  1 0 0 0\n"
        "close 0.5 power\n"
        "wait 0.2\n"
        "reach 1.0  -0.030 0.0108 0.080  1 0 0 0\n"
        "reach 2.0  0.065 0.0108 0.080  1 0 0 0\n");
  for (int seed = 1; seed <= 6; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const auto file = write(dir, "still.lua",
                            R"(return scenario {
  name = "still", units = "mm",
  parts = { bar = part { shape = cylinder { diameter = 40, length = 120 }, at = { 60, 0.8, 0 },
                         turn = { y = -90 } } },
  hand = glove { plan = "slide.plan", noise = { position = 0, angle = 0, joints = 0.5, seed = )" +
                                std::to_string(seed) + R"( } },
}
)");
    const RunOutcome o = run_scenario(file);
    ASSERT_EQ(o.status, RunOutcome::Status::kPassed) << o.failure_summary();
    bool touched = false;
    for (const engine::Event& e : o.report.events) {
      EXPECT_NE(e.kind, engine::EventKind::kGrasp) << "at t=" << e.time;
      touched = touched || (e.kind == engine::EventKind::kHandContactBegin && e.b == "bar");
    }
    EXPECT_TRUE(touched) << "the hand must come down on the bar";
  }
}

TEST(ScenarioRun, AHeldPartIsKeptWhenTheFirstSampleReadHigh) {
  // `holding` takes the flexion at the grasp from the trace's first sample.
  // Here the thumb's reads 7 degrees above the closed hand's, and from 0.3 s
  // the hand relaxes by 1.5 degrees: 8.5 below that one sample, which once
  // let the part go. The flexion at the grasp now settles on the hand's own.
  const test::TempDir dir("dovetail_scenario");
  std::string trace =
      "t,x,y,z,qw,qx,qy,qz,thumb_roll,thumb_mcp,thumb_ip,thumb_abd,index_mcp,index_pip,index_dip,"
      "middle_mcp,middle_pip,middle_dip,ring_mcp,ring_pip,ring_dip,pinky_mcp,pinky_pip,pinky_dip,"
      "index_middle_abd,middle_ring_abd,ring_pinky_abd,palm_arch,wrist_pitch,wrist_yaw\n";
  for (int i = 0; i <= 90; ++i) {
    const double t = i / 90.0;
    const double thumb_mcp = i == 0 ? 37 : t >= 0.3 ? 28.5 : 30;
    char row[512];
    std::snprintf(row, sizeof(row),
                  "%.17g,0,0.15,0.09,1,0,0,0,50,%g,30,30,60,70,40,60,70,40,60,70,40,60,70,40,0,0,"
                  "0,11,0,0\n",
                  t, thumb_mcp);
    trace += row;
  }
  write(dir, "held.csv", trace);
  const auto file = write(dir, "held.lua", R"(return scenario {
  name = "held", units = "mm",
  parts = { peg = part { shape = cylinder { diameter = 20, length = 60 }, at = { 0, 100, 0 },
                         turn = { x = 90 } } },
  hand = glove { trace = "held.csv", holding = "peg" },
}
)");
  const RunOutcome o = run_scenario(file);
  ASSERT_EQ(o.status, RunOutcome::Status::kPassed) << o.failure_summary();
  for (const engine::Event& e : o.report.events) {
    EXPECT_NE(e.kind, engine::EventKind::kRelease) << e.b << " at t=" << e.time;
  }

  // A hand that opens at once, within the settling, still lets go: the
  // flexion at the grasp settles by half the release opening at most.
  std::string opening = trace.substr(0, trace.find('\n') + 1);
  for (int i = 0; i <= 90; ++i) {
    char row[512];
    const double k = i == 0 ? 1 : 0;  // closed at the first sample, open from the second
    std::snprintf(row, sizeof(row),
                  "%.17g,0,0.15,0.09,1,0,0,0,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,0,0,"
                  "0,%g,0,0\n",
                  i / 90.0, 50 * k, 30 * k, 30 * k, 30 * k, 60 * k, 70 * k, 40 * k, 60 * k, 70 * k,
                  40 * k, 60 * k, 70 * k, 40 * k, 60 * k, 70 * k, 40 * k, 11 * k);
    opening += row;
  }
  write(dir, "held.csv", opening);
  const RunOutcome opened = run_scenario(file);
  ASSERT_EQ(opened.status, RunOutcome::Status::kPassed) << opened.failure_summary();
  bool released = false;
  for (const engine::Event& e : opened.report.events) {
    released = released || (e.kind == engine::EventKind::kRelease && e.time < 0.2);
  }
  EXPECT_TRUE(released) << opened.to_json();
}

TEST(ScenarioRun, AHandClosingOnABarGraspsItWhereverThePalmLiesOnIt) {
  // Bars of 30 and 50 mm lying along x, the open hand above with its palm
  // from 2 mm into the bar to 1.5 mm above it and the wrist 50 to 80 mm
  // behind the bar's axis, closing to a fist: every placement grasps. Once
  // a digit stopped whole where its first segment met the bar, leaving its
  // tip in the air, and the palm's one nearest point lay under another
  // finger than the one wrapping round; 11 of these 40 placements grasped.
  const test::TempDir dir("dovetail_scenario");
  int grasped = 0, tried = 0;
  for (const double diameter : {30.0, 50.0}) {
    for (const double behind : {50.0, 60.0, 70.0, 80.0}) {
      for (const double above : {-2.0, -0.5, 0.0, 0.5, 1.5}) {
        const double wrist = diameter / 2 + 10.45 + above;  // the palm's face is 10.45 mm below it
        char plan[160];
        std::snprintf(plan, sizeof plan,
                      "start 0 %.6f %.6f  1 0 0 0 open\nclose 0.5 fist\nwait 0.2\n", wrist / 1000,
                      behind / 1000);
        write(dir, "bar.plan", plan);
        const auto file = write(dir, "bar.lua",
                                "return scenario {\n  name = \"bar\", units = \"mm\",\n"
                                "  parts = { bar = part { shape = cylinder { diameter = " +
                                    std::to_string(diameter) +
                                    ", length = 120 }, at = { -60, 0, 0 }, turn = { y = 90 } } },\n"
                                    "  hand = glove { plan = \"bar.plan\" },\n"
                                    "  expect = { grasped_as(\"bar\", \"power\") },\n}\n");
        const RunOutcome o = run_scenario(file);
        ++tried;
        grasped += o.status == RunOutcome::Status::kPassed;
        EXPECT_EQ(o.status, RunOutcome::Status::kPassed)
            << diameter << " mm bar, wrist " << behind << " mm behind, palm " << above
            << " mm above: " << o.failure_summary();
      }
    }
  }
  EXPECT_EQ(grasped, tried);
}

TEST(ScenarioRun, AGraspNeverMadeNamesThePartsThatStoppedTheFingers) {
  // A fist closed over a bar lying on a table: the ring and little fingers'
  // tips stop on the table, and the hand, carried on, grasps nothing. The
  // failure names the table beside what touched the bar.
  const test::TempDir dir("dovetail_scenario");
  write(dir, "fist.plan",
        "start 0 0.090 0.065  1 0 0 0 open\n"
        "reach 1.0  0 0.051 0.065  1 0 0 0\n"
        "close 0.5 fist\n"
        "reach 1.5  0.150 0.080 0.065  1 0 0 0\n");
  const RunOutcome o = run_scenario(write(dir, "fist.lua", R"(return scenario {
  name = "bar on a table", units = "mm",
  parts = {
    table = part { shape = box { size = { 1000, 1000, 1000 } }, at = { 0, -500, 0 }, fixed = true },
    bar = part { shape = cylinder { diameter = 40, length = 80 }, at = { -40, 20.5, 0 },
                 turn = { y = 90 } },
  },
  hand = glove { plan = "fist.plan" },
  expect = { grasped_as("bar", "power") },
})"));
  ASSERT_EQ(o.status, RunOutcome::Status::kFailed) << o.failure_summary() << o.error;
  ASSERT_EQ(o.expectations.size(), 1u);
  const std::string& detail = o.expectations[0].detail;
  EXPECT_NE(detail.find("the hand's closest try was at t="), std::string::npos) << detail;
  EXPECT_NE(detail.find("; then the hand touched 'table' ("), std::string::npos) << detail;
  EXPECT_NE(detail.find(") too, and a finger stops at the first part it meets"), std::string::npos)
      << detail;
}

TEST(ScenarioRun, AGraspNeverMadeIsExplainedByTheHandsClosestTry) {
  // A hand 5 mm too high wraps its fingers round the bar without its palm
  // on it; one far above never touches it. The failure says which.
  const test::TempDir dir("dovetail_scenario");
  const auto detail = [&](double wrist_mm, const char* hand = "close 0.5 fist") {
    char plan[128];
    std::snprintf(plan, sizeof plan, "start 0 %.6f 0.060  1 0 0 0 open\n%s\nwait 0.2\n",
                  wrist_mm / 1000, hand);
    write(dir, "bar.plan", plan);
    const RunOutcome o = run_scenario(write(dir, "bar.lua", R"(return scenario {
  name = "bar", units = "mm",
  parts = { bar = part { shape = cylinder { diameter = 30, length = 120 }, at = { -60, 0, 0 },
                         turn = { y = 90 } } },
  hand = glove { plan = "bar.plan" },
  expect = { grasped_as("bar", "power") },
})"));
    EXPECT_EQ(o.status, RunOutcome::Status::kFailed) << o.failure_summary() << o.error;
    return o.expectations.empty() ? std::string() : o.expectations[0].detail;
  };
  const std::string high = detail(15 + 10.45 + 5);
  EXPECT_NE(high.find("'bar' was never grasped as power; the hand's closest try was at t="),
            std::string::npos)
      << high;
  EXPECT_NE(high.find("index_distal"), std::string::npos) << high;
  EXPECT_NE(high.find("neither the palm (within 2 mm) nor the thumb's tip touched it"),
            std::string::npos)
      << high;
  EXPECT_NE(detail(200).find("the hand never touched it while it held nothing"), std::string::npos);
  // An open hand laid on the bar, which never closes.
  const std::string open = detail(15 + 10.45, "wait 0.5");
  EXPECT_NE(open.find("; the hand never touched it while closing (a grasp needs the glove's "
                      "flexion to rise by 10 degrees"),
            std::string::npos)
      << open;
}

TEST(ScenarioRun, AGraspBuildsUpThroughGloveNoise) {
  // A shaft with a collar, grasped by the shaft, carried into a hole, under
  // the glove's noise model (1 mm, 0.15 degrees, 0.5 degrees a joint): the
  // palm's contact flickers and the summed flexion of 15 joints swings by
  // more than the closing slack from frame to frame. The grasp must still
  // come as the close ends (at 1.0 s) and the shaft must seat, for every
  // seed; before, seed 1 grasped at 1.89 s and left the shaft 28 mm short.
  const test::TempDir dir("dovetail_scenario");
  write(dir, "shaft.plan",
        "start -0.070 0.110 0.080  0.7071067811865476 0 0 0.7071067811865476\n"
        "reach 0.6  -0.030 0.110 0.080  0.7071067811865476 0 0 0.7071067811865476\n"
        "close 0.4 power\n"
        "reach 2.0  -0.030 0.025 0.080  0.7071067811865476 0 0 0.7071067811865476\n"
        "wait 0.2\n"
        "open 0.3\n"
        "reach 0.5  -0.070 0.025 0.080  0.7071067811865476 0 0 0.7071067811865476\n");
  for (int seed = 1; seed <= 6; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const auto file = write(dir, "noisy.lua",
                            R"(return scenario {
  name = "noisy", units = "mm",
  parts = {
    block = part { shape = block_with_hole { size = { 100, 60, 100 }, hole = 40.5, depth = 40 }, fixed = true },
    shaft = part { shape = cylinder { diameter = 40, length = 130 }, at = { 0, 200, 0 }, turn = { x = 90 } },
    collar = part { shape = tube { outer = 60, inner = 39.9, length = 40 }, at = { 0, 200, 0 },
                    turn = { x = 90 }, attached_to = "shaft" },
  },
  mates = { seat = mate { part = "shaft", point = { 0, 0, 130 }, axis = "z", into = "block",
                          at = { 0, -10, 0 }, along = "-y" } },
  hand = glove { plan = "shaft.plan",
                 noise = { position = 1, angle = 0.15, joints = 0.5, seed = )" +
                                std::to_string(seed) + R"( } },
  expect = { mate_made "seat", max_penetration(0.01) },
})");
    const RunOutcome o = run_scenario(file);
    EXPECT_EQ(o.status, RunOutcome::Status::kPassed) << o.failure_summary() << o.error;
    std::optional<double> grasped;
    for (const engine::Event& e : o.report.events) {
      if (e.kind == engine::EventKind::kGrasp && !grasped) grasped = e.time;
    }
    ASSERT_TRUE(grasped.has_value());
    EXPECT_GT(*grasped, 0.6) << "not before the close";
    EXPECT_LT(*grasped, 1.2);
  }
}

TEST(ScenarioRun, MateMadeSaysWhereThePartWasWhenTheHandLetItGo) {
  // The shaft's seat is on the base, 200 mm away: released far from it.
  const test::TempDir dir("dovetail_scenario");
  std::string text;
  {
    std::ifstream in(collar_on_shaft(
        dir, "far.lua",
        "far = mate { part = \"shaft\", point = { 0, 0, 0 }, axis = \"z\", into = \"base\", "
        "at = { 0, 10, 0 }, along = \"-y\" }",
        ""));
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  const auto file = write(dir, "far.lua",
                          std::regex_replace(text, std::regex("  hand = glove"),
                                             "  expect = { mate_made \"far\" },\n  hand = glove"));
  const RunOutcome o = run_scenario(file);
  ASSERT_EQ(o.status, RunOutcome::Status::kFailed) << o.error;
  ASSERT_EQ(o.expectations.size(), 1u);
  EXPECT_NE(o.expectations[0].detail.find("'shaft' never snapped into 'base': when the hand let "
                                          "it go at t="),
            std::string::npos)
      << o.expectations[0].detail;
  EXPECT_NE(o.expectations[0].detail.find(" off; the closest it came was "), std::string::npos)
      << o.expectations[0].detail;
}

TEST(ScenarioRun, MateMadeSaysWhatStoppedThePartAndAnAxisTheWrongWayRound) {
  // A shaft 1 mm too thick for its hole rests on the block when the hand
  // lets it go: the failure says so, not only how far it was. A mate whose
  // axis points the other way is named as such.
  const test::TempDir dir("dovetail_scenario");
  write(dir, "shaft.plan",
        "start -0.070 0.110 0.080  0.7071067811865476 0 0 0.7071067811865476\n"
        "reach 0.6  -0.030 0.110 0.080  0.7071067811865476 0 0 0.7071067811865476\n"
        "close 0.4 power\n"
        "reach 2.0  -0.030 0.025 0.080  0.7071067811865476 0 0 0.7071067811865476\n"
        "wait 0.2\n"
        "open 0.3\n"
        "reach 0.5  -0.070 0.025 0.080  0.7071067811865476 0 0 0.7071067811865476\n");
  const auto shaft = [&](const std::string& name, double hole, const std::string& axis) {
    return run_scenario(write(dir, name,
                              R"(return scenario {
  name = "shaft", units = "mm",
  parts = {
    block = part { shape = block_with_hole { size = { 100, 60, 100 }, hole = )" +
                                  std::to_string(hole) + R"(, depth = 40 }, fixed = true },
    shaft = part { shape = cylinder { diameter = 40, length = 130 }, at = { 0, 200, 0 }, turn = { x = 90 } },
  },
  mates = { seat = mate { part = "shaft", point = { 0, 0, 130 }, axis = ")" +
                                  axis +
                                  R"(", into = "block", at = { 0, -10, 0 }, along = "-y" } },
  hand = glove { plan = "shaft.plan" },
  expect = { mate_made "seat" },
})"));
  };
  const RunOutcome thick = shaft("thick.lua", 39, "z");
  ASSERT_EQ(thick.status, RunOutcome::Status::kFailed) << thick.error;
  EXPECT_NE(thick.expectations[0].detail.find(", resting against 'block' (sliding on it from t="),
            std::string::npos)
      << thick.expectations[0].detail;
  const RunOutcome reversed = shaft("reversed.lua", 40.5, "-z");
  ASSERT_EQ(reversed.status, RunOutcome::Status::kFailed) << reversed.error;
  EXPECT_NE(reversed.expectations[0].detail.find("its axis points the opposite way"),
            std::string::npos)
      << reversed.expectations[0].detail;
  EXPECT_EQ(shaft("right.lua", 40.5, "z").status, RunOutcome::Status::kPassed);
}

TEST(ScenarioRun, AHeldPartAttachedToAFixedPartIsLetGo) {
  // While carried, a rule attaches the shaft to the fixed base: the hand lets
  // the collar go ("attached"), and the pair stays where it was.
  const test::TempDir dir("dovetail_scenario");
  const RunOutcome o = run_scenario(collar_on_shaft(
      dir, "fixed.lua", "", "rule { when = after(1.5), act = { attach(\"shaft\", \"base\") } }"));
  ASSERT_EQ(o.status, RunOutcome::Status::kPassed) << o.error;
  std::vector<std::string> grasps;
  for (const engine::Event& e : o.report.events) {
    if (e.kind == engine::EventKind::kGrasp || e.kind == engine::EventKind::kRelease) {
      grasps.push_back(e.a + " " + e.b);
    }
  }
  EXPECT_EQ(grasps, (std::vector<std::string>{"collar power", "collar attached"}));
  for (const auto& pose : o.final_poses) {
    if (pose.part == "shaft") {
      EXPECT_GT(pose.position.y(), 0.1) << "let go on the way down";
    }
  }
}

TEST(ScenarioLoad, HoldingAPartAttachedToAFixedPartIsAnError) {
  const test::TempDir dir("dovetail_scenario");
  write(dir, "hold.plan", "start 0 0.2 0 1 0 0 0\nwait 0.5\n");
  const std::string what = load_error(write(dir, "hold.lua", R"(return scenario {
  name = "held", units = "mm",
  parts = {
    base = part { shape = box { size = { 20, 20, 20 } }, fixed = true },
    nut = part { shape = box { size = { 5, 5, 5 } }, at = { 0, 12, 0 }, attached_to = "base" },
  },
  hand = glove { plan = "hold.plan", holding = "nut" },
})"));
  EXPECT_NE(what.find("hold.lua:7: glove: the hand cannot hold 'nut': it is attached to 'base', "
                      "which is fixed"),
            std::string::npos)
      << what;
}

TEST(ScenarioRun, TextWithNulAndControlBytesIsKeptWholeAndShownEscaped) {
  // A NUL inside a logged text (a log action's and dt.log's) is kept, and
  // the report writes it as \u0000; the failure summary for the terminal
  // shows control bytes as \xNN.
  const test::TempDir dir("dovetail_scenario");
  const auto file = write(
      dir, "nul.lua",
      moved_peg(
          "    rule { when = after(0.1), act = { log \"a\\0b\" }, once = true },\n"
          "    rule { when = after(0.2), act = { custom(function(dt) dt.log(\"c\\0d\") end) },\n"
          "           once = true },\n"
          "    rule { when = after(0.3), act = { fail \"e\\27[31m\" }, once = true },",
          ""));
  const RunOutcome o = run_scenario(file);
  EXPECT_EQ(logged_texts(o),
            (std::vector<std::string>{std::string("a\0b", 3), std::string("c\0d", 3)}));
  const std::string json = o.to_json();
  EXPECT_NE(json.find(R"("text": "a\u0000b")"), std::string::npos) << json;
  // A part's name may hold one; a file name may not (it would name another file).
  const auto named =
      write(dir, "named.lua",
            "return scenario {\n  name = \"s\",\n  parts = {\n    [\"x\\0y\"] = part "
            "{ shape = box { size = { 1, 1, 1 } } },\n    z = part { mesh = "
            "\"cube.obj\\0junk\" },\n  },\n}\n");
  EXPECT_NE(
      load_error(named).find("named.lua:5: part 'z' 'mesh': a file name cannot hold a NUL byte: "
                             "\"cube.obj\\x00junk\""),
      std::string::npos);
  EXPECT_NE(o.failure_summary().find("failed at t=0.300 s: e\\x1B[31m\n"), std::string::npos)
      << o.failure_summary();
}

TEST(ScenarioRun, AMovedPartArrivesOnceInTheFrameItGetsThere) {
  // A move over 0.2 s from the start of the frame after t = 0.1, and one at
  // once: each arrives once, where it was sent; a move replaced before its
  // end does not arrive.
  const test::TempDir dir("dovetail_scenario");
  const auto file = write(
      dir, "arrive.lua",
      moved_peg("    rule { when = after(0.1), act = { move(\"peg\", { 0, 150, 0 }, 0.2) } },\n"
                "    rule { when = after(0.4), act = { move(\"peg\", { 0, 200, 0 }, 0.3) } },\n"
                "    rule { when = after(0.5), act = { move(\"peg\", { 0, 180, 0 }) } },\n"
                "    rule { when = arrives \"peg\", act = { custom(function(dt)\n"
                "      local x, y, z = dt.part(\"peg\"):translation()\n"
                "      dt.log(string.format(\"%.6g\", y))\n"
                "    end) } },",
                ""));
  const RunOutcome o = run_scenario(file);
  ASSERT_NE(o.status, RunOutcome::Status::kError) << o.error;
  const std::vector<std::pair<double, std::string>> logged = logged_messages(o);
  ASSERT_EQ(logged.size(), 2u) << o.to_json();
  EXPECT_EQ(logged[0].second, "150");
  EXPECT_GE(logged[0].first, 0.3);
  EXPECT_LE(logged[0].first, 0.3 + 3.0 / 90);  // sent a frame after the rule fired
  EXPECT_EQ(logged[1].second, "180");
  // The report gives where every part ended, in the scenario's units.
  ASSERT_EQ(o.final_poses.size(), 3u);
  EXPECT_EQ(o.final_poses[2].part, "peg");  // the parts' names in order
  EXPECT_NEAR(o.final_poses[2].position.y(), 0.180, 1e-12);
  EXPECT_NE(o.to_json().find("{\"part\": \"peg\", \"position\": [0, 180, 0], \"rotation\": ["),
            std::string::npos)
      << o.to_json();
  EXPECT_LE(logged[1].first, 0.5 + 3.0 / 90);
}

TEST(ScenarioRun, AFailedMateNamesWhatAPartCarriedWithItRestedAgainst) {
  // A shaft with a ring pressed on its end lies on a stand; carried into a
  // housing, the ring catches on the stand and holds it back 15 mm short.
  // The reason names the ring's slide on the stand, not only the shaft's.
  const test::TempDir dir("dovetail_scenario");
  write(dir, "push.plan",
        "start 0.090 0.150 0.065  1 0 0 0 open\nreach 1.0  0.090 0.0855 0.065  1 0 0 0\n"
        "close 0.5 fist\nwait 0.2\nreach 2.0  -0.035 0.0855 0.065  1 0 0 0\nwait 0.2\n"
        "open 0.3\nreach 0.5  -0.035 0.150 0.065  1 0 0 0\n");
  const auto file = write(dir, "ring.lua", R"(return scenario {
  name = "ring", units = "mm",
  parts = {
    housing = part {
      shape = block_with_hole { size = { 120, 60, 80 }, hole = 30.5, depth = 45 },
      at = { -100, 60, 0 }, turn = { z = -90 }, fixed = true,
    },
    stand = part { shape = box { size = { 30, 45, 50 } }, at = { 25, 22.5, 0 }, fixed = true },
    shaft = part {
      shape = cylinder { diameter = 30, length = 160 }, at = { 170, 60, 0 }, turn = { y = -90 },
    },
    ring = part {
      shape = tube { outer = 60, inner = 30.5, length = 20 }, at = { 150, 60, 0 },
      turn = { y = 90 }, attached_to = "shaft",
    },
  },
  mates = {
    shaft_in_housing = mate {
      part = "shaft", point = { 0, 0, 160 }, axis = "z",
      into = "housing", at = { 0, -15, 0 }, along = "-y",
    },
  },
  hand = glove { plan = "push.plan" },
  expect = { mate_made "shaft_in_housing" },
})");
  const RunOutcome o = run_scenario(file);
  ASSERT_EQ(o.status, RunOutcome::Status::kFailed) << o.error;
  const std::string& why = o.expectations[0].detail;
  EXPECT_NE(why.find("short of it along the axis"), std::string::npos) << why;
  EXPECT_NE(why.find("resting against 'stand' ('ring', moved with it, sliding on it from t="),
            std::string::npos)
      << why;
}

TEST(ScenarioRun, AMateNeverMadeSaysHowCloseItsPartCame) {
  // The peg moved to 12 mm above its place in the hole and left there.
  const test::TempDir dir("dovetail_scenario");
  const auto file = write(dir, "short.lua",
                          moved_peg("    rule { when = after(0.1), act = { move(\"peg\", { 0, 62, "
                                    "0 }, 0.2) } },",
                                    "    mate_made \"peg_in_hole\","));
  const RunOutcome o = run_scenario(file);
  ASSERT_EQ(o.status, RunOutcome::Status::kFailed) << o.error;
  const std::string summary = o.failure_summary();
  EXPECT_NE(summary.find("'peg' never snapped into 'block': the closest it came was 12 mm from its "
                         "place (12 mm short of it along the axis, on the axis), its axis 0 "
                         "degrees off, at t=0.311 s (a snap needs the part released within 2 mm "
                         "and 5 degrees)"),
            std::string::npos)
      << summary;
}

TEST(ScenarioRun, SetMatrixTakesSixteenNumbersWithTheLastRowOfAPose) {
  for (const auto& [matrix, message] :
       {std::pair{"{1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1, 5}", "needs 16 numbers, row by row"},
        std::pair{"{1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,1,1}", "the last row must be 0, 0, 0, 1"},
        std::pair{"{1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,2}", "the last row must be 0, 0, 0, 1"}}) {
    const test::TempDir dir("dovetail_scenario");
    const auto file = write(dir, "matrix.lua",
                            moved_peg(std::string("    rule { when = after(0.1), act = { "
                                                  "custom(function(dt)\n      dt.part(\"peg\"):"
                                                  "set_matrix(") +
                                          matrix + ")\n    end) } },",
                                      ""));
    const RunOutcome o = run_scenario(file);
    ASSERT_EQ(o.status, RunOutcome::Status::kError) << matrix;
    EXPECT_NE(o.error.find(std::string("set_matrix: ") + message), std::string::npos) << o.error;
  }
}

TEST(ScenarioRun, RegionsTimersAttachAndCompletedEventsAsDescribed) {
  const test::TempDir dir("dovetail_scenario");
  const auto file = write(dir, "words.lua", R"(return scenario {
  name = "words", units = "mm", duration = 1,
  parts = {
    a = part { shape = box { size = { 10, 10, 10 } } },
    c = part { shape = box { size = { 4, 4, 4 } }, at = { 0, 20, 0 } },
    base = part { shape = box { size = { 10, 10, 10 } }, at = { 0, 0, -100 }, fixed = true },
  },
  regions = { tray = region { min = { -20, -20, 80 }, max = { 20, 20, 120 } } },
  steps = { step { "arrive", done = enters("a", "tray") } },
  rules = {
    rule { when = after(0.1), act = { attach("c", "a"), move("a", { 0, 0, 100 }, 0.2) } },
    rule { when = enters("a", "tray"), act = { log "entered", hide "a" } },
    rule { when = completed "arrive", act = { log "arrived" } },
    rule { when = every(0.25), act = { log "tick" }, cooldown = 0 },
    rule { when = after(0.6), act = { detach "c", move("a", { 0, 0, 300 }, 0.1) } },
    rule { when = leaves("a", "tray"), only_if = done "arrive", act = { custom(function(dt)
      local x, y, z = dt.part("c"):translation()
      dt.log(string.format("c at %g %g %g", x, y, z))
    end) } },
  },
  expect = { steps_in_order { "arrive" }, no_contact("a", "base") },
})");
  const RunOutcome o = run_scenario(file);
  ASSERT_EQ(o.status, RunOutcome::Status::kPassed) << o.failure_summary() << o.error;
  std::vector<std::string> logged;
  for (const Message& m : o.messages) logged.push_back(m.text);
  // a reaches the tray (z >= 80 - 5 mm) during its move; c rode along 20 mm
  // above it and stayed where it was when detached at 0.6 s, while a left.
  const std::vector<std::string> expected = {"tick",          "entered", "arrived", "tick",
                                             "c at 0 20 100", "tick",    "tick"};
  EXPECT_EQ(logged, expected) << o.to_json();
  ASSERT_TRUE(o.steps[0].done_at);
  EXPECT_GT(*o.steps[0].done_at, 0.2);
  EXPECT_LT(*o.steps[0].done_at, 0.3);
}

TEST(ScenarioLoad, AGltfFileReadInMillimetresWithoutItsUnitsIsAWarning) {
  // glTF is in metres by its specification; this one's numbers are
  // millimetres, which a part says with units = "mm".
  const std::string engine =
      "/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";
  if (!std::filesystem::exists(engine))
    GTEST_SKIP() << engine << " (assimp-testmodels) is not installed";
  const test::TempDir dir("dovetail_scenario");
  const auto scenario = [&](const char* name, const std::string& units) {
    return check_scenario(write(dir, name,
                                "return scenario {\n  name = \"g\", units = \"mm\",\n  parts = "
                                "{\n    engine = part { mesh = \"" +
                                    engine + "\", open_surface = true" + units + " },\n  },\n}\n"));
  };
  const Scenario unsaid = scenario("unsaid.lua", "");
  ASSERT_EQ(unsaid.warnings.size(), 1u);
  EXPECT_NE(unsaid.warnings[0].find(
                "unsaid.lua:4: part 'engine' (" + engine +
                "): a glTF file is in metres by its specification, but its numbers are read in "
                "mm, as the scenario's: 836 mm across, where in metres it is 836 m; give the part "
                "units = \"m\", or units = \"mm\" if the file is in mm"),
            std::string::npos)
      << unsaid.warnings[0];
  EXPECT_TRUE(scenario("said.lua", ", units = \"mm\"").warnings.empty());
}

TEST(ScenarioLoad, ANodeTakenByTwoPartsWhereEachStandsIsAWarning) {
  // The piston's group holds its pin: the pin taken again as a part attached
  // to the piston is two pins in one place, which the overlap warning leaves
  // out between attached parts. A copy of the pin placed apart is a copy.
  const std::string engine =
      "/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";
  if (!std::filesystem::exists(engine))
    GTEST_SKIP() << engine << " (assimp-testmodels) is not installed";
  const test::TempDir dir("dovetail_scenario");
  const std::string mesh = "mesh = \"" + engine + "\", units = \"mm\", open_surface = true, ";
  const Scenario s =
      check_scenario(write(dir, "twice.lua",
                           "return scenario {\n  name = \"n\", units = \"mm\",\n  parts = {\n"
                           "    piston = part { " +
                               mesh +
                               "nodes = { \"nodes[4]\" } },\n"
                               "    pin = part { " +
                               mesh +
                               "nodes = { \"nodes[6]\" }, attached_to = \"piston\" },\n"
                               "    spare = part { " +
                               mesh +
                               "nodes = { \"nodes[6]\" }, at = { 500, 0, 0 } },\n"
                               "  },\n}\n"));
  ASSERT_EQ(s.warnings.size(), 1u) << testing::PrintToString(s.warnings);
  EXPECT_NE(s.warnings[0].find("twice.lua:5: parts 'pin' and 'piston' both take node 'nodes[6]' "
                               "of 2CylinderEngine.glb, where each stands: its triangles are in "
                               "both, one over the other"),
            std::string::npos)
      << s.warnings[0];
}

TEST(ScenarioLoad, NodesOfAMeshFileBecomeTheirOwnParts) {
  const std::string engine =
      "/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";
  if (!std::filesystem::exists(engine))
    GTEST_SKIP() << engine << " (assimp-testmodels) is not installed";
  const test::TempDir dir("dovetail_scenario");
  const std::string parts = "  parts = {\n    block = part { mesh = \"" + engine +
                            "\", without = { \"nodes[5]\", \"nodes[5]_2\" }, fixed = true },\n"
                            "    piston = part { mesh = \"" +
                            engine +
                            "\", nodes = { \"nodes[5]\", \"nodes[5]_2\" } },\n"
                            "    whole = part { mesh = \"" +
                            engine + "\", at = { 0, 1000, 0 } },\n  },\n";
  LuaHost host({}, 1);
  const Scenario s = load_scenario(
      host, write(dir, "nodes.lua", "return scenario {\n  name = \"n\",\n" + parts + "}\n"));
  ASSERT_EQ(s.parts.size(), 3u);
  const auto& block = *s.parts[0].mesh;
  const auto& piston = *s.parts[1].mesh;
  const auto& whole = *s.parts[2].mesh;
  EXPECT_GT(piston.triangles.size(), 100u);
  EXPECT_EQ(block.triangles.size() + piston.triangles.size(), whole.triangles.size());
  EXPECT_NE(s.parts[0].mesh, s.parts[1].mesh);  // one file, other nodes: meshes of their own
  EXPECT_NE(s.parts[1].mesh, s.parts[2].mesh);
  const std::string typo =
      load_error(write(dir, "typo.lua",
                       "return scenario { name = \"n\", parts = { p = part { mesh = \"" + engine +
                           "\", nodes = { \"node[5]\" } } } }\n"));
  EXPECT_NE(typo.find("2CylinderEngine.glb has no node 'node[5]' (did you mean 'nodes[5]'?)"),
            std::string::npos)
      << typo;
}

TEST(ScenarioLoad, ANodeIsTakenWholeAndAGroupWithEverythingInIt) {
  // In the glTF engine, node 78 holds one mesh of two primitives, imported
  // as parts nodes[78] (141 triangles) and nodes[78]_2 (721): either name
  // takes the whole node. Node 13 is a group of meshes: its name takes
  // every part below it.
  const std::string engine =
      "/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";
  if (!std::filesystem::exists(engine))
    GTEST_SKIP() << engine << " (assimp-testmodels) is not installed";
  engine::ImportOptions per_part;
  per_part.merge = false;
  const engine::ImportReport file = engine::import_file(engine, per_part);
  std::size_t node_78 = 0, in_13 = 0, parts_in_13 = 0;
  for (const engine::ImportedPart& p : file.parts) {
    if (p.name == "nodes[78]" || p.name == "nodes[78]_2") node_78 += p.mesh.triangles.size();
    if (std::find(p.groups.begin(), p.groups.end(), "nodes[13]") != p.groups.end()) {
      in_13 += p.mesh.triangles.size();
      ++parts_in_13;
    }
  }
  ASSERT_EQ(node_78, 862u);
  ASSERT_GT(parts_in_13, 2u);
  const test::TempDir dir("dovetail_scenario");
  LuaHost host({}, 1);
  const Scenario s = load_scenario(host, write(dir, "nodes.lua",
                                               "return scenario {\n  name = \"n\",\n  parts = {\n"
                                               "    first = part { mesh = \"" +
                                                   engine +
                                                   "\", nodes = { \"nodes[78]\" } },\n"
                                                   "    second = part { mesh = \"" +
                                                   engine +
                                                   "\", nodes = { \"nodes[78]_2\" } },\n"
                                                   "    group = part { mesh = \"" +
                                                   engine +
                                                   "\", nodes = { \"nodes[13]\" } },\n"
                                                   "    rest = part { mesh = \"" +
                                                   engine +
                                                   "\", without = { \"nodes[13]\" } },\n"
                                                   "  },\n}\n"));
  ASSERT_EQ(s.parts.size(), 4u);
  const auto triangles = [&](const std::string& name) {
    for (const PartSpec& p : s.parts) {
      if (p.name == name) return p.mesh->triangles.size();
    }
    ADD_FAILURE() << "no part " << name;
    return std::size_t{0};
  };
  EXPECT_EQ(triangles("first"), 862u);
  EXPECT_EQ(triangles("second"), 862u);
  EXPECT_EQ(triangles("group"), in_13);
  std::size_t all = 0;
  for (const engine::ImportedPart& p : file.parts) all += p.mesh.triangles.size();
  EXPECT_EQ(triangles("rest"), all - in_13);
  const std::string typo =
      load_error(write(dir, "typo.lua",
                       "return scenario { name = \"n\", parts = { p = part { mesh = \"" + engine +
                           "\", nodes = { \"nodes[133]\" } } } }\n"));
  EXPECT_NE(typo.find("has no node 'nodes[133]' (did you mean"), std::string::npos) << typo;
}

TEST(ScenarioLoad, PartsThatStartInsideEachOtherAreWarnedOf) {
  // A shaft through a housing's wall: warned of, with the depth. A pin
  // attached to the housing (pressed in), and a lid resting exactly on it,
  // are not.
  const test::TempDir dir("dovetail_scenario");
  LuaHost host({}, 1);
  const Scenario s = load_scenario(host, write(dir, "inside.lua", R"(return scenario {
  name = "n", units = "mm",
  parts = {
    housing = part { shape = box { size = { 40, 40, 40 } }, fixed = true },
    shaft = part { shape = cylinder { diameter = 10, length = 60 }, at = { 15, 0, -50 } },
    pin = part { shape = cylinder { diameter = 4, length = 10 }, at = { 0, 0, 5 },
                 attached_to = "housing" },
    lid = part { shape = box { size = { 40, 40, 4 } }, at = { 0, 0, 22 } },
  },
})"));
  ASSERT_EQ(s.warnings.size(), 1u) << testing::PrintToString(s.warnings);
  EXPECT_NE(s.warnings[0].find("inside.lua:5: parts 'shaft' and 'housing' (line 4) overlap by 10 "
                               "mm where the scenario places them"),
            std::string::npos)
      << s.warnings[0];
}

TEST(ScenarioLoad, PartsOfTheSameFileAndNodesShareOneMesh) {
  // Three bricks from one file share one mesh (so the pipeline builds its
  // hull and hierarchy once); the same file's nodes, or another file, do not.
  const test::TempDir dir("dovetail_scenario");
  const std::string cube =
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
      "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\n"
      "f 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";
  std::ofstream(dir / "cube.obj") << cube;
  std::ofstream(dir / "other.obj") << cube;
  std::filesystem::create_directory(dir / "sub");
  LuaHost host({}, 1);
  const Scenario s = load_scenario(host, write(dir, "bricks.lua", R"(return scenario {
  name = "n",
  parts = {
    a = part { mesh = "cube.obj" },
    b = part { mesh = "cube.obj", at = { 2, 0, 0 } },
    c = part { mesh = "sub/../cube.obj", at = { 4, 0, 0 } },
    d = part { mesh = "other.obj", at = { 6, 0, 0 } },
  },
})"));
  ASSERT_EQ(s.parts.size(), 4u);
  EXPECT_EQ(s.parts[0].mesh, s.parts[1].mesh);
  EXPECT_EQ(s.parts[0].mesh, s.parts[2].mesh);
  EXPECT_NE(s.parts[0].mesh, s.parts[3].mesh);
  EXPECT_EQ(s.parts[1].file, "cube.obj");
  EXPECT_EQ(s.parts[2].file, "sub/../cube.obj");
}

TEST(ScenarioRun, AGraspIsCheckedByItsType) {
  // The bar of the power-grasp test (44 mm across, under the palm of the hand at
  // the origin), closed on, lifted and let go by the simulated glove.
  const test::TempDir dir("dovetail_scenario");
  std::ofstream(dir / "grasp.plan")
      << "close 0.5 power\nwait 0.2\nreach 0.5 0 0.05 0 1 0 0 0\nopen 0.4\nwait 0.2\n";
  const auto file = write(dir, "grasp.lua", R"(return scenario {
  name = "bar", units = "mm",
  parts = { bar = part { shape = cylinder { diameter = 44, length = 80 }, at = { -20, -32.6, -60 }, turn = { y = 90 } } },
  hand = glove { plan = "grasp.plan" },
  rules = { rule { when = grasped("bar", "power"), act = { log "power" } } },
  expect = { grasped_as("bar", "power"), grasped_as("bar", "precision") },
})");
  const RunOutcome o = run_scenario(file);
  ASSERT_EQ(o.status, RunOutcome::Status::kFailed) << o.failure_summary() << o.error;
  ASSERT_EQ(o.expectations.size(), 2u);
  EXPECT_TRUE(o.expectations[0].passed) << o.expectations[0].detail;
  EXPECT_FALSE(o.expectations[1].passed);
  EXPECT_NE(o.expectations[1].detail.find(
                "'bar' was never grasped as precision; it was grasped as power at t="),
            std::string::npos)
      << o.expectations[1].detail;
  ASSERT_EQ(o.messages.size(), 1u);
  EXPECT_EQ(o.messages[0].text, "power");
}

TEST(ScenarioRun, AnAttachThatWouldMakeACycleIsAWarningAtItsLine) {
  // The cap is attached to the peg, then the peg to the cap: the second is
  // refused with a warning naming its rule, and the run goes on.
  const test::TempDir dir("dovetail_scenario");
  const RunOutcome o = run_scenario(write(dir, "cycle.lua", R"(return scenario {
  name = "cycle", units = "mm", duration = 0.5,
  parts = {
    peg = part { shape = cylinder { diameter = 20, length = 60 } },
    cap = part { shape = box { size = { 30, 10, 30 } }, at = { 0, 0, 70 } },
  },
  rules = {
    rule { when = after(0.1), act = { attach("cap", "peg") } },
    rule { when = after(0.2), act = { attach("peg", "cap") } },
  },
  expect = { warnings_at_most(0) },
})"));
  ASSERT_EQ(o.status, RunOutcome::Status::kFailed) << o.error;
  ASSERT_EQ(o.messages.size(), 1u);
  EXPECT_EQ(o.messages[0].level, "warn");
  EXPECT_EQ(o.messages[0].where.line, 9);
  EXPECT_EQ(o.messages[0].text,
            "attach: 'cap' moves with 'peg' already; attaching 'peg' to it would make a cycle, so "
            "it stays as it was");
}

TEST(ScenarioRun, APartAttachedFromTheStartMovesWithItsPartAndItsPressFitIsNotAnOverlap) {
  // A bearing pressed on a shaft (bore 0.2 mm under the shaft): attached
  // from the start, it moves with the shaft, and their overlap is not
  // counted by max_penetration.
  const test::TempDir dir("dovetail_scenario");
  const RunOutcome o = run_scenario(write(dir, "press.lua", R"(return scenario {
  name = "press fit", units = "mm", duration = 0.5,
  parts = {
    shaft = part { shape = cylinder { diameter = 20, length = 60 } },
    bearing = part { shape = tube { outer = 40, inner = 19.8, length = 10 }, at = { 0, 0, 20 },
                     attached_to = "shaft" },
    block = part { shape = box { size = { 10, 10, 10 } }, at = { 100, 0, 0 }, fixed = true },
  },
  rules = { rule { when = after(0.1), act = { move("shaft", { 0, 50, 0 }) } } },
  expect = { max_penetration(0.01) },
})"));
  ASSERT_EQ(o.status, RunOutcome::Status::kPassed) << o.failure_summary() << o.error;
  ASSERT_EQ(o.final_poses.size(), 3u);
  for (const auto& pose : o.final_poses) {
    if (pose.part == "bearing") {
      EXPECT_NEAR(pose.position.y(), 0.050, 1e-12);
    }
  }
  const std::string cycle = load_error(write(dir, "cycle.lua", R"(return scenario {
  name = "cycle", units = "mm",
  parts = {
    a = part { shape = box { size = { 1, 1, 1 } }, attached_to = "b" },
    b = part { shape = box { size = { 1, 1, 1 } }, attached_to = "a" },
    c = part { shape = box { size = { 1, 1, 1 } }, fixed = true, attached_to = "a" },
  },
})"));
  EXPECT_NE(cycle.find("cycle.lua:4: part 'a': attached_to makes a cycle: 'a' to 'b' to 'a'"),
            std::string::npos)
      << cycle;
  EXPECT_NE(cycle.find("cycle.lua:6: part 'c': attached_to: the part is fixed, so it cannot move "
                       "with 'a'"),
            std::string::npos)
      << cycle;
}

TEST(ScenarioRun, AGloveInOtherUnitsFailsWarningsAtMostZero) {
  // The bar's plan written in millimetres: the hand is 50 m from every part.
  // The set-up's warning says so, and warnings_at_most(0) counts it.
  const test::TempDir dir("dovetail_scenario");
  std::ofstream(dir / "grasp.plan") << "reach 0.5 0 50 0 1 0 0 0\n";
  const auto file = write(dir, "units.lua", R"(return scenario {
  name = "bar", units = "mm",
  parts = { bar = part { shape = cylinder { diameter = 44, length = 80 }, at = { -20, -32.6, -60 }, turn = { y = 90 } } },
  hand = glove { plan = "grasp.plan" },
  expect = { warnings_at_most(0) },
})");
  const RunOutcome o = run_scenario(file);
  ASSERT_EQ(o.status, RunOutcome::Status::kFailed) << o.failure_summary() << o.error;
  ASSERT_EQ(o.warnings.size(), 1u);
  EXPECT_NE(o.warnings[0].find("is it written in other units?"), std::string::npos)
      << o.warnings[0];
  ASSERT_EQ(o.expectations.size(), 1u);
  EXPECT_NE(o.expectations[0].detail.find("1 warning; first over the limit: warning before "
                                          "the run: "),
            std::string::npos)
      << o.expectations[0].detail;
}

/// The glove trace of a run of the shipped peg-in-hole scenario, recorded in `dir`.
std::filesystem::path recorded_peg_trace(const test::TempDir& dir) {
  RunOptions record;
  record.record = dir / "peg.csv";
  EXPECT_EQ(run_scenario(kScenarios / "01_peg_in_hole.lua", record).status,
            RunOutcome::Status::kPassed);
  return *record.record;
}

/// The file `from` written to `to` line by line, each line (0-based `row`)
/// through `edit`.
void rewrite_lines(const std::filesystem::path& from, const std::filesystem::path& to,
                   const std::function<std::string(int row, const std::string& line)>& edit) {
  std::ifstream in(from);
  std::ofstream out(to);
  std::string line;
  for (int row = 0; std::getline(in, line); ++row) out << edit(row, line) << "\n";
}

/// The text of the shipped peg-in-hole scenario.
std::string peg_in_hole_text() {
  std::ifstream f(kScenarios / "01_peg_in_hole.lua");
  return std::string(std::istreambuf_iterator<char>(f), {});
}

TEST(ScenarioRun, AMateOfAPartStillHeldAtTheEndSaysSo) {
  // The shipped peg in hole cut at 1 s, the peg still in the hand.
  const test::TempDir dir("dovetail_scenario");
  std::string text = std::regex_replace(peg_in_hole_text(), std::regex("units = \"mm\","),
                                        "units = \"mm\", duration = 1,");
  text = std::regex_replace(text, std::regex("\\.\\./assets"), (kScenarios / "../assets").string());
  const RunOutcome o = run_scenario(write(dir, "cut.lua", text));
  ASSERT_EQ(o.status, RunOutcome::Status::kFailed);
  const auto made = std::find_if(o.expectations.begin(), o.expectations.end(), [](const auto& e) {
    return e.text == "mate_made(\"peg_in_hole\")";
  });
  ASSERT_NE(made, o.expectations.end());
  EXPECT_NE(made->detail.find("; the hand still held it when the run ended, and a part snaps when "
                              "the hand lets it go"),
            std::string::npos)
      << made->detail;
}

TEST(ScenarioReplay, ATraceOnADeviceClockIsNamedAsSuch) {
  // A trace whose times count from 1970 (device time) rather than from the
  // start of the run: too long without a duration, said with where it starts;
  // with one, a warning that the hand stays at its first sample until then.
  const test::TempDir dir("dovetail_scenario");
  rewrite_lines(recorded_peg_trace(dir), dir / "epoch.csv", [](int row, const std::string& line) {
    if (row == 0) return line;  // the header
    const std::size_t comma = line.find(',');
    char t[64];
    std::snprintf(t, sizeof t, "%.17g", 1732752000.25 + std::stod(line.substr(0, comma)));
    return t + line.substr(comma);
  });
  RunOptions replay;
  replay.trace = dir / "epoch.csv";
  const RunOutcome too_long = run_scenario(kScenarios / "01_peg_in_hole.lua", replay);
  ASSERT_EQ(too_long.status, RunOutcome::Status::kError);
  EXPECT_NE(too_long.error.find("epoch.csv: the trace ends at t=1.73275e+09 s (it starts at "
                                "t=1.73275e+09 s; its times are seconds from the start of the "
                                "run), later than the 3600.000 s a run may last; shift its times "
                                "to start at 0 (subtract 1732752000.25 s from each)"),
            std::string::npos)
      << too_long.error;
  std::filesystem::create_directories(dir / "scenarios");
  std::ofstream(dir / "scenarios" / "short.lua") << std::regex_replace(
      peg_in_hole_text(), std::regex("units = \"mm\","), "units = \"mm\", duration = 1,");
  const RunOutcome frozen = run_scenario(dir / "scenarios" / "short.lua", replay);
  ASSERT_NE(frozen.status, RunOutcome::Status::kError) << frozen.error;
  ASSERT_FALSE(frozen.warnings.empty());
  EXPECT_NE(frozen.warnings[0].find("epoch.csv: the trace starts at t=1.73275e+09 s; until then "
                                    "the hand stays at its first sample"),
            std::string::npos)
      << frozen.warnings[0];
}

TEST(ScenarioReplay, AJointFarOutsideItsRangeIsAWarning) {
  // One sample's index_mcp at 500 degrees (a column misnamed, or radians
  // scaled twice): clamped as always, and now said before the run.
  const test::TempDir dir("dovetail_scenario");
  rewrite_lines(recorded_peg_trace(dir), dir / "bent.csv", [](int row, const std::string& line) {
    if (row != 2) return line;
    std::size_t at = 0;  // index_mcp is the 13th column
    for (int k = 0; k < 12; ++k) at = line.find(',', at) + 1;
    return line.substr(0, at) + "500" + line.substr(line.find(',', at));
  });
  RunOptions replay;
  replay.trace = dir / "bent.csv";
  const RunOutcome o = run_scenario(kScenarios / "01_peg_in_hole.lua", replay);
  ASSERT_EQ(o.warnings.size(), 1u) << o.error;
  EXPECT_NE(o.warnings[0].find("bent.csv: index_mcp reaches 500 deg at t=0.0111111 s, outside "
                               "its range [-30, 90] by 410 deg (clamped)"),
            std::string::npos)
      << o.warnings[0];
  EXPECT_EQ(o.status, RunOutcome::Status::kFailed) << "warnings_at_most(0) counts it";
}

TEST(ScenarioReplay, ATraceCutShortIsAWarning) {
  // A file cut short after its last value, before the line end: it reads
  // (so would one cut inside a value of several digits), so the replay says
  // what may have happened.
  const test::TempDir dir("dovetail_scenario");
  std::ifstream in(recorded_peg_trace(dir), std::ios::binary);
  std::string text(std::istreambuf_iterator<char>(in), {});
  ASSERT_EQ(text.back(), '\n');
  text.pop_back();
  std::ofstream(dir / "cut.csv", std::ios::binary) << text;
  RunOptions replay;
  replay.trace = dir / "cut.csv";
  const RunOutcome o = run_scenario(kScenarios / "01_peg_in_hole.lua", replay);
  ASSERT_EQ(o.warnings.size(), 1u) << o.error;
  EXPECT_NE(o.warnings[0].find("cut.csv: its last line has no line end"), std::string::npos)
      << o.warnings[0];
  EXPECT_EQ(o.status, RunOutcome::Status::kFailed) << "warnings_at_most(0) counts it";
}

TEST(ScenarioReplay, TimesInMillisecondsOrBeforeZeroAreNamed) {
  const test::TempDir dir("dovetail_scenario");
  const auto shifted = [&](const std::string& name, double scale, double shift) {
    rewrite_lines(recorded_peg_trace(dir), dir / name, [&](int row, const std::string& line) {
      if (row == 0) return line;
      const std::size_t comma = line.find(',');
      char t[64];
      std::snprintf(t, sizeof t, "%.17g", std::stod(line.substr(0, comma)) * scale + shift);
      return t + line.substr(comma);
    });
    return dir / name;
  };
  // Times in half-milliseconds: too long without a duration, and the error says why.
  RunOptions ms;
  ms.trace = shifted("ms.csv", 2000, 0);
  const RunOutcome too_long = run_scenario(kScenarios / "01_peg_in_hole.lua", ms);
  ASSERT_EQ(too_long.status, RunOutcome::Status::kError);
  EXPECT_NE(too_long.error.find("s a run may last; its samples are 22.22 s apart (the median)"),
            std::string::npos)
      << too_long.error;
  EXPECT_NE(too_long.error.find("are its times in milliseconds?"), std::string::npos)
      << too_long.error;
  // Two seconds before 0: those samples are not used, and a warning says so.
  RunOptions early;
  early.trace = shifted("early.csv", 1, -2);
  const RunOutcome o = run_scenario(kScenarios / "01_peg_in_hole.lua", early);
  ASSERT_FALSE(o.warnings.empty()) << o.error;
  EXPECT_NE(o.warnings[0].find("early.csv: the trace starts at t=-2.000 s; what it holds before "
                               "t=0 is not used"),
            std::string::npos)
      << o.warnings[0];
}

TEST(ScenarioReplay, AScenarioWithoutAGloveGetsTheTracesHandWithoutAWarning) {
  // Replayed, a scenario with no glove gets the trace's hand, so a rule on
  // released() can happen: no "the scenario has no hand".
  const test::TempDir dir("dovetail_scenario");
  RunOptions replay;
  replay.trace = recorded_peg_trace(dir);
  std::filesystem::create_directories(dir / "scenarios");
  std::ofstream(dir / "scenarios" / "noglove.lua")
      << std::regex_replace(peg_in_hole_text(), std::regex("  hand = glove [^\n]*\n"), "");
  const RunOutcome o = run_scenario(dir / "scenarios" / "noglove.lua", replay);
  ASSERT_NE(o.status, RunOutcome::Status::kError) << o.error;
  for (const std::string& w : o.warnings) EXPECT_EQ(w.find("has no hand"), std::string::npos) << w;
  EXPECT_FALSE(run_scenario(dir / "scenarios" / "noglove.lua").warnings.empty())
      << "run without the trace: the rule on released() can never happen";
}

TEST(ScenarioReplay, AScenarioWithoutAGloveMayNameTheHandWhenReplayed) {
  // touches("hand", ...) needs a hand: run alone, the scenario has none (an
  // error at its line); replayed, the trace's hand is there.
  const test::TempDir dir("dovetail_scenario");
  RunOptions replay;
  replay.trace = recorded_peg_trace(dir);
  std::filesystem::create_directories(dir / "scenarios");
  const std::string text = std::regex_replace(
      std::regex_replace(peg_in_hole_text(), std::regex("  hand = glove [^\n]*\n"), ""),
      std::regex("  rules = \\{\n"),
      "  rules = {\n    rule { when = touches(\"hand\", \"peg\"), act = { log \"touched\" } },\n");
  std::ofstream(dir / "scenarios" / "hand.lua") << text;
  const RunOutcome o = run_scenario(dir / "scenarios" / "hand.lua", replay);
  ASSERT_NE(o.status, RunOutcome::Status::kError) << o.error;
  const RunOutcome alone = run_scenario(dir / "scenarios" / "hand.lua");
  ASSERT_EQ(alone.status, RunOutcome::Status::kError);
  EXPECT_NE(alone.error.find("touches: the scenario has no hand"), std::string::npos)
      << alone.error;
}

TEST(ShippedScenarios, PegInHolePassesAndGivesTheSameReportAtAnyThreadCountAndOnReplay) {
  const test::TempDir dir("dovetail_scenario");
  RunOptions options;
  options.record = dir / "peg.csv";
  const RunOutcome first = run_scenario(kScenarios / "01_peg_in_hole.lua", options);
  ASSERT_EQ(first.status, RunOutcome::Status::kPassed) << first.failure_summary();
  for (const int threads : {2, 8}) {
    RunOptions again;
    again.threads = threads;
    EXPECT_EQ(run_scenario(kScenarios / "01_peg_in_hole.lua", again).to_json(), first.to_json())
        << threads;
  }
  RunOptions replay;
  replay.trace = dir / "peg.csv";
  EXPECT_EQ(run_scenario(kScenarios / "01_peg_in_hole.lua", replay).to_json(), first.to_json());
}

TEST(ScenarioRun, TheHandEntersAndLeavesARegionAsOne) {
  // The open hand sweeps 200 mm along x through a region, so its 16
  // segments enter one after another and leave one after another; the
  // timeline and the rules see the hand come in once and go out once.
  const test::TempDir dir("dovetail_scenario");
  write(dir, "sweep.plan",
        "start -0.200 0.100 0.000  0.7071067811865476 0 0 0.7071067811865476\n"
        "reach 1.0  0.200 0.100 0.000  0.7071067811865476 0 0 0.7071067811865476\n");
  const auto file = write(dir, "sweep.lua", R"(return scenario {
  name = "sweep", units = "mm", duration = 1.2,
  parts = {
    base = part { shape = box { size = { 20, 20, 20 } }, at = { 0, -200, 0 }, fixed = true },
  },
  regions = {
    gate = region { min = { -10, 0, -150 }, max = { 10, 200, 150 } },
    hand_only = region { min = { -10, 0, -150 }, max = { 10, 200, 150 }, parts = { "hand" } },
    base_only = region { min = { -10, 0, -150 }, max = { 10, 200, 150 }, parts = { "base" } },
  },
  hand = glove { plan = "sweep.plan" },
  rules = {
    rule { when = enters("hand", "gate"), only_if = inside("hand", "hand_only"),
           act = { log "in" } },
    rule { when = leaves("hand", "hand_only"), act = { log "out" } },
    rule { when = enters("hand", "base_only"), act = { log "never" } },
  },
})");
  LuaHost host({}, 1);
  const Scenario s = load_scenario(host, file);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("sweep.lua:16: rule: enters(\"hand\", \"base_only\") can never "
                               "happen: region 'base_only' watches only 'base'"),
            std::string::npos)
      << s.warnings[0];
  const RunOutcome o = run_scenario(file);
  ASSERT_EQ(o.status, RunOutcome::Status::kPassed) << o.failure_summary() << o.error;
  EXPECT_EQ(logged_texts(o), (std::vector<std::string>{"in", "out"})) << o.to_json();
  std::vector<std::string> regions;
  for (const engine::Event& e : o.report.events) {
    if (e.kind == engine::EventKind::kRegionEnter || e.kind == engine::EventKind::kRegionLeave)
      regions.push_back(std::string(engine::event_kind_name(e.kind)) + " " + e.a + " " + e.b);
  }
  EXPECT_EQ(regions,
            (std::vector<std::string>{"region_enter hand gate", "region_enter hand hand_only",
                                      "region_leave hand gate", "region_leave hand hand_only"}));
}

TEST(ScenarioRun, ARegionNamingTheHandTwiceWatchesItOnce) {
  const test::TempDir dir("dovetail_scenario");
  write(dir, "hand.plan", "start 0 0.2 0  1 0 0 0\nwait 0.1\n");
  const RunOutcome o = run_scenario(write(
      dir, "twice.lua",
      moved_peg("", "",
                "  hand = glove { plan = \"hand.plan\" },\n"
                "  regions = { r = region { min = { -500, -500, -500 }, max = { 500, 500, 500 }, "
                "parts = { \"hand\", \"hand\" } } },\n")));
  ASSERT_EQ(o.status, RunOutcome::Status::kPassed) << o.failure_summary() << o.error;
  std::size_t entered = 0;
  for (const engine::Event& e : o.report.events)
    entered += e.kind == engine::EventKind::kRegionEnter;
  EXPECT_EQ(entered, 1u);
}

TEST(ScenarioLoad, ARegionWatchingTheHandNeedsOne) {
  const test::TempDir dir("dovetail_scenario");
  const std::string error =
      load_error(write(dir, "nohand.lua",
                       moved_peg("", "",
                                 "  regions = { r = region { min = { 0, 0, 0 }, max = { 1, 1, 1 }, "
                                 "parts = { \"hand\" } } },\n")));
  EXPECT_NE(error.find("nohand.lua:22: region 'r': the scenario has no hand"), std::string::npos)
      << error;
}
}  // namespace
}  // namespace dovetail::scripting
