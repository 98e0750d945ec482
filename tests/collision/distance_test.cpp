// Distance and tolerance queries: the triangle-triangle distance against
// known cases and sampling, the RSS bound against sampling, and the
// hierarchy against brute force on contact-distance poses at several scales.

#include "dovetail/collision/distance.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "dovetail/collision/model.h"
#include "dovetail/collision/pose_sampling.h"
#include "dovetail/collision/primitives.h"
#include "dovetail/collision/tri_tri.h"
#include "proximity/rss_tree.h"
#include "proximity/tri_distance.h"

namespace dovetail::collision {
namespace {

using detail::TriangleVertices;

std::shared_ptr<const Mesh> share(Mesh m) { return std::make_shared<const Mesh>(std::move(m)); }

Mesh transformed(const Mesh& m, const Transform& X) {
  std::vector<Vec3> v;
  for (const Vec3& p : m.vertices) v.push_back(X.apply(p));
  return make_mesh(v, m.triangles, m.source + " (moved)");
}

Mesh scaled(const Mesh& m, Real s) {
  Transform X;
  X.R = Mat3::Identity() * s;
  return transformed(m, X);
}

/// Distance from p to the plane of t and how far outside t its projection is
/// (0 when p lies on the closed triangle).
Real off_triangle(const Vec3& p, const TriangleVertices& t) {
  return (p - detail::closest_point_on_triangle(p, t)).norm();
}

/// Longest edge squared over twice the area: about the aspect ratio.
Real condition(const TriangleVertices& t) {
  Real longest = 0;
  for (int k = 0; k < 3; ++k) longest = std::max(longest, (t[(k + 1) % 3] - t[k]).squaredNorm());
  return longest / (t[1] - t[0]).cross(t[2] - t[0]).norm();
}

/// An upper bound on the distance of two triangles converging from above:
/// points sampled on each, against the exact closest point on the other.
Real sampled_distance(const TriangleVertices& a, const TriangleVertices& b, int n) {
  Real best = std::numeric_limits<Real>::infinity();
  for (int side = 0; side < 2; ++side) {
    const TriangleVertices& x = side == 0 ? a : b;
    const TriangleVertices& y = side == 0 ? b : a;
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; i + j <= n; ++j) {
        const Real u = Real(i) / n, v = Real(j) / n;
        const Vec3 p = x[0] + (x[1] - x[0]) * u + (x[2] - x[0]) * v;
        best = std::min(best, (p - detail::closest_point_on_triangle(p, y)).norm());
      }
    }
  }
  return best;
}

Vec3 random_vec(std::mt19937_64& rng, Real extent) {
  std::uniform_real_distribution<Real> u(-extent, extent);
  return Vec3(u(rng), u(rng), u(rng));
}

// ----------------------------------------------------------- triangle level

TEST(DistanceTriangles, ParallelFacesAreTheirOffset) {
  const TriangleVertices a{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  for (const Real h : {1.0, 1e-3, 1e-9, -0.25}) {
    // Same shape above, and a rotated one whose projection overlaps a's.
    const TriangleVertices b{Vec3(0, 0, h), Vec3(1, 0, h), Vec3(0, 1, h)};
    const TriangleVertices c{Vec3(0.2, 0.2, h), Vec3(-0.5, 0.1, h), Vec3(0.1, -0.5, h)};
    for (const TriangleVertices& t : {b, c}) {
      const detail::TriangleDistance d = detail::triangle_distance(a, t);
      EXPECT_DOUBLE_EQ(d.distance, std::abs(h));
      EXPECT_NEAR((d.p - d.q).norm(), std::abs(h), 1e-15);
      EXPECT_LT(off_triangle(d.p, a), 1e-15);
      EXPECT_LT(off_triangle(d.q, t), 1e-15);
    }
  }
}

TEST(DistanceTriangles, KnownEdgeEdgeAndVertexFace) {
  // Skew edges: a's edge along x at z = 0, b's edge along y at z = 2.
  const TriangleVertices a{Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, -1)};
  const TriangleVertices b{Vec3(0, -1, 2), Vec3(0, 1, 2), Vec3(0, 0, 3)};
  detail::TriangleDistance d = detail::triangle_distance(a, b);
  EXPECT_DOUBLE_EQ(d.distance, 2.0);
  EXPECT_NEAR((d.p - Vec3(0, 0, 0)).norm(), 0, 1e-15);
  EXPECT_NEAR((d.q - Vec3(0, 0, 2)).norm(), 0, 1e-15);
  // Vertex above the interior of a face.
  const TriangleVertices f{Vec3(0, 0, 0), Vec3(4, 0, 0), Vec3(0, 4, 0)};
  const TriangleVertices v{Vec3(1, 1, 0.5), Vec3(1, 2, 3), Vec3(2, 1, 3)};
  d = detail::triangle_distance(f, v);
  EXPECT_DOUBLE_EQ(d.distance, 0.5);
  EXPECT_NEAR((d.p - Vec3(1, 1, 0)).norm(), 0, 1e-15);
  // The same with the roles swapped.
  d = detail::triangle_distance(v, f);
  EXPECT_DOUBLE_EQ(d.distance, 0.5);
  EXPECT_NEAR((d.q - Vec3(1, 1, 0)).norm(), 0, 1e-15);
  // Parallel edges (collinear, offset along the line): endpoint to endpoint.
  const TriangleVertices e1{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, -1, 0)};
  const TriangleVertices e2{Vec3(3, 0, 0), Vec3(2, 0, 0), Vec3(2.5, 1, 0)};
  EXPECT_DOUBLE_EQ(detail::triangle_distance(e1, e2).distance, 1.0);
  // Parallel edges side by side, overlapping along the line.
  const TriangleVertices e3{Vec3(0.25, 0.5, 0), Vec3(2, 0.5, 0), Vec3(1, 1.5, 0)};
  EXPECT_DOUBLE_EQ(detail::triangle_distance(e1, e3).distance, 0.5);
}

TEST(DistanceTriangles, IntersectingIsZeroWithAWitness) {
  // b pierces a's interior: no feature pair is at distance 0.
  const TriangleVertices a{Vec3(-1, -1, 0), Vec3(2, -1, 0), Vec3(-1, 2, 0)};
  const TriangleVertices b{Vec3(0.1, 0.2, -1), Vec3(0.3, 0.1, 1), Vec3(0.2, 0.4, 1)};
  const detail::TriangleDistance d = detail::triangle_distance(a, b);
  EXPECT_EQ(d.distance, 0);
  EXPECT_EQ(d.p, d.q);
  EXPECT_LT(off_triangle(d.p, a), 1e-15);
  EXPECT_LT(off_triangle(d.p, b), 1e-15);
  // Touching at a vertex counts, as in collide.
  const TriangleVertices t{Vec3(0, 0, 0), Vec3(0, 0, 1), Vec3(0, 1, 1)};
  EXPECT_EQ(detail::triangle_distance(a, t).distance, 0);
  // Coplanar and overlapping.
  const TriangleVertices c{Vec3(0, 0, 0), Vec3(3, 0.5, 0), Vec3(0.5, 3, 0)};
  const detail::TriangleDistance dc = detail::triangle_distance(a, c);
  EXPECT_EQ(dc.distance, 0);
  EXPECT_LT(off_triangle(dc.p, a), 1e-15);
  EXPECT_LT(off_triangle(dc.p, c), 1e-15);
}

TEST(DistanceTriangles, RandomPairsAgainstSamplingAndTheExactTest) {
  std::mt19937_64 rng(7);
  int intersecting = 0;
  for (int trial = 0; trial < 600; ++trial) {
    // Every third pair a sliver (one vertex near the opposite edge's midpoint).
    TriangleVertices a{random_vec(rng, 1), random_vec(rng, 1), random_vec(rng, 1)};
    TriangleVertices b{random_vec(rng, 1), random_vec(rng, 1), random_vec(rng, 1)};
    b[0] += Vec3(0.8, 0, 0);
    if (trial % 3 == 0) a[2] = (a[0] + a[1]) * 0.5 + random_vec(rng, 1e-7);
    if (trial % 5 == 0) b[2] = (b[0] + b[1]) * 0.5 + random_vec(rng, 1e-9);
    const detail::TriangleDistance d = detail::triangle_distance(a, b);
    const bool hit = triangles_intersect(a[0], a[1], a[2], b[0], b[1], b[2]);
    ASSERT_EQ(d.distance == 0, hit) << trial;
    intersecting += hit;
    // The points lie on their triangles and realise the distance. Slivers
    // lose accuracy in their normal: allow for their condition (edge^2 / 2 area).
    EXPECT_LT(off_triangle(d.p, a), 1e-12 + 1e-14 * condition(a)) << trial;
    EXPECT_LT(off_triangle(d.q, b), 1e-12 + 1e-14 * condition(b)) << trial;
    if (!hit) {
      EXPECT_NEAR((d.p - d.q).norm(), d.distance, 1e-12) << trial;
      // Nothing sampled is closer.
      EXPECT_LE(d.distance, sampled_distance(a, b, 24) + 1e-12) << trial;
    }
  }
  EXPECT_GT(intersecting, 20);
}

TEST(DistanceTriangles, SegmentsParallelAndDegenerate) {
  Vec3 x, y;
  // Parallel, overlapping projections: distance is the offset.
  EXPECT_DOUBLE_EQ(detail::segment_distance_squared(Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(1, 1, 0),
                                                    Vec3(3, 1, 0), x, y),
                   1.0);
  // Anti-parallel, disjoint along the line.
  EXPECT_DOUBLE_EQ(detail::segment_distance_squared(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(4, 0, 0),
                                                    Vec3(3, 0, 0), x, y),
                   4.0);
  // A point against a segment, and two points.
  EXPECT_DOUBLE_EQ(detail::segment_distance_squared(Vec3(0.5, 2, 0), Vec3(0.5, 2, 0), Vec3(0, 0, 0),
                                                    Vec3(1, 0, 0), x, y),
                   4.0);
  EXPECT_DOUBLE_EQ(detail::segment_distance_squared(Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(0, 3, 4),
                                                    Vec3(0, 3, 4), x, y),
                   25.0);
  // Nearly parallel: never above the endpoint distances.
  const Real d2 = detail::segment_distance_squared(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0),
                                                   Vec3(1, 1 + 1e-13, 0), x, y);
  EXPECT_NEAR(d2, 1.0, 1e-12);
}

TEST(DistanceTriangles, NearlyParallelCrossingEdges) {
  // Edges crossing at a small angle, one a small height above the other: the
  // distance is that height, found where they cross, not at an endpoint
  // (which is about angle x length away). A regression test: the lines'
  // closest points must come from a form that stays accurate at small angles.
  const TriangleVertices a{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 0, -1)};
  const TriangleVertices b{Vec3(0.2, -1.5e-8, 1e-9), Vec3(0.8, 1.5e-8, 1e-9), Vec3(0.5, 0.5, 1)};
  const detail::TriangleDistance d = detail::triangle_distance(a, b);
  EXPECT_NEAR(d.distance, 1e-9, 1e-18);
  EXPECT_NEAR(d.p.x(), 0.5, 1e-7);
  // Skew segments over a range of small angles and heights, distance known.
  for (const Real angle : {1e-4, 1e-6, 1e-7, 3e-8, 1e-8, 1e-10}) {
    for (const Real height : {1e-3, 1e-6, 1e-9, 1e-12}) {
      const Vec3 half(0.3 * std::cos(angle), 0.3 * std::sin(angle), 0);
      const Vec3 centre(0.45, 0, height);
      Vec3 x, y;
      const Real d2 = detail::segment_distance_squared(Vec3(0, 0, 0), Vec3(1, 0, 0), centre - half,
                                                       centre + half, x, y);
      EXPECT_NEAR(std::sqrt(d2), height, 1e-15 + 1e-9 * height)
          << "angle " << angle << " height " << height;
      EXPECT_NEAR((x - y).norm(), std::sqrt(d2), 1e-15);
    }
  }
}

// ------------------------------------------------------------- the RSS bound

TEST(DistanceRss, LowerBoundNeverExceedsSampledDistance) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<Real> unit(0, 1);
  double ratio_sum = 0;
  int ratio_count = 0;
  for (int trial = 0; trial < 400; ++trial) {
    detail::Rss r[2];
    for (auto& x : r) {
      const Mat3 R = rotation_from_quaternion(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5,
                                              unit(rng) - 0.5);
      x.centre = random_vec(rng, 2);
      x.u = R.col(0);
      x.v = R.col(1);
      x.hu = unit(rng);
      x.hv = trial % 4 == 0 ? 0 : unit(rng);
      x.radius = 0.1 * unit(rng);
    }
    if (trial % 7 == 0) r[1].u = r[0].u, r[1].v = r[0].v;  // parallel rectangles
    // Upper bound on the rectangles' distance by sampling both.
    constexpr int n = 20;
    Real sampled = std::numeric_limits<Real>::infinity();
    std::vector<Vec3> points[2];
    for (int k = 0; k < 2; ++k) {
      for (int i = 0; i <= n; ++i) {
        for (int j = 0; j <= n; ++j) {
          points[k].push_back(r[k].centre + r[k].u * (r[k].hu * (2.0 * i / n - 1)) +
                              r[k].v * (r[k].hv * (2.0 * j / n - 1)));
        }
      }
    }
    for (const Vec3& p : points[0]) {
      for (const Vec3& q : points[1]) sampled = std::min(sampled, (p - q).norm());
    }
    const Real bound = detail::rss_lower_bound(r[0], r[1]) + r[0].radius + r[1].radius;
    EXPECT_LE(bound, sampled + 1e-12) << trial;
    if (sampled > 0.05) {
      ratio_sum += bound / sampled;
      ++ratio_count;
    }
  }
  const double tightness = ratio_sum / ratio_count;
  std::printf("[ rss bound ] mean bound / sampled distance: %.3f over %d pairs\n", tightness,
              ratio_count);
  EXPECT_GT(tightness, 0.9);
}

/// Slots under node n of the tree.
void collect_slots(const detail::RssTree& tree, std::uint32_t n, std::vector<std::uint32_t>& out) {
  const detail::NodeLink link = tree.nodes()[n].link;
  if (link.is_leaf()) {
    for (int i = 0; i < link.count(); ++i) out.push_back(tree.order()[link.first_slot() + i]);
    return;
  }
  collect_slots(tree, link.first_child(), out);
  collect_slots(tree, link.first_child() + 1, out);
}

TEST(DistanceRss, EveryNodeEnclosesItsTriangles) {
  for (int leaf : {1, 3}) {
    for (const Mesh& mesh :
         {make_torus(0.7, 0.25, 24, 12), scaled(make_sphere(1, 2), 1e3),
          transformed(make_box(Vec3(1, 2, 3)), {Mat3::Identity(), Vec3(500, -200, 7)})}) {
      const detail::RssTree tree(mesh, leaf);
      for (std::uint32_t n = 0; n < tree.nodes().size(); ++n) {
        const detail::Rss r = tree.rss(n);
        std::vector<std::uint32_t> slots;
        collect_slots(tree, n, slots);
        for (std::uint32_t t : slots) {
          for (std::uint32_t v : mesh.triangles[t]) {
            const Vec3 d = mesh.vertices[v] - r.centre;
            const Real x = std::clamp(d.dot(r.u), -r.hu, r.hu);
            const Real y = std::clamp(d.dot(r.v), -r.hv, r.hv);
            ASSERT_LE((d - r.u * x - r.v * y).norm(), r.radius) << mesh.source << " node " << n;
          }
        }
      }
    }
  }
}

// ------------------------------------------------------------- mesh level

struct Scene {
  std::string name;
  std::shared_ptr<const Mesh> a, b;
};

std::vector<Scene> scenes() {
  std::vector<Scene> out;
  out.push_back({"sphere/torus", share(make_sphere(0.6, 2)), share(make_torus(0.7, 0.25, 24, 12))});
  out.push_back(
      {"box/box", share(make_box(Vec3(0.5, 0.3, 0.2))), share(make_box(Vec3(0.4, 0.4, 0.1)))});
  out.push_back(
      {"torus/cylinder", share(make_torus(0.5, 0.2, 20, 10)), share(make_cylinder(0.1, 0.8, 32))});
  for (const Real s : {1e-3, 1e3}) {
    out.push_back({"sphere/torus x" + std::to_string(s), share(scaled(make_sphere(0.6, 2), s)),
                   share(scaled(make_torus(0.7, 0.25, 24, 12), s))});
  }
  return out;
}

std::vector<SampledPose> poses_for(const Scene& scene, int directions, std::uint64_t seed) {
  const auto ma = build_model(Method::kObb, scene.a);
  const auto mb = build_model(Method::kObb, scene.b);
  ContactPoseSettings settings;
  settings.directions = directions;
  settings.seed = seed;
  settings.gaps = {-0.02, -0.001, 0.0, 0.0005, 0.005, 0.02, 0.1, 0.3};
  return contact_distance_poses(*ma, *mb, settings);
}

TEST(DistanceMeshes, EqualsBruteForceAndZeroExactlyWhenColliding) {
  int total = 0, colliding = 0, mismatches = 0;
  std::uint64_t tree_pairs = 0, brute_pairs = 0;
  for (const Scene& scene : scenes()) {
    const auto da = build_distance_model(scene.a);
    const auto db = build_distance_model(scene.b);
    const auto da3 = build_distance_model(scene.a, {.max_leaf_size = 3});
    const auto db3 = build_distance_model(scene.b, {.max_leaf_size = 3});
    const auto ca = build_model(Method::kBrute, scene.a);
    const auto cb = build_model(Method::kBrute, scene.b);
    for (const SampledPose& pose : poses_for(scene, 12, 11)) {
      const DistanceResult brute = distance_brute(*scene.a, *scene.b, pose.X_AB);
      const DistanceResult tree = distance(*da, *db, pose.X_AB);
      const DistanceResult tree3 = distance(*da3, *db3, pose.X_AB);
      const bool hit = ca->collide(*cb, pose.X_AB).colliding;
      ++total;
      colliding += hit;
      tree_pairs += tree.stats.triangle_tests;
      brute_pairs += brute.stats.triangle_tests;
      // The same triangle pairs give the same bits: equal, not merely close.
      const bool ok = tree.distance == brute.distance && tree3.distance == brute.distance &&
                      (tree.distance == 0) == hit && (brute.distance == 0) == hit;
      if (!ok && ++mismatches <= 5) {
        ADD_FAILURE() << scene.name << " gap " << pose.gap << ": tree " << tree.distance
                      << " leaf3 " << tree3.distance << " brute " << brute.distance << " colliding "
                      << hit;
      }
      // The witness: points on the reported triangles, as far apart as reported.
      const Mesh& a = *scene.a;
      const Mesh& b = *scene.b;
      const TriangleIndices& ta = a.triangles[tree.triangle_a];
      const TriangleIndices& tb = b.triangles[tree.triangle_b];
      const TriangleVertices va{a.vertices[ta[0]], a.vertices[ta[1]], a.vertices[ta[2]]};
      const TriangleVertices vb{pose.X_AB.apply(b.vertices[tb[0]]),
                                pose.X_AB.apply(b.vertices[tb[1]]),
                                pose.X_AB.apply(b.vertices[tb[2]])};
      const Real size = a.vertices[0].norm() + 1;
      EXPECT_LT(off_triangle(tree.p_A, va), 1e-12 * size) << scene.name;
      EXPECT_LT(off_triangle(tree.q_A, vb), 1e-12 * size) << scene.name;
      EXPECT_NEAR((tree.p_A - tree.q_A).norm(), tree.distance, 1e-12 * size) << scene.name;
    }
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_GT(colliding, 0);
  EXPECT_LT(colliding, total);
  std::printf(
      "[ distance ] %d poses (%d colliding), 0 allowed mismatches, found %d; triangle pairs per "
      "query: tree %.1f, brute %.1f\n",
      total, colliding, mismatches, double(tree_pairs) / total, double(brute_pairs) / total);
}

TEST(DistanceMeshes, ToleranceVerdictEqualsBruteDistance) {
  int total = 0, within = 0, mismatches = 0;
  for (const Scene& scene : scenes()) {
    const auto da = build_distance_model(scene.a);
    const auto db = build_distance_model(scene.b);
    const Bounds bounds = mesh_bounds(*scene.a);
    const Real size = (bounds.max - bounds.min).norm();
    for (const SampledPose& pose : poses_for(scene, 8, 5)) {
      const Real d = distance_brute(*scene.a, *scene.b, pose.X_AB).distance;
      for (const Real eps : {0.0, 0.5 * d, d, 1.5 * d, 0.003 * size, 0.05 * size}) {
        const ToleranceResult t = within_tolerance(*da, *db, pose.X_AB, eps);
        const bool expected = d <= eps;
        ++total;
        within += t.within;
        // Exact ties (eps == d) are decided the same way too.
        if (t.within != expected && ++mismatches <= 5) {
          ADD_FAILURE() << scene.name << " gap " << pose.gap << " eps " << eps << " distance " << d
                        << " within " << t.within;
        }
        if (t.within) {
          EXPECT_LE(t.distance, eps);
          EXPECT_NEAR((t.p_A - t.q_A).norm(), t.distance, 1e-12 * size);
        }
        if (total % 7 == 0) {
          EXPECT_EQ(within_tolerance_brute(*scene.a, *scene.b, pose.X_AB, eps).within, expected)
              << scene.name;
        }
      }
    }
  }
  EXPECT_EQ(mismatches, 0);
  std::printf("[ tolerance ] %d queries (%d within), %d mismatches\n", total, within, mismatches);
}

TEST(DistanceMeshes, RequestedErrorBoundsTheResult) {
  const Scene scene = scenes()[0];
  const auto da = build_distance_model(scene.a);
  const auto db = build_distance_model(scene.b);
  for (const SampledPose& pose : poses_for(scene, 6, 9)) {
    const Real exact = distance(*da, *db, pose.X_AB).distance;
    const DistanceResult approx =
        distance(*da, *db, pose.X_AB, {.relative_error = 0.1, .absolute_error = 1e-3});
    EXPECT_GE(approx.distance, exact);
    EXPECT_LE(approx.distance, exact * 1.1 + 1e-3 + 1e-15);
  }
}

TEST(DistanceMeshes, ModelsAreSharedAcrossThreads) {
  const Scene scene = scenes()[0];
  const auto da = build_distance_model(scene.a);
  const auto db = build_distance_model(scene.b);
  const std::vector<SampledPose> poses = poses_for(scene, 6, 2);
  std::vector<Real> serial, parallel(poses.size());
  for (const SampledPose& p : poses) serial.push_back(distance(*da, *db, p.X_AB).distance);
  std::vector<std::thread> threads;
  for (int t = 0; t < 3; ++t) {
    threads.emplace_back([&, t] {
      for (std::size_t i = t; i < poses.size(); i += 3)
        parallel[i] = distance(*da, *db, poses[i].X_AB).distance;
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(serial, parallel);
}

TEST(DistanceMeshes, InfoAndArguments) {
  const auto mesh = share(make_sphere(1, 2));
  const auto model = build_distance_model(mesh);
  const ModelInfo info = model->info();
  EXPECT_EQ(info.leaves, mesh->triangle_count());
  EXPECT_EQ(info.nodes, 2 * mesh->triangle_count() - 1);
  EXPECT_GT(info.bytes_per_triangle, 64);
  EXPECT_THROW(build_distance_model(nullptr), std::invalid_argument);
  EXPECT_THROW(build_distance_model(mesh, {.max_leaf_size = 8}), std::invalid_argument);
  // A mesh against itself at the identity: every triangle touches itself.
  EXPECT_EQ(distance(*model, *model, Transform::identity()).distance, 0);
  // Negative or NaN tolerances and allowed errors are refused, not guessed at.
  {
    const auto box = std::make_shared<const Mesh>(make_box(Vec3(1, 1, 1)));
    const auto m = build_distance_model(box);
    const Transform X;
    for (const Real bad : {-1.0, std::nan("")}) {
      EXPECT_THROW(within_tolerance(*m, *m, X, bad), std::invalid_argument);
      EXPECT_THROW(within_tolerance_brute(*box, *box, X, bad), std::invalid_argument);
      EXPECT_THROW(distance(*m, *m, X, {.relative_error = bad}), std::invalid_argument);
      EXPECT_THROW(distance(*m, *m, X, {.absolute_error = bad}), std::invalid_argument);
    }
  }
}

}  // namespace
}  // namespace dovetail::collision
