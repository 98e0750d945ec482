// Where collision methods are known to fail, each with the expectation
// Dovetail states for it (docs/weak-spots.md): an exact verdict, or a
// documented and bounded failure. Every polygon-level method is checked
// against brute force; the work each did is printed, so the figures in the
// docs can be reproduced with
//   build/tests/collision_tests --gtest_filter='WeakSpots.*'

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "dovetail/collision/collision_world.h"
#include "dovetail/collision/containment.h"
#include "dovetail/collision/convex.h"
#include "dovetail/collision/model.h"
#include "dovetail/collision/primitives.h"

namespace dovetail::collision {
namespace {

std::shared_ptr<const Mesh> share(Mesh m) { return std::make_shared<const Mesh>(std::move(m)); }

Mesh transformed(Mesh m, const Mat3& A, const Vec3& t = Vec3::Zero()) {
  for (Vec3& v : m.vertices) v = A * v + t;
  return m;
}

Transform pose(const Mat3& R, const Vec3& t) {
  Transform X;
  X.R = R;
  X.t = t;
  return X;
}

Mat3 turn(Real angle, const Vec3& axis) {
  return Eigen::AngleAxis<Real>(angle, axis.normalized()).toRotationMatrix();
}

constexpr Method kMethods[] = {Method::kBoxtree, Method::kDop6, Method::kDop14, Method::kDop18,
                               Method::kDop26,   Method::kAabb, Method::kObb};

/// Every method's verdict on one query against brute force's; the work of
/// each is printed as one line `label: method volume_tests triangle_tests ...`.
/// Returns brute force's verdict.
bool expect_exact(const std::shared_ptr<const Mesh>& a, const std::shared_ptr<const Mesh>& b,
                  const Transform& X_AB, const std::string& label) {
  const bool truth =
      build_model(Method::kBrute, a)->collide(*build_model(Method::kBrute, b), X_AB).colliding;
  std::string line = label + (truth ? " [intersecting]" : " [separate]") + ":";
  for (const Method m : kMethods) {
    const CollideResult r = build_model(m, a)->collide(*build_model(m, b), X_AB);
    EXPECT_EQ(r.colliding, truth) << label << ": " << method_name(m);
    char cell[96];
    std::snprintf(cell, sizeof cell, " %s %llu/%llu", std::string(method_name(m)).c_str(),
                  static_cast<unsigned long long>(r.stats.volume_tests),
                  static_cast<unsigned long long>(r.stats.triangle_tests));
    line += cell;
  }
  std::printf("%s\n", line.c_str());
  return truth;
}

/// A flat plate of 2 n^2 triangles in z = 0 over [-1, 1]^2, closed by a
/// thin slab below it (thickness 0.01), so it is a solid.
Mesh plate(int n) {
  std::vector<Vec3> v;
  std::vector<TriangleIndices> t;
  const auto at = [&](int i, int j, int layer) {
    return static_cast<std::uint32_t>(layer * (n + 1) * (n + 1) + i * (n + 1) + j);
  };
  for (int layer = 0; layer < 2; ++layer) {
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; j <= n; ++j) {
        v.emplace_back(-1 + 2.0 * i / n, -1 + 2.0 * j / n, layer == 0 ? 0.0 : -0.01);
      }
    }
  }
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      t.push_back({at(i, j, 0), at(i + 1, j, 0), at(i + 1, j + 1, 0)});
      t.push_back({at(i, j, 0), at(i + 1, j + 1, 0), at(i, j + 1, 0)});
      t.push_back({at(i, j, 1), at(i + 1, j + 1, 1), at(i + 1, j, 1)});
      t.push_back({at(i, j, 1), at(i, j + 1, 1), at(i + 1, j + 1, 1)});
    }
  }
  // The rim.
  for (int k = 0; k < n; ++k) {
    const std::uint32_t rim[4][2] = {{at(k, 0, 0), at(k + 1, 0, 0)},
                                     {at(n, k, 0), at(n, k + 1, 0)},
                                     {at(k + 1, n, 0), at(k, n, 0)},
                                     {at(0, k + 1, 0), at(0, k, 0)}};
    for (const auto& e : rim) {
      const std::uint32_t e0 = e[0], e1 = e[1];
      const std::uint32_t f0 = e0 + (n + 1) * (n + 1), f1 = e1 + (n + 1) * (n + 1);
      t.push_back({e0, f0, f1});
      t.push_back({e0, f1, e1});
    }
  }
  return make_mesh(std::move(v), std::move(t), "plate");
}

// Parallel close proximity: two finely tessellated plates face to face. Box-like
// volumes of flat clusters all overlap within the gap, so the traversal goes
// down to the leaves over the whole face: exact verdicts, at a cost that
// grows as the gap closes.
TEST(WeakSpots, ParallelCloseProximityIsExactAtEveryGap) {
  // The whole scene turned by a general rotation, so that no volume's axes
  // line up with the plates.
  const Mat3 Q = turn(0.7, Vec3(1, 2, 3));
  const auto a = share(transformed(plate(24), Q));
  const auto b = share(plate(24));
  const Mat3 flip = turn(std::numbers::pi, Vec3::UnitX());  // B's face down onto A's
  for (const Real gap : {1e-2, 1e-4, 1e-6, 1e-9, 0.0, -1e-9}) {
    const Transform X = pose(Q * flip * turn(0.3, Vec3::UnitZ()), Q * Vec3(0.1, 0.05, gap));
    char label[64];
    std::snprintf(label, sizeof label, "parallel plates, gap %g", gap);
    const bool colliding = expect_exact(a, b, X, label);
    EXPECT_EQ(colliding, gap <= 0) << gap;
  }
}

// Coplanar and nearly coplanar contact: faces on each other in a frame where
// rounding decides, and tilted by angles down to 1e-12.
TEST(WeakSpots, CoplanarAndNearlyCoplanarContactIsExact) {
  const auto a = share(make_box(Vec3(1, 1, 0.5)));
  const auto b = share(make_box(Vec3(0.4, 0.4, 0.4)));
  const Mat3 Q = turn(0.7, Vec3(1, 2, 3));
  const auto qa = share(transformed(*a, Q));
  for (const Real tilt : {0.0, 1e-12, 1e-9, 1e-6}) {
    // B's bottom face on A's top, turned about an axis in the face by `tilt`
    // (about B's bottom edge, so the face lifts off A's top on one side).
    const Mat3 R = turn(tilt, Vec3::UnitY());
    const Vec3 edge(-0.4, 0, -0.4);
    const Vec3 t = Vec3(0.2, 0.1, 0.9) - R * edge + edge;
    char label[64];
    std::snprintf(label, sizeof label, "coplanar, tilt %g", tilt);
    expect_exact(a, b, pose(R, t), label);
    std::snprintf(label, sizeof label, "coplanar turned, tilt %g", tilt);
    expect_exact(qa, b, pose(Q * R, Q * t), label);
  }
}

// Thin and sliver parts: a plate 1e-6 thick and a needle of slivers through
// a box face, and crossing just past its edge.
TEST(WeakSpots, ThinAndSliverPartsAreExact) {
  const auto box = share(make_box(Vec3(0.5, 0.5, 0.5)));
  const auto foil = share(transformed(make_box(Vec3(1, 1, 1)), Vec3(0.3, 0.3, 5e-7).asDiagonal()));
  const auto needle = share(transformed(make_cylinder(1, 1, 6), Vec3(1e-6, 1e-6, 2).asDiagonal()));
  for (const Real offset : {0.0, 0.4999999, 0.5 - 1e-12, 0.5, 0.5 + 1e-12, 0.5000001, 0.85, 1.2}) {
    char label[64];
    std::snprintf(label, sizeof label, "foil at x %.13g", offset);
    expect_exact(box, foil, pose(turn(0.4, Vec3(1, 1, 0)), Vec3(offset, 0, 0)), label);
    std::snprintf(label, sizeof label, "needle at x, y %.13g", offset);
    expect_exact(box, needle, pose(turn(0.2, Vec3(0, 1, 0)), Vec3(offset, offset, 0)), label);
  }
}

// A small part fully inside a large one: no surfaces meet, so every polygon-
// level method says "separate" (documented); the containment query is the
// tool for it and says "inside".
TEST(WeakSpots, FullContainmentIsMissedBySurfacesAndFoundByContainment) {
  const auto outer = share(make_sphere(1.0, 3));
  const auto inner = share(make_box(Vec3(0.1, 0.2, 0.1)));
  const Transform X = pose(turn(0.5, Vec3(1, 0, 1)), Vec3(0.2, -0.1, 0.3));
  EXPECT_FALSE(expect_exact(outer, inner, X, "box inside sphere"));
  const PointLocator locator(*outer);
  for (const Vec3& v : inner->vertices) {
    EXPECT_EQ(locator.locate(X.apply(v)), PointLocation::kInside);
  }
}

// Very fast rotation between frames: a thin bar turning half a turn per frame
// passes through a post between two poses that are both free. Dovetail tests
// poses, not sweeps (documented): the pass is missed at frame rate and caught
// once the turn per check is below the bar's angular width at the post.
TEST(WeakSpots, TunnellingThroughAFastRotationIsMissedBetweenPoses) {
  const auto post = share(make_cylinder(0.02, 1, 16));
  const auto bar = share(transformed(make_box(Vec3(1, 0.01, 0.01)), Mat3::Identity()));
  // The post stands on the x axis at x = 0.5; the bar turns about z through it.
  const Transform X_post = pose(turn(std::numbers::pi / 2, Vec3::UnitX()), Vec3(0.5, 0, 0));
  const auto posed_post = share(transformed(*post, X_post.R, X_post.t));
  const auto at = [&](Real angle) {
    return build_model(Method::kObb, posed_post)
        ->collide(*build_model(Method::kObb, bar), pose(turn(angle, Vec3::UnitZ()), Vec3::Zero()))
        .colliding;
  };
  const Real before = -std::numbers::pi / 2, after = std::numbers::pi / 2;
  EXPECT_FALSE(at(before));
  EXPECT_FALSE(at(after));  // the two frames see nothing...
  EXPECT_TRUE(at(0));       // ...though the bar lay across the post between them
  // Bounded: checking every `step` radians catches it when the step is below
  // the angle the bar and post overlap over, (0.02 + 0.01) / 0.5 on each side.
  const Real overlap = 2 * (0.02 + 0.01) / 0.5;
  int checks = 0;
  bool caught = false;
  for (Real angle = before; angle <= after && !caught; angle += 0.9 * overlap) {
    ++checks;
    caught = at(angle);
  }
  EXPECT_TRUE(caught) << checks;
}

// The separating-plane search at touching contact: hulls that touch (face,
// edge or vertex on a face, in turned frames, where rounding decides whether
// they meet) are reported separated only when brute force finds the meshes
// apart too: the search gives up and leaves the pair to the polygon level.
// Slightly apart it may give up as well (within 1e-3 of the size): that costs
// time, never a verdict.
TEST(WeakSpots, SeparatingPlaneNeverSeparatesTouchingHulls) {
  const Mesh cube = make_box(Vec3(0.5, 0.5, 0.5));
  const auto b_mesh = share(cube);
  const ConvexHull b_hull = compute_convex_hull(cube.vertices, "cube");
  const auto brute_b = build_model(Method::kBrute, b_mesh);
  int touching = 0, touching_met = 0, touching_separated = 0;
  int gave_up_near = 0, gave_up_far = 0, apart = 0;  // apart: 1e-9 and 1e-2
  for (int k = 0; k < 60; ++k) {
    // A is the cube turned by Q; B sits on A's top, the scene turned by Q.
    const Mat3 Q = turn(0.1 * k, Vec3(1, 0.3 * k, 2));
    const auto a_mesh = share(transformed(cube, Q));
    const ConvexHull a_hull = compute_convex_hull(a_mesh->vertices, "turned cube");
    const auto brute_a = build_model(Method::kBrute, a_mesh);
    // Face on face, edge on face, vertex on face: B's lowest point on A's top.
    for (const Mat3& R : {Mat3(Mat3::Identity()), turn(std::numbers::pi / 4, Vec3::UnitX()),
                          turn(0.9553166181245093, Vec3(1, -1, 0))}) {
      Real lowest = 0;
      for (const Vec3& v : cube.vertices) lowest = std::min(lowest, (R * v).z());
      for (const Real gap : {0.0, 1e-9, 1e-2}) {
        const Transform X_AB = pose(Q * R, Q * Vec3(0.1, 0.2, 0.5 - lowest + gap));
        SeparatingPlaneCache cache;
        const SeparatingPlaneResult r = separating_plane_test(a_hull, b_hull, X_AB, cache);
        const bool met = brute_a->collide(*brute_b, X_AB).colliding;
        if (r.separated) {
          EXPECT_FALSE(met) << "k " << k << " gap " << gap;
        }
        if (gap == 0) {
          ++touching;
          touching_met += met;
          touching_separated += r.separated;
        } else {
          ++apart;
          EXPECT_FALSE(met);
          (gap < 1e-3 ? gave_up_near : gave_up_far) += r.separated ? 0 : 1;
        }
      }
    }
  }
  std::printf(
      "separating plane: %d touching (%d meeting after rounding), %d separated; apart, gave up %d "
      "of %d at 1e-9 and %d of %d at 1e-2\n",
      touching, touching_met, touching_separated, gave_up_near, apart / 2, gave_up_far, apart / 2);
  EXPECT_EQ(touching, 180);
  EXPECT_GT(touching_met, 0);
}

// Extreme scales and parts far from the origin: the same touching, crossing
// and apart configurations at sizes 1e-3 to 1e3 and 1e6 sizes away from the
// origin keep their exact verdicts.
TEST(WeakSpots, ExtremeScalesAndFarFromTheOriginAreExact) {
  const Mesh sphere = make_sphere(0.5, 2);
  const Mesh torus = make_torus(0.6, 0.2, 16, 8);
  for (const Real scale : {1e-3, 1.0, 1e3}) {
    for (const Real far : {0.0, 1e6}) {
      const Vec3 offset = Vec3(1, -2, 3).normalized() * far * scale;
      const auto a = share(transformed(sphere, Mat3::Identity() * scale, offset));
      const auto b = share(transformed(torus, Mat3::Identity() * scale));
      for (const Real x : {0.0, 0.3, 0.9, 1.5}) {
        const Transform X = pose(turn(0.6, Vec3(0, 1, 1)), offset + Vec3(x, 0.1, 0) * scale);
        char label[96];
        std::snprintf(label, sizeof label, "scale %g, %g sizes out, x %g", scale, far, x);
        expect_exact(a, b, X, label);
      }
    }
  }
}

}  // namespace
}  // namespace dovetail::collision
