// The Boxtree's subtree frames (boxtree.h): orthonormal rotations, frame
// boxes that hold their subtrees, exact answers with and without frames, and
// fewer volume tests where the surface is slanted to the mesh's axes.

#include "polygon/boxtree.h"

#include <gtest/gtest.h>

#include <memory>
#include <stdexcept>
#include <vector>

#include "dovetail/collision/model.h"
#include "dovetail/collision/pose_sampling.h"
#include "dovetail/collision/primitives.h"

namespace dovetail::collision {
namespace {

Mesh turned(const Mesh& m, const Mat3& R) {
  std::vector<Vec3> v;
  for (const Vec3& p : m.vertices) v.push_back(R * p);
  return make_mesh(v, m.triangles, m.source + " (turned)");
}

/// A turn that takes no axis near any of the mesh's axes.
Mat3 slant() { return rotation_from_quaternion(0.88, 0.28, -0.33, 0.19); }

/// A wavy sheet turned by slant(): no face is near the mesh's axes.
Mesh slanted_sheet() { return turned(make_wavy_sheet(1.0, 0.05, 3.0, 24), slant()); }

/// The triangles under `node`.
void subtree_triangles(const Boxtree& tree, std::uint32_t node, std::vector<std::uint32_t>& out) {
  const BoxtreeNode& n = tree.nodes()[node];
  if (n.is_leaf()) {
    for (int k = 0; k < n.leaf_count(); ++k) {
      out.push_back(k < 2 ? n.word[k] : tree.triangle_order()[n.index() + k - 2]);
    }
  } else if (n.is_frame()) {
    subtree_triangles(tree, tree.frames()[n.index()].child, out);
  } else {
    // A slab node's one child, or the first of two, is at index().
    subtree_triangles(tree, n.index(), out);
    if (n.kind() == BoxtreeNode::kBothChildren) subtree_triangles(tree, n.index() + 1, out);
  }
}

TEST(BoxtreeFrames, RotationsAreOrthonormalAndBoxesHoldTheirSubtrees) {
  const Mesh mesh = slanted_sheet();
  const Boxtree tree(mesh);
  ASSERT_GT(tree.frames().size(), 0u);
  std::vector<bool> seen(mesh.triangles.size(), false);
  for (std::uint32_t node = 0; node < tree.nodes().size(); ++node) {
    const BoxtreeNode& n = tree.nodes()[node];
    if (!n.is_frame()) continue;
    const Mat3 R = n.rotation();
    EXPECT_LT((R.transpose() * R - Mat3::Identity()).norm(), 1e-14);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-14);
    const BoxtreeFrame& f = tree.frames()[n.index()];
    std::vector<std::uint32_t> tris;
    subtree_triangles(tree, f.child, tris);
    ASSERT_FALSE(tris.empty());
    for (std::uint32_t t : tris) {
      for (std::uint32_t v : mesh.triangles[t]) {
        const Vec3 p = R.transpose() * mesh.vertices[v];
        for (int k = 0; k < 3; ++k) {
          EXPECT_LE(f.lo[k], p[k]);
          EXPECT_GE(f.hi[k], p[k]);
        }
      }
    }
  }
  // Every triangle is in exactly one leaf.
  std::vector<std::uint32_t> all;
  subtree_triangles(tree, 0, all);
  ASSERT_EQ(all.size(), mesh.triangles.size());
  for (std::uint32_t t : all) {
    EXPECT_FALSE(seen[t]);
    seen[t] = true;
  }
}

TEST(BoxtreeFrames, ExactWithAndWithoutFramesAndFewerTestsWithThem) {
  const Mesh sheet = slanted_sheet();
  const Mesh ball = make_sphere(0.3, 2);
  const Boxtree with_a(sheet), with_b(ball);
  BoxtreeSettings plain;
  plain.frames = false;
  const Boxtree without_a(sheet, plain), without_b(ball, plain);
  EXPECT_EQ(without_a.frames().size(), 0u);
  const auto brute_a = build_model(Method::kBrute, std::make_shared<const Mesh>(sheet));
  const auto brute_b = build_model(Method::kBrute, std::make_shared<const Mesh>(ball));

  // The ball near the sheet's surface: along the sheet's normal at random
  // points, from just through it to just clear of it.
  const Mat3 R = slant();
  const std::vector<Transform> jitter = random_poses(200, 0.8, 7);
  std::uint64_t tests_with = 0, tests_without = 0;
  int colliding = 0;
  for (std::size_t i = 0; i < jitter.size(); ++i) {
    Transform X = jitter[i];
    const Real lift = 0.3 + 0.1 * (static_cast<Real>(i % 9) - 4.0) / 4.0;
    X.t = R * Vec3(jitter[i].t.x(), jitter[i].t.y(), lift * (i % 2 ? 1 : -1));
    for (const bool all_pairs : {false, true}) {
      CollideRequest request;
      request.all_pairs = all_pairs;
      const CollideResult expected = brute_a->collide(*brute_b, X, request);
      const CollideResult framed = with_a.collide(sheet, with_b, ball, X, request);
      const CollideResult unframed = without_a.collide(sheet, without_b, ball, X, request);
      ASSERT_EQ(framed.colliding, expected.colliding) << "pose " << i;
      ASSERT_EQ(unframed.colliding, expected.colliding) << "pose " << i;
      if (all_pairs) {
        ASSERT_EQ(framed.pairs, expected.pairs) << "pose " << i;
        ASSERT_EQ(unframed.pairs, expected.pairs) << "pose " << i;
        colliding += expected.colliding ? 1 : 0;
      } else {
        tests_with += framed.stats.volume_tests;
        tests_without += unframed.stats.volume_tests;
      }
    }
  }
  EXPECT_GT(colliding, 0);
  EXPECT_LT(colliding, static_cast<int>(jitter.size()));
  EXPECT_LT(tests_with, tests_without);
}

TEST(BoxtreeFrames, SettingsAreChecked) {
  const Mesh ball = make_sphere(1.0, 1);
  BoxtreeSettings bad;
  bad.frame_step = 1;
  EXPECT_THROW(Boxtree(ball, bad), std::invalid_argument);
}

}  // namespace
}  // namespace dovetail::collision
