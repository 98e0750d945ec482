// The helpers behind `dovetail query`: pose loops (collision, distance,
// tolerance, contacts) and their output formats, and the option parsers they need.

#include "pose_queries.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "cli.h"
#include "dovetail/collision/primitives.h"

namespace dovetail::cli {
namespace {

using collision::Transform;
using collision::Vec3;

Transform translation(double x, double y, double z) {
  Transform X;
  X.t = Vec3(x, y, z);
  return X;
}

Transform rotation_about_z(double angle, const Vec3& t) {
  Transform X;
  X.R << std::cos(angle), -std::sin(angle), 0, std::sin(angle), std::cos(angle), 0, 0, 0, 1;
  X.t = t;
  return X;
}

// The number following the first `key` in `json`; NaN when the key is absent.
double number_after(const std::string& json, const std::string& key) {
  const std::size_t at = json.find(key);
  if (at == std::string::npos) return std::numeric_limits<double>::quiet_NaN();
  return std::strtod(json.c_str() + at + key.size(), nullptr);
}

struct TwoBoxes {
  std::shared_ptr<const collision::Mesh> a =
      std::make_shared<const collision::Mesh>(collision::make_box(Vec3(1, 1, 0.5)));
  std::shared_ptr<const collision::Mesh> b =
      std::make_shared<const collision::Mesh>(collision::make_box(Vec3(0.5, 0.5, 0.5)));
  // B above A at known gaps along z (A's top is z = 0.5, B's bottom z = t.z - 0.5),
  // resting, sunk, and turned about z while hovering.
  std::vector<Transform> poses = {
      translation(0, 0, 1.25), translation(0.25, -0.5, 3),
      translation(0, 0, 1),    translation(0, 0, 0.75),
      translation(3, 0, 0),    rotation_about_z(0.3, Vec3(0.1, 0.2, 1.0625)),
      translation(2, 0, 1.5),
  };
  // Exact distances of the poses above; the last is corner edge to corner edge,
  // (0.5, 0.5) apart in x and z.
  std::vector<double> expected = {0.25, 2, 0, 0, 1.5, 0.0625, std::sqrt(0.5)};
};

TEST(PoseQueries, ForEachPoseVisitsEveryIndexOnce) {
  for (int threads : {1, 2, 0}) {
    std::vector<std::atomic<int>> visits(1000);
    for_each_pose(visits.size(), threads, [&](std::size_t i) { ++visits[i]; });
    for (std::size_t i = 0; i < visits.size(); ++i) {
      ASSERT_EQ(visits[i].load(), 1) << "index " << i << ", threads " << threads;
    }
  }
}

TEST(PoseQueries, DistancesOfTheRssTreeEqualBruteForceAtAnyThreadCount) {
  const TwoBoxes scene;
  const auto model_a = collision::build_distance_model(scene.a);
  const auto model_b = collision::build_distance_model(scene.b);
  const DistanceInputs rss{scene.a.get(), scene.b.get(), model_a.get(), model_b.get()};
  const DistanceInputs brute{scene.a.get(), scene.b.get()};

  const DistanceQueryResult one = run_distance_queries(rss, scene.poses, 1);
  ASSERT_EQ(one.distances.size(), scene.poses.size());
  for (std::size_t i = 0; i < scene.poses.size(); ++i) {
    EXPECT_NEAR(one.distances[i], scene.expected[i], 1e-15) << "pose " << i;
  }
  EXPECT_EQ(one.distances[0], 0.25);
  EXPECT_EQ(one.distances[2], 0.0);
  EXPECT_EQ(one.colliding_count, 2u);
  EXPECT_EQ(one.distance_min, 0.0);
  EXPECT_EQ(one.distance_max, 2.0);
  EXPECT_GT(one.stats.volume_tests, 0u);
  EXPECT_GT(one.stats.triangle_tests, 0u);

  const DistanceQueryResult two = run_distance_queries(rss, scene.poses, 2);
  const DistanceQueryResult reference = run_distance_queries(brute, scene.poses, 1);
  EXPECT_EQ(two.distances, one.distances);
  EXPECT_EQ(reference.distances, one.distances);
  EXPECT_EQ(two.stats.volume_tests, one.stats.volume_tests);
  EXPECT_EQ(reference.stats.volume_tests, 0u);
}

TEST(PoseQueries, DistanceOfNoPosesHasNoMinimum) {
  const TwoBoxes scene;
  const DistanceQueryResult none =
      run_distance_queries({scene.a.get(), scene.b.get()}, std::span<const Transform>(), 2);
  EXPECT_TRUE(none.distances.empty());
  EXPECT_EQ(none.colliding_count, 0u);
  EXPECT_EQ(json_number(none.distance_min), "null");
  EXPECT_EQ(json_number(none.distance_max), "null");
}

TEST(PoseQueries, ToleranceVerdictsAreDistanceAtMostTolerance) {
  const TwoBoxes scene;
  const auto model_a = collision::build_distance_model(scene.a);
  const auto model_b = collision::build_distance_model(scene.b);
  const DistanceInputs rss{scene.a.get(), scene.b.get(), model_a.get(), model_b.get()};
  const DistanceInputs brute{scene.a.get(), scene.b.get()};
  const DistanceQueryResult d = run_distance_queries(brute, scene.poses, 1);
  for (double eps : {0.0, 0.0625, 0.1, 0.25, 1.5, 10.0}) {
    for (const DistanceInputs& inputs : {rss, brute}) {
      for (int threads : {1, 2}) {
        const ToleranceQueryResult t = run_tolerance_queries(inputs, scene.poses, eps, threads);
        ASSERT_EQ(t.within.size(), scene.poses.size());
        std::uint64_t count = 0;
        for (std::size_t i = 0; i < scene.poses.size(); ++i) {
          EXPECT_EQ(t.within[i] != 0, d.distances[i] <= eps) << "pose " << i << ", eps " << eps;
          count += d.distances[i] <= eps ? 1 : 0;
        }
        EXPECT_EQ(t.within_count, count);
      }
    }
  }
}

TEST(PoseQueries, ContactsOfABoxRestingOnABox) {
  const TwoBoxes scene;
  const auto model_a = collision::build_model(collision::Method::kBoxtree, scene.a);
  const auto model_b = collision::build_model(collision::Method::kBoxtree, scene.b);
  const ContactQueryResult one = run_contact_queries(*model_a, *model_b, scene.poses, {}, 1);
  ASSERT_EQ(one.lines.size(), scene.poses.size());
  EXPECT_EQ(one.lines[0], R"({"pose":0,"colliding":false,"patches":[]})");
  // Resting: one face patch, the whole bottom of B (area 1), normal from A to B.
  EXPECT_EQ(one.lines[2].rfind(R"({"pose":2,"colliding":true,"patches":[{"kind":"face",)", 0), 0u)
      << one.lines[2];
  EXPECT_NE(one.lines[2].find(R"("normal":[0,0,1],)"), std::string::npos) << one.lines[2];
  EXPECT_NEAR(number_after(one.lines[2], R"("area":)"), 1.0, 1e-12) << one.lines[2];
  EXPECT_NE(one.lines[2].find(R"("depth":0,"penetrating":false,)"), std::string::npos)
      << one.lines[2];
  // Sunk by 0.25: penetrating at the default touching tolerance.
  EXPECT_NE(one.lines[3].find(R"("penetrating":true)"), std::string::npos) << one.lines[3];
  EXPECT_EQ(one.colliding_count, 2u);
  EXPECT_GE(one.patches_total, 2u);
  EXPECT_EQ(one.face_patches + one.curve_patches + one.point_patches, one.patches_total);
  EXPECT_GE(one.face_patches, 1u);
  EXPECT_GE(one.penetrating_patches, 1u);
  EXPECT_GT(one.pairs_total, 0u);

  // A touching tolerance beyond the sinking depth makes every patch touching;
  // worker threads change nothing.
  collision::ContactRequest lenient;
  lenient.touching_tolerance = 0.5;
  const ContactQueryResult two = run_contact_queries(*model_a, *model_b, scene.poses, lenient, 2);
  EXPECT_EQ(two.penetrating_patches, 0u);
  EXPECT_EQ(two.patches_total, one.patches_total);
  EXPECT_EQ(two.lines[2], one.lines[2]);
  EXPECT_EQ(two.pairs_total, one.pairs_total);
}

TEST(PoseQueries, ContactLineFormat) {
  collision::ContactPatch patch;
  patch.kind = collision::ContactKind::kCurve;
  patch.point = Vec3(0.5, -0.25, 1e-20);
  patch.normal = Vec3(0, -1, 0);
  patch.area = 0;
  patch.length = 0.1;
  patch.depth = 2.5e-7;
  patch.penetrating = false;
  patch.pairs = {{0, 1}, {0, 2}, {3, 1}};
  const std::vector<collision::ContactPatch> patches = {patch, patch};
  const std::string one =
      R"({"kind":"curve","point":[0.5,-0.25,1e-20],"normal":[0,-1,0],"area":0,"length":0.1,)"
      R"("depth":2.5e-07,"penetrating":false,"pairs":3})";
  EXPECT_EQ(contact_line_json(7, true, patches),
            R"({"pose":7,"colliding":true,"patches":[)" + one + "," + one + "]}");
  EXPECT_EQ(contact_line_json(0, false, {}), R"({"pose":0,"colliding":false,"patches":[]})");
}

TEST(PoseQueries, DistancesAreWrittenToRoundTrip) {
  EXPECT_EQ(format_distance(0), "0");
  EXPECT_EQ(format_distance(0.25), "0.25");
  EXPECT_EQ(format_distance(0.1), "0.10000000000000001");
  EXPECT_EQ(format_distance(std::sqrt(0.5)), "0.70710678118654757");
  for (double d : {0.1, 1.0 / 3.0, 6.02214076e23, 5e-324, std::nextafter(1.0, 2.0)}) {
    EXPECT_EQ(std::strtod(format_distance(d).c_str(), nullptr), d) << format_distance(d);
  }
}

TEST(CliArgs, NumberIsFiniteAndAtLeastTheMinimum) {
  auto parse = [](const std::string& text) {
    const std::vector<std::string> argv = {"--tolerance", text};
    return Args("query", argv, {"tolerance"}, {}).number("tolerance", 0.0);
  };
  EXPECT_EQ(parse("0.5"), 0.5);
  EXPECT_EQ(parse("+2"), 2.0);
  EXPECT_EQ(parse("1e-3"), 1e-3);
  EXPECT_EQ(parse("0"), 0.0);
  EXPECT_FALSE(std::signbit(*parse("-0")));
  for (const char* bad : {"-1", "-1e-300", "nan", "inf", "-inf", "1e999", "", "+", "0.1x", "abc"}) {
    EXPECT_THROW(parse(bad), UsageError) << bad;
  }
  const std::vector<std::string> none;
  EXPECT_FALSE(Args("query", none, {"tolerance"}, {}).number("tolerance", 0.0));
}

TEST(CliJson, AddAllAppendsKeysInOrder) {
  JsonLine inner;
  inner.add("x", 1).add("y", "two");
  JsonLine outer;
  outer.add("a", true).add_all(inner).add_all(JsonLine()).add("z", 0.5);
  EXPECT_EQ(outer.str(), R"({"a":true,"x":1,"y":"two","z":0.5})");
  EXPECT_EQ(JsonLine().add_all(inner).str(), R"({"x":1,"y":"two"})");
}

}  // namespace
}  // namespace dovetail::cli
