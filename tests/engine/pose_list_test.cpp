#include "dovetail/engine/pose_list.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "dovetail/collision/pose_sampling.h"

namespace dovetail::engine {
namespace {

namespace fs = std::filesystem;
using collision::Mat3;
using collision::Transform;
using collision::Vec3;

class TempFile {
 public:
  explicit TempFile(const std::string& content) {
    std::string pattern = (fs::temp_directory_path() / "dovetail_poses_XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    dir_ = pattern;
    path_ = dir_ / "poses.txt";
    std::ofstream(path_, std::ios::binary) << content;
  }
  ~TempFile() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  const fs::path& path() const { return path_; }
  const fs::path& dir() const { return dir_; }

 private:
  fs::path dir_;
  fs::path path_;
};

/// The PoseListError message of reading `content`, failing the test otherwise.
std::string read_error(const std::string& content, std::string* prefix = nullptr) {
  TempFile file(content);
  if (prefix != nullptr) *prefix = file.path().string();
  try {
    read_pose_list(file.path());
  } catch (const PoseListError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error for:\n" << content;
  return {};
}

TEST(PoseList, ReadsPosesSkippingCommentsBlankLinesAndExtraColumns) {
  TempFile file(
      "# tx ty tz qw qx qy qz\n"
      "\n"
      "1 2 3 1 0 0 0\n"
      "   # indented comment\n"
      "\t-0.5 +2.5e-1 1e3 0 0 0 1 0.01 anything here\r\n"
      "0 0 0 2 0 0 0\n"
      "   \n");
  const std::vector<PoseEntry> poses = read_pose_list(file.path());
  ASSERT_EQ(poses.size(), 3u);
  EXPECT_EQ(poses[0].line, 3u);
  EXPECT_EQ(poses[0].X_AB.t, Vec3(1, 2, 3));
  EXPECT_EQ(poses[0].X_AB.R, Mat3::Identity());
  EXPECT_EQ(poses[1].line, 5u);
  EXPECT_EQ(poses[1].X_AB.t, Vec3(-0.5, 0.25, 1000));
  // 180 degrees about z.
  EXPECT_EQ(poses[1].X_AB.R, collision::rotation_from_quaternion(0, 0, 0, 1));
  EXPECT_NEAR(poses[1].X_AB.R(0, 0), -1, 1e-15);
  // Normalised: (2, 0, 0, 0) is the identity.
  EXPECT_EQ(poses[2].line, 6u);
  EXPECT_EQ(poses[2].X_AB.R, Mat3::Identity());
}

TEST(PoseList, RotationIsTheGeneratorsBitForBit) {
  const double q[4] = {0.3, -0.2, 0.9, 0.11};
  const std::optional<Transform> X = parse_pose_line(
      "0.1 0.2 0.3 0.29999999999999999 -0.20000000000000001 0.90000000000000002 0.11", "here");
  ASSERT_TRUE(X.has_value());
  EXPECT_EQ(X->R, collision::rotation_from_quaternion(q[0], q[1], q[2], q[3]));
}

TEST(PoseList, ExtremeButValidQuaternionsGiveRotations) {
  for (const char* line :
       {"0 0 0 1e300 1e300 0 0", "0 0 0 1e-200 0 1e-200 0", "0 0 0 4.9e-324 0 0 0"}) {
    SCOPED_TRACE(line);
    const std::optional<Transform> X = parse_pose_line(line, "here");
    ASSERT_TRUE(X.has_value());
    EXPECT_TRUE(X->R.allFinite());
    EXPECT_NEAR((X->R * X->R.transpose() - Mat3::Identity()).norm(), 0, 1e-12);
  }
}

TEST(PoseList, BadLinesNameFileAndLine) {
  struct Case {
    const char* content;
    const char* where;  // ":line: "
    const char* what;
  };
  const Case cases[] = {
      {"1 2 3 1 0 0 0\n1 2 3 1 0 0\n", ":2: ", "found 6"},
      {"1 2 3\n", ":1: ", "found 3"},
      {"# c\n\n1 2 x 1 0 0 0\n", ":3: ", "'x' is not a number"},
      {"1 2 3 1 0 0 0abc\n", ":1: ", "is not a number"},
      {"+-1 2 3 1 0 0 0\n", ":1: ", "'+-1' is not a number"},
      {"1 2 3 0 0 0 0\n", ":1: ", "zero"},
      {"1 2 3 -0 0 0 -0\n", ":1: ", "zero"},
      {"nan 2 3 1 0 0 0\n", ":1: ", "not finite"},
      {"1 2 3 inf 0 0 0\n", ":1: ", "not finite"},
      {"1 2 3 1 0 0 1e999\n", ":1: ", "not finite"},
      {"1 -2e30 3 1 0 0 0\n", ":1: ", "column 2 (ty) '-2e30' is beyond the coordinate limit"},
      {"1,2,3,1,0,0,0\n", ":1: ", "not a number"},
      {"\n\n\n\n\n\n\n\n\n\n\n1 2 3 1 0 0\n", ":12: ", "expected 7 columns"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.content);
    std::string file;
    const std::string message = read_error(c.content, &file);
    EXPECT_EQ(message.rfind(file + c.where, 0), 0u) << message;
    EXPECT_NE(message.find(c.what), std::string::npos) << message;
  }
}

TEST(PoseList, ReaderKeepsThePosesBeforeABadLine) {
  TempFile file("0 0 0 1 0 0 0\n1 0 0 1 0 0 0\n# fine\n1 0 0 0 0 0 0\n2 0 0 1 0 0 0\n");
  PoseListReader reader(file.path());
  std::vector<PoseEntry> good;
  std::string error;
  try {
    while (std::optional<PoseEntry> pose = reader.next()) good.push_back(*pose);
  } catch (const PoseListError& e) {
    error = e.what();
  }
  EXPECT_EQ(good.size(), 2u);
  EXPECT_EQ(reader.line(), 4u);
  EXPECT_EQ(error.rfind(file.path().string() + ":4: ", 0), 0u) << error;
}

TEST(PoseList, MissingFileAndDirectory) {
  TempFile file("");
  EXPECT_TRUE(read_pose_list(file.path()).empty());
  try {
    read_pose_list(file.dir() / "absent.txt");
    ADD_FAILURE();
  } catch (const PoseListError& e) {
    EXPECT_NE(std::string(e.what()).find("absent.txt: file not found"), std::string::npos);
  }
  EXPECT_THROW(read_pose_list(file.dir()), PoseListError);
}

TEST(PoseList, QuaternionFromRotationInvertsRotationFromQuaternion) {
  // Random rotations plus the awkward ones: identity and half turns (trace -1).
  std::vector<Mat3> rotations;
  for (const Transform& X : collision::random_poses(500, 1.0, 7)) rotations.push_back(X.R);
  rotations.push_back(Mat3::Identity());
  rotations.push_back(collision::rotation_from_quaternion(0, 1, 0, 0));
  rotations.push_back(collision::rotation_from_quaternion(0, 0, 1, 0));
  rotations.push_back(collision::rotation_from_quaternion(0, 0, 0, 1));
  rotations.push_back(collision::rotation_from_quaternion(0, 1, 1, 0));
  rotations.push_back(collision::rotation_from_quaternion(1e-9, 0, 0, 1));
  for (const Mat3& R : rotations) {
    const Quaternion q = quaternion_from_rotation(R);
    EXPECT_GE(q.w, 0);
    EXPECT_NEAR(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z, 1, 1e-15);
    const Mat3 back = collision::rotation_from_quaternion(q.w, q.x, q.y, q.z);
    EXPECT_LT((back - R).cwiseAbs().maxCoeff(), 2e-15) << R;
  }
}

TEST(PoseList, WriteThenReadRoundTrips) {
  const std::vector<Transform> poses = collision::random_poses(200, 3.0, 11);
  TempFile file("");
  write_pose_list(file.path(), poses, "written by a test");
  std::ifstream in(file.path());
  std::string first;
  std::getline(in, first);
  EXPECT_EQ(first, "# written by a test");

  const std::vector<PoseEntry> read = read_pose_list(file.path());
  ASSERT_EQ(read.size(), poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    EXPECT_EQ(read[i].X_AB.t, poses[i].t);  // %.17g: translations exactly
    EXPECT_LT((read[i].X_AB.R - poses[i].R).cwiseAbs().maxCoeff(), 2e-15);
  }
  // Reading what was written and writing it again reaches a fixed point.
  std::vector<Transform> once;
  for (const PoseEntry& e : read) once.push_back(e.X_AB);
  TempFile second("");
  write_pose_list(second.path(), once);
  std::vector<Transform> twice;
  for (const PoseEntry& e : read_pose_list(second.path())) twice.push_back(e.X_AB);
  for (std::size_t i = 0; i < once.size(); ++i) {
    EXPECT_EQ(twice[i].t, once[i].t);
    EXPECT_LT((twice[i].R - once[i].R).cwiseAbs().maxCoeff(), 2e-15);
  }
}

TEST(PoseList, FormatUsesSeventeenDigits) {
  Transform X;
  X.t = Vec3(0.1, -1.0 / 3.0, 1e-300);  // 1e-300 needs no more digits
  EXPECT_EQ(format_pose(X), "0.10000000000000001 -0.33333333333333331 1e-300 1 0 0 0");
}

TEST(PoseList, WriteToAnUnwritablePathFails) {
  TempFile file("");
  const std::vector<Transform> poses(1);
  EXPECT_THROW(write_pose_list(file.dir() / "no/such/folder/p.txt", poses), PoseListError);
  EXPECT_THROW(write_pose_list(file.dir(), poses), PoseListError);
}

}  // namespace
}  // namespace dovetail::engine
