#include "dovetail/interaction/glove_plan.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "../support/temp_dir.h"
#include "dovetail/interaction/glove_source.h"
#include "dovetail/interaction/postures.h"

namespace dovetail::interaction {
namespace {

GlovePlan parse(const std::string& text) {
  std::istringstream in(text);
  return read_plan(in, "plan.txt");
}

/// The message read_plan throws for `text`, or "" when it reads.
std::string error_of(const std::string& text) {
  try {
    parse(text);
  } catch (const PlanError& e) {
    return e.what();
  }
  return "";
}

void expect_pose(const TrackerPose& X, Real x, Real y, Real z, const Quaternion& q) {
  EXPECT_EQ(X.p_WH, Vec3(x, y, z));
  EXPECT_EQ(X.q_WH.w, q.w);
  EXPECT_EQ(X.q_WH.x, q.x);
  EXPECT_EQ(X.q_WH.y, q.y);
  EXPECT_EQ(X.q_WH.z, q.z);
}

std::string angles_text(Real first) {
  std::string text;
  for (std::size_t j = 0; j < kJointCount; ++j) {
    text += ' ';
    text += std::to_string(first + static_cast<Real>(j));
  }
  return text;
}

TEST(GlovePlan, ReadsEveryStepKind) {
  const GlovePlan plan = parse(
      "# a plan with every step\n"
      "\n"
      "start 0.1 0.2 0.3 1 0 0 0 pinch   # the pose at t = 0\n"
      "reach 1.5 0.4 -0.5 +0.6 0 0 0 2\n"
      "\t path 2  0 0 1 0 3 0 0  1e-3 0 1 0 0 0 -0.5\r\n"
      "close 0.5 fist\n"
      "close 0.25" +
      angles_text(-3) +
      "\n"
      "open 0\n"
      "   \n"
      "wait 0.75\n"
      "# done\n");
  expect_pose(plan.start, 0.1, 0.2, 0.3, {1, 0, 0, 0});
  EXPECT_EQ(plan.start_posture, *named_posture("pinch"));
  ASSERT_EQ(plan.steps.size(), 6u);

  const PlanStep& reach = plan.steps[0];
  EXPECT_EQ(reach.kind, PlanStep::Kind::kReach);
  EXPECT_EQ(reach.duration, 1.5);
  ASSERT_EQ(reach.poses.size(), 1u);
  expect_pose(reach.poses[0], 0.4, -0.5, 0.6, {0, 0, 0, 1});  // normalised

  const PlanStep& path = plan.steps[1];
  EXPECT_EQ(path.kind, PlanStep::Kind::kPath);
  EXPECT_EQ(path.duration, 2);
  ASSERT_EQ(path.poses.size(), 2u);
  expect_pose(path.poses[0], 0, 0, 1, {0, 1, 0, 0});
  expect_pose(path.poses[1], 1e-3, 0, 1, {0, 0, 0, -1});

  EXPECT_EQ(plan.steps[2].kind, PlanStep::Kind::kClose);
  EXPECT_EQ(plan.steps[2].duration, 0.5);
  EXPECT_EQ(plan.steps[2].posture, *named_posture("fist"));

  EXPECT_EQ(plan.steps[3].kind, PlanStep::Kind::kClose);
  EXPECT_EQ(plan.steps[3].duration, 0.25);
  for (std::size_t j = 0; j < kJointCount; ++j) {
    EXPECT_EQ(plan.steps[3].posture[j], -3 + static_cast<Real>(j));
  }

  EXPECT_EQ(plan.steps[4].kind, PlanStep::Kind::kOpen);
  EXPECT_EQ(plan.steps[4].duration, 0);
  EXPECT_EQ(plan.steps[5].kind, PlanStep::Kind::kWait);
  EXPECT_EQ(plan.steps[5].duration, 0.75);
  EXPECT_EQ(plan.duration(), 1.5 + 2 + 0.5 + 0.25 + 0 + 0.75);
}

TEST(GlovePlan, StartIsOptionalAndMayGiveAngles) {
  const GlovePlan plain = parse("wait 1\n");
  expect_pose(plain.start, 0, 0, 0, {1, 0, 0, 0});
  EXPECT_EQ(plain.start_posture, *named_posture("open"));

  const GlovePlan angled = parse("start 1 2 3 0 0 5 0" + angles_text(10) + "\nwait 1\n");
  expect_pose(angled.start, 1, 2, 3, {0, 0, 1, 0});
  for (std::size_t j = 0; j < kJointCount; ++j) {
    EXPECT_EQ(angled.start_posture[j], 10 + static_cast<Real>(j));
  }
}

TEST(GlovePlan, ReadPlanDrivesTheSimulatedGlove) {
  const SimulatedGlove glove(
      parse("start 0 0 0 1 0 0 0\n"
            "reach 1 0.2 0 0 1 0 0 0\n"
            "close 1 fist\n"));
  EXPECT_EQ(glove.sample(0.5).p_WH.x(), 0.1);
  EXPECT_EQ(glove.sample(2).joints, *named_posture("fist"));
  EXPECT_EQ(glove.end_time(), 2);
}

struct BadPlan {
  std::string text;
  std::string message;
};

TEST(GlovePlan, ErrorsNameTheLine) {
  std::string postures;
  for (const std::string& name : posture_names()) postures += (postures.empty() ? "" : ", ") + name;
  const std::string pose = " 0 0 0 1 0 0 0";
  const std::vector<BadPlan> cases = {
      {"wait 1\n\n# comment\nfly 2\n",
       "plan.txt:4: unknown step 'fly' (expected start, reach, path, close, open or wait)"},
      {"Wait 1\n",
       "plan.txt:1: unknown step 'Wait' (expected start, reach, path, close, open or "
       "wait)"},
      {"wait 1\nreach 1 0 0 0 1 0 0\n",
       "plan.txt:2: reach expects DURATION X Y Z QW QX QY QZ, found 7 fields"},
      {"reach 1" + pose + " 9\n",
       "plan.txt:1: reach expects DURATION X Y Z QW QX QY QZ, found 9 fields"},
      {"path 1\n",
       "plan.txt:1: path expects DURATION and one or more poses X Y Z QW QX QY QZ, found 1 field"},
      {"path 1" + pose + " 4\n",
       "plan.txt:1: path expects DURATION and one or more poses X Y Z QW QX QY QZ, found 9 "
       "fields"},
      {"close 1\n",
       "plan.txt:1: close expects DURATION and a posture name or 22 angles, found 1 "
       "field"},
      {"close 1 fist 2\n",
       "plan.txt:1: close expects DURATION and a posture name or 22 angles, found 3 fields"},
      {"open\n", "plan.txt:1: open expects DURATION, found 0 fields"},
      {"wait 1 2\n", "plan.txt:1: wait expects DURATION, found 2 fields"},
      {"start 0 0 0 1 0 0\nwait 1\n",
       "plan.txt:1: start expects X Y Z QW QX QY QZ and an optional posture (a name or 22 "
       "angles), found 6 fields"},
      {"wait 1\nwait abc\n", "plan.txt:2: wait duration 'abc' is not a number"},
      {"reach 1 0 0 x 1 0 0 0\n", "plan.txt:1: reach z 'x' is not a number"},
      {"reach 1 0 0 0 1 0 0 0,\n", "plan.txt:1: reach qz '0,' is not a number"},
      {"path 1" + pose + " 0 0 0 1 0 y 0\n", "plan.txt:1: path pose 2 qy 'y' is not a number"},
      {"close 1 1 2 3 4 5 six 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22\n",
       "plan.txt:1: close index_pip 'six' is not a number"},
      {"start 0 0 0 1 0 0 0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 q\nwait 1\n",
       "plan.txt:1: start wrist_yaw 'q' is not a number"},
      {"wait inf\n", "plan.txt:1: wait duration 'inf' is not finite"},
      {"reach 1 0 0 1e999 1 0 0 0\n", "plan.txt:1: reach z '1e999' is not finite"},
      {"reach 1 0 0 0 nan 0 0 0\n", "plan.txt:1: reach qw 'nan' is not finite"},
      {"wait 1\nwait 2\nwait -0.5\n", "plan.txt:3: wait duration '-0.5' is negative"},
      {"reach 1 0 0 0 0 0 0 0\n", "plan.txt:1: reach quaternion (qw qx qy qz) is zero"},
      {"path 1" + pose + " 1 1 1 0 0 -0 0\n",
       "plan.txt:1: path pose 2 quaternion (qw qx qy qz) is zero"},
      {"start 0 0 0 0 0 0 0\nwait 1\n", "plan.txt:1: start quaternion (qw qx qy qz) is zero"},
      {"wait 1\nclose 1 claw\n", "plan.txt:2: unknown posture 'claw' (known: " + postures + ")"},
      {"start" + pose + " claw\nwait 1\n",
       "plan.txt:1: unknown posture 'claw' (known: " + postures + ")"},
      {"wait 1\nstart" + pose + "\n", "plan.txt:2: start must come before every other step"},
      {"start" + pose + "\n# again\nstart" + pose + "\nwait 1\n",
       "plan.txt:3: start given twice (first on line 1)"},
      {"wait 1e308\nwait 1e308\n", "plan.txt:2: the plan's duration overflows"},
      {"", "plan.txt: plan has no steps"},
      {"# nothing\n\n", "plan.txt: plan has no steps"},
      {"start" + pose + " fist\n", "plan.txt: plan has no steps"},
  };
  for (const BadPlan& bad : cases) EXPECT_EQ(error_of(bad.text), bad.message) << bad.text;
}

TEST(GlovePlan, NegativeZeroDurationIsAllowed) {
  const GlovePlan plan = parse("wait -0\n");
  ASSERT_EQ(plan.steps.size(), 1u);
  EXPECT_EQ(plan.steps[0].duration, 0);
}

TEST(GlovePlan, ReadsAFileAndNamesItInErrors) {
  const test::TempDir dir("dovetail_plan");
  const std::filesystem::path good = dir / "good.txt";
  std::ofstream(good, std::ios::binary) << "start 0 0 0 1 0 0 0\nclose 1 power\n";
  const GlovePlan plan = read_plan(good);
  ASSERT_EQ(plan.steps.size(), 1u);
  EXPECT_EQ(plan.steps[0].posture, *named_posture("power"));

  const std::filesystem::path bad = dir / "bad.txt";
  std::ofstream(bad, std::ios::binary) << "wait 1\nwait x\n";
  const auto message = [](const std::filesystem::path& path) {
    try {
      read_plan(path);
    } catch (const PlanError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(message(bad), bad.string() + ":2: wait duration 'x' is not a number");
  EXPECT_EQ(message(dir / "missing.txt"), (dir / "missing.txt").string() + ": file not found");
  EXPECT_EQ(message(dir.path()), dir.path().string() + ": is a directory");
}

}  // namespace
}  // namespace dovetail::interaction
