// OpenXR joint poses made by the hand's own forward kinematics come back as
// the angles they were made from.

#include "dovetail/interaction/openxr_hand.h"

#include <gtest/gtest.h>

#include <random>
#include <sstream>

#include "dovetail/collision/pose_sampling.h"
#include "dovetail/interaction/glove_trace.h"
#include "dovetail/interaction/postures.h"

namespace dovetail::interaction {
namespace {

JointAngles random_angles(std::mt19937_64& random) {
  JointAngles q{};
  for (std::size_t j = 0; j < kJointCount; ++j) {
    const JointLimit& limit = joint_limits()[j];
    q[j] = std::uniform_real_distribution<Real>(limit.min, limit.max)(random);
  }
  at(q, Joint::kWristPitch) = 0;  // no forearm in OpenXR's joints
  at(q, Joint::kWristYaw) = 0;
  return q;
}

Transform random_pose(std::mt19937_64& random) {
  std::normal_distribution<Real> n;
  Transform X;
  X.R = collision::rotation_from_quaternion(n(random), n(random), n(random), n(random));
  X.t = Vec3(n(random), n(random), n(random));
  return X;
}

TEST(OpenXrHand, JointPosesFromKnownAnglesComeBackWithinATenthOfADegree) {
  std::mt19937_64 random(5);
  for (const char* size : {"adult_m50", "adult_f05"}) {
    const HandModel model({.size = size});
    std::vector<XrHandFrame> frames;
    std::vector<JointAngles> truth;
    for (const std::string& name : posture_names()) truth.push_back(*named_posture(name));
    for (int i = 0; i < 200; ++i) truth.push_back(random_angles(random));
    for (std::size_t i = 0; i < truth.size(); ++i) {
      frames.push_back(openxr_frame(model, truth[i], random_pose(random), 0.01 * i));
    }
    // Through the file format, as a headset's export would come.
    std::istringstream file(format_openxr(frames));
    const std::vector<GloveSample> samples = read_openxr(file, "hands.csv");
    ASSERT_EQ(samples.size(), truth.size());
    Real worst = 0;
    for (std::size_t i = 0; i < truth.size(); ++i) {
      for (std::size_t j = 0; j < kJointCount; ++j) {
        EXPECT_NEAR(samples[i].joints[j], truth[i][j], 0.1)
            << size << " frame " << i << " " << joint_name(static_cast<Joint>(j));
        worst = std::max(worst, std::abs(samples[i].joints[j] - truth[i][j]));
      }
      EXPECT_EQ(samples[i].t, frames[i].t);
      EXPECT_LT((samples[i].p_WH - frames[i].X_WJ[1].t).norm(), 1e-15);
      EXPECT_LT((samples[i].X_WH().R - frames[i].X_WJ[1].R).norm(), 1e-12);
    }
    // The conversion is the exact inverse: only rounding separates them.
    EXPECT_LT(worst, 1e-9) << size;
  }
}

TEST(OpenXrHand, ForwardKinematicsGivesOpenXrAxes) {
  // Flat hand at the origin: every finger bone points along -Z, backs along +Y.
  const HandModel model;
  const XrHandFrame frame = openxr_frame(model, JointAngles{}, Transform::identity(), 0);
  for (XrJoint j : {XrJoint::kIndexProximal, XrJoint::kMiddleDistal, XrJoint::kLittleTip}) {
    const Transform& X = frame.X_WJ[static_cast<std::size_t>(j)];
    EXPECT_LT((X.R * Vec3(0, 0, -1) - Vec3(0, 0, -1)).norm(), 1e-15) << openxr_joint_name(j);
    EXPECT_LT((X.R * Vec3(0, 1, 0) - Vec3(0, 1, 0)).norm(), 1e-15) << openxr_joint_name(j);
  }
  EXPECT_LT(frame.X_WJ[static_cast<std::size_t>(XrJoint::kIndexTip)].t.x(), 0) << "thumb side";
  EXPECT_EQ(openxr_joint_name(XrJoint::kLittleTip), "little_tip");
}

std::string error_of(const std::string& text) {
  std::istringstream in(text);
  try {
    read_openxr(in, "xr.csv");
  } catch (const TraceError& e) {
    return e.what();
  }
  return "no error";
}

TEST(OpenXrHand, BadFilesNameTheLine) {
  const HandModel model;
  const XrHandFrame frame = openxr_frame(model, JointAngles{}, Transform::identity(), 0);
  const std::string good = format_openxr(std::span(&frame, 1));
  const std::string header = good.substr(0, good.find('\n') + 1);
  const std::string row = good.substr(header.size());
  EXPECT_EQ(error_of(""), "xr.csv: empty, no header row");
  EXPECT_EQ(error_of(header), "xr.csv: no frames after the header");
  EXPECT_EQ(error_of(row), "xr.csv:1: expected a header row naming the columns, found numbers");
  std::string missing = header;
  missing.replace(missing.find(",palm_px"), 8, "");
  EXPECT_NE(error_of(missing).find("xr.csv:1: missing column 'palm_px'"), std::string::npos)
      << error_of(missing);
  std::string unknown = header;
  unknown.replace(unknown.find("palm_px"), 7, "elbow_px");
  EXPECT_NE(error_of(unknown).find("xr.csv:1: unknown column 'elbow_px'"), std::string::npos)
      << error_of(unknown);
  EXPECT_NE(error_of(header + row + row).find("xr.csv:3: time does not increase"),
            std::string::npos);
  std::string nan_row = row;
  nan_row.replace(nan_row.find(','), 1, ",nan,");
  EXPECT_NE(error_of(header + nan_row).find("xr.csv:2: expected"), std::string::npos)
      << error_of(header + nan_row);
  std::string inf_row = row;
  inf_row.replace(0, inf_row.find(','), "inf");
  EXPECT_NE(error_of(header + inf_row).find("xr.csv:2: column 't': 'inf' is not finite"),
            std::string::npos)
      << error_of(header + inf_row);
}

}  // namespace
}  // namespace dovetail::interaction
