// Every hierarchy must report exactly what the exhaustive reference reports:
// the same yes/no verdict and the same set of intersecting triangle pairs.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "dovetail/collision/model.h"
#include "dovetail/collision/pose_sampling.h"
#include "dovetail/collision/primitives.h"
#include "dovetail/collision/task_system.h"
#include "dovetail/collision/tri_tri.h"

namespace dovetail::collision {
namespace {

std::shared_ptr<const Mesh> share(Mesh m) { return std::make_shared<const Mesh>(std::move(m)); }

/// Mesh with a transform applied to every vertex.
Mesh transformed(const Mesh& m, const Transform& X) {
  std::vector<Vec3> v;
  for (const Vec3& p : m.vertices) v.push_back(X.apply(p));
  return make_mesh(v, m.triangles, m.source + " (moved)");
}

struct Agreement {
  int poses = 0;
  int colliding = 0;
  int disagreements = 0;
};

/// Runs every method on every pose and compares with brute force: verdicts of
/// first-hit queries, and the full sorted pair lists of all-pairs queries.
/// Reports the first few disagreements in full.
Agreement expect_agreement(const std::shared_ptr<const Mesh>& a,
                           const std::shared_ptr<const Mesh>& b,
                           const std::vector<Transform>& poses, const std::string& scene) {
  std::vector<std::shared_ptr<const CollisionModel>> models_a, models_b;
  for (Method m : all_methods()) {
    models_a.push_back(build_model(m, a));
    models_b.push_back(build_model(m, b));
  }
  const std::size_t brute = models_a.size() - 1;
  Agreement agreement;
  auto disagree = [&](std::size_t p, std::size_t m, const std::string& what) {
    if (++agreement.disagreements <= 5) {
      ADD_FAILURE() << scene << " pose " << p << " method " << method_name(models_a[m]->method())
                    << ": " << what << "\nR=\n"
                    << poses[p].R << "\nt=" << poses[p].t.transpose();
    }
  };
  for (std::size_t p = 0; p < poses.size(); ++p) {
    const CollideResult reference =
        models_a[brute]->collide(*models_b[brute], poses[p], {.all_pairs = true});
    agreement.colliding += reference.colliding ? 1 : 0;
    ++agreement.poses;
    for (std::size_t m = 0; m + 1 < models_a.size(); ++m) {
      const CollideResult first = models_a[m]->collide(*models_b[m], poses[p]);
      if (first.colliding != reference.colliding) {
        disagree(p, m, "first-hit verdict differs from brute");
      } else if (first.colliding && (first.pairs.size() != 1 ||
                                     !std::binary_search(reference.pairs.begin(),
                                                         reference.pairs.end(), first.pairs[0]))) {
        disagree(p, m, "first-hit pair is not an intersecting pair");
      }
      const CollideResult all = models_a[m]->collide(*models_b[m], poses[p], {.all_pairs = true});
      if (all.pairs != reference.pairs) {
        disagree(p, m,
                 "all-pairs list differs: " + std::to_string(all.pairs.size()) + " vs brute " +
                     std::to_string(reference.pairs.size()));
      }
    }
  }
  EXPECT_EQ(agreement.disagreements, 0) << scene;
  std::printf("[ agreement ] %s: %d poses (%d colliding) x %zu methods, %d disagreements\n",
              scene.c_str(), agreement.poses, agreement.colliding, models_a.size() - 1,
              agreement.disagreements);
  return agreement;
}

std::vector<Transform> contact_poses(const std::shared_ptr<const Mesh>& a,
                                     const std::shared_ptr<const Mesh>& b, int directions,
                                     std::uint64_t seed) {
  const auto ma = build_model(Method::kBoxtree, a);
  const auto mb = build_model(Method::kBoxtree, b);
  std::vector<Transform> out;
  ContactPoseSettings settings;
  settings.directions = directions;
  settings.seed = seed;
  // Besides the standard gaps, poses at the bisected contact distance itself.
  settings.gaps.push_back(0.0);
  for (const SampledPose& s : contact_distance_poses(*ma, *mb, settings)) out.push_back(s.X_AB);
  return out;
}

TEST(Hierarchies, SphereAgainstTorusRandomAndContactPoses) {
  const auto a = share(make_sphere(0.6, 2));
  const auto b = share(make_torus(0.7, 0.25, 24, 12));
  std::vector<Transform> poses = random_poses(2500, 1.2, 11);
  const std::vector<Transform> contact = contact_poses(a, b, 120, 12);
  poses.insert(poses.end(), contact.begin(), contact.end());
  const Agreement r = expect_agreement(a, b, poses, "sphere/torus");
  EXPECT_GE(r.poses, 3400);
  // The pose set must exercise both verdicts.
  EXPECT_GT(r.colliding, r.poses / 5);
  EXPECT_LT(r.colliding, r.poses * 4 / 5);
}

TEST(Hierarchies, ParallelCloseProximityWavySheets) {
  // Two copies of a wavy sheet, the second lifted by tiny amounts and slightly
  // turned: many parallel, nearly touching faces.
  const auto a = share(make_wavy_sheet(1.0, 0.1, 4.0, 22));
  const auto b = a;
  std::vector<Transform> poses;
  const std::vector<Transform> jitter = random_poses(1500, 1.0, 21);
  for (std::size_t i = 0; i < jitter.size(); ++i) {
    Transform X;
    const Real angle = 1e-3 * (static_cast<Real>(i % 7) - 3.0);
    X.R = rotation_from_quaternion(std::cos(angle / 2), 0, 0, std::sin(angle / 2));
    const Real dz = std::ldexp(1.0, -static_cast<int>(i % 40)) * ((i % 2) ? 1 : -1) * 0.05;
    X.t = Vec3(0.01 * jitter[i].t.x(), 0.01 * jitter[i].t.y(), dz);
    poses.push_back(X);
  }
  poses.push_back(Transform::identity());  // coincident: every face touches its twin
  const Agreement r = expect_agreement(a, b, poses, "wavy sheets");
  EXPECT_GT(r.colliding, 0);
  EXPECT_LT(r.colliding, r.poses);
}

TEST(Hierarchies, BoxesTouchingFacesEdgesAndVertices) {
  // Unit boxes placed exactly face to face, edge to edge, vertex to vertex,
  // and a hair apart, under the 24 axis-aligned rotations (exact in floating point).
  const auto a = share(make_box(Vec3(0.5, 0.5, 0.5)));
  const auto b = share(make_box(Vec3(0.5, 0.5, 0.5)));
  std::vector<Mat3> rotations;
  for (int perm = 0; perm < 6; ++perm) {
    const int order[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    for (int signs = 0; signs < 8; ++signs) {
      Mat3 R = Mat3::Zero();
      for (int r = 0; r < 3; ++r) R(r, order[perm][r]) = (signs >> r & 1) ? -1 : 1;
      if (R.determinant() > 0) rotations.push_back(R);
    }
  }
  std::vector<Transform> poses;
  const Real eps = std::ldexp(1.0, -30);
  for (const Mat3& R : rotations) {
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          for (Real extra : {0.0, eps, -eps, 0.25}) {
            Transform X;
            X.R = R;
            X.t = Vec3(dx, dy, dz) * (1.0 + extra);
            X.t.x() += dy == 0 ? 0.5 : 0.0;  // half-offset faces: partial overlap of coplanar faces
            poses.push_back(X);
          }
        }
      }
    }
  }
  const Agreement r = expect_agreement(a, b, poses, "boxes");
  EXPECT_GT(r.colliding, 0);
  EXPECT_LT(r.colliding, r.poses);
}

TEST(Hierarchies, SliversAndSharedEdges) {
  // A 128-sided thin cylinder (long sliver facets) against itself turned about
  // its axis by exact multiples of its facet angle: facets share edges.
  const auto a = share(make_cylinder(0.05, 3.0, 128));
  std::vector<Transform> poses = random_poses(1500, 0.2, 31);
  for (int k = 0; k < 64; ++k) {
    Transform X;
    X.R = rotation_from_quaternion(1, 0, 0, 0);
    X.t = Vec3(0, 0, 0.5 * (k % 8));
    poses.push_back(X);
    X.t = Vec3(0.1, 0, 0);  // side by side, touching along a line
    poses.push_back(X);
  }
  const Agreement r = expect_agreement(a, a, poses, "slivers");
  EXPECT_GT(r.colliding, 0);
  EXPECT_LT(r.colliding, r.poses);
}

TEST(Hierarchies, ScaledScenesAgree) {
  // The same scene at 1e-3 and 1e3: the conservative margins scale with it.
  for (Real scale : {1e-3, 1e3}) {
    Transform S;
    S.R = Mat3::Identity() * scale;
    const auto a = share(transformed(make_sphere(0.6, 2), S));
    const auto b = share(transformed(make_torus(0.7, 0.25, 16, 8), S));
    std::vector<Transform> poses = random_poses(800, 1.2 * scale, 41);
    const Agreement r = expect_agreement(a, b, poses, "scale " + std::to_string(scale));
    EXPECT_GT(r.colliding, 0);
    EXPECT_LT(r.colliding, r.poses);
  }
}

TEST(Hierarchies, SurfaceOnlyTestsMissFullContainment) {
  // Documented behaviour: a part fully inside another with no surface contact
  // is not reported by the polygon level (containment is a separate query).
  const auto outer = share(make_sphere(1.0, 2));
  const auto inner = share(make_sphere(0.3, 1));
  for (Method m : all_methods()) {
    const auto a = build_model(m, outer);
    const auto b = build_model(m, inner);
    EXPECT_FALSE(a->collide(*b, Transform::identity()).colliding) << method_name(m);
    Transform X;
    X.t = Vec3(0.8, 0, 0);  // now it pokes through the shell
    EXPECT_TRUE(a->collide(*b, X).colliding) << method_name(m);
  }
}

TEST(Hierarchies, ModelsRejectMixedMethods) {
  const auto mesh = share(make_box(Vec3(1, 1, 1)));
  const auto a = build_model(Method::kBoxtree, mesh);
  const auto b = build_model(Method::kDop14, mesh);
  EXPECT_THROW(a->collide(*b, Transform::identity()), std::invalid_argument);
}

TEST(Hierarchies, ModelsRefuseMeshesMakeMeshWouldRefuseNamingTheSource) {
  // A Mesh can be filled by hand, past make_mesh's checks; a NaN vertex
  // used to crash the partition.
  for (const Method m : all_methods()) {
    Mesh nan = make_box(Vec3(1, 1, 1));
    nan.source = "hand-made.mesh";
    nan.vertices[3].y() = std::numeric_limits<Real>::quiet_NaN();
    Mesh inf = make_box(Vec3(1, 1, 1));
    inf.source = "hand-made.mesh";
    inf.vertices[0].x() = std::numeric_limits<Real>::infinity();
    Mesh bad_index = make_box(Vec3(1, 1, 1));
    bad_index.source = "hand-made.mesh";
    bad_index.triangles[5][1] = 99;
    Mesh empty;
    empty.source = "hand-made.mesh";
    for (const Mesh* mesh : {&nan, &inf, &bad_index, &empty}) {
      try {
        build_model(m, share(*mesh));
        ADD_FAILURE() << method_name(m) << " built a model of a bad mesh";
      } catch (const MeshError& e) {
        EXPECT_EQ(std::string(e.what()).rfind("hand-made.mesh: ", 0), 0u) << e.what();
      }
    }
    // What make_mesh would keep or drop is no reason to refuse: an unused
    // vertex, a degenerate triangle, a coordinate beyond the default limit
    // (an importer may raise it).
    Mesh odd = make_box(Vec3(1, 1, 1));
    odd.vertices.push_back(Vec3(5, 5, 5));
    odd.triangles.push_back({0, 0, 1});
    odd.vertices[0].x() = -2e30;
    EXPECT_NO_THROW(build_model(m, share(odd))) << method_name(m);
  }
}

TEST(Hierarchies, InfoReportsShapeAndMemory) {
  const auto mesh = share(make_sphere(1.0, 4));  // 5120 triangles
  for (Method m : all_methods()) {
    const ModelInfo info = build_model(m, mesh)->info();
    EXPECT_GT(info.bytes, 0u) << method_name(m);
    EXPECT_GT(info.bytes_per_triangle, 0.0) << method_name(m);
    if (m != Method::kBrute) {
      EXPECT_GT(info.nodes, info.leaves) << method_name(m);
      EXPECT_GE(info.depth, 12u) << method_name(m);  // at least log2(5120 / leaf size)
      EXPECT_LE(info.depth, 64u) << method_name(m);
    }
  }
  // The boxtree is the smallest hierarchy.
  const double boxtree = build_model(Method::kBoxtree, mesh)->info().bytes_per_triangle;
  for (Method m : {Method::kDop6, Method::kDop26, Method::kAabb, Method::kObb}) {
    EXPECT_LT(boxtree, build_model(m, mesh)->info().bytes_per_triangle) << method_name(m);
  }
}

TEST(Hierarchies, RepeatedQueriesAreIdentical) {
  const auto a = share(make_sphere(0.6, 3));
  const auto b = share(make_torus(0.7, 0.25, 32, 16));
  for (Method m : all_methods()) {
    const auto ma = build_model(m, a);
    const auto mb = build_model(m, b);
    for (const Transform& X : random_poses(50, 1.0, 51)) {
      const CollideResult r1 = ma->collide(*mb, X, {.all_pairs = true});
      const CollideResult r2 = ma->collide(*mb, X, {.all_pairs = true});
      EXPECT_EQ(r1.pairs, r2.pairs);
      EXPECT_EQ(r1.stats.volume_tests, r2.stats.volume_tests);
      EXPECT_EQ(r1.stats.triangle_tests, r2.stats.triangle_tests);
    }
  }
}

TEST(Hierarchies, TriangleSearchVisitsEveryTriangleThatMeetsIt) {
  // Triangles of every size thrown at a torus, in the torus's frame: the
  // OBB tree's search must visit every triangle the exact test finds
  // crossing, and pass over most of the rest.
  const auto torus = share(make_torus(0.7, 0.25, 48, 24));
  const auto model = build_model(Method::kObb, torus);
  const auto plain = build_model(Method::kAabb, torus);
  const std::vector<Transform> places = random_poses(600, 1.0, 31);
  std::size_t crossing = 0, visited = 0, searched = 0;
  for (std::size_t i = 0; i < places.size(); ++i) {
    const Real size = std::ldexp(1.0, -static_cast<int>(i % 8));
    const std::array<Vec3, 3> t{places[i].apply(Vec3(0, 0, 0)), places[i].apply(Vec3(size, 0, 0)),
                                places[i].apply(Vec3(0, 0.6 * size, 0.1 * size))};
    std::vector<bool> seen(torus->triangles.size(), false);
    CollideStats stats;
    const bool stopped = model->search_triangle(
        t, 1e-12,
        [&](std::uint32_t k) {
          seen[k] = true;
          ++visited;
          return false;
        },
        stats);
    EXPECT_FALSE(stopped);
    searched += stats.triangle_volume_tests;
    for (std::size_t k = 0; k < torus->triangles.size(); ++k) {
      const TriangleIndices& f = torus->triangles[k];
      if (!triangles_intersect(torus->vertices[f[0]], torus->vertices[f[1]], torus->vertices[f[2]],
                               t[0], t[1], t[2])) {
        continue;
      }
      ++crossing;
      ASSERT_TRUE(seen[k]) << "triangle " << k << " crosses query " << i << " unvisited";
    }
    // The first visit that accepts ends the search.
    int calls = 0;
    if (std::find(seen.begin(), seen.end(), true) != seen.end()) {
      EXPECT_TRUE(model->search_triangle(
          t, 1e-12, [&](std::uint32_t) { return ++calls == 1; }, stats));
      EXPECT_EQ(calls, 1);
    }
    // Hierarchies without the search visit nothing.
    EXPECT_FALSE(plain->search_triangle(
        t, 1e-12, [&](std::uint32_t) { return true; }, stats));
  }
  EXPECT_GT(crossing, 200u);  // the queries do cross the surface
  EXPECT_LT(visited, places.size() * torus->triangles.size() / 20);
  EXPECT_GT(searched, places.size());
}

TEST(Hierarchies, TraversalHintsNeverChangeTheVerdict) {
  // A torus sweeping slowly through a sphere: first-hit queries carrying a
  // TraversalHint from frame to frame must give brute force's verdict at
  // every pose, and the hint must be picked up where hits are found.
  const auto a = share(make_sphere(0.6, 3));
  const auto b = share(make_torus(0.7, 0.25, 32, 16));
  const auto brute_a = build_model(Method::kBrute, a);
  const auto brute_b = build_model(Method::kBrute, b);
  for (Method m : {Method::kAabb, Method::kObb, Method::kDop6, Method::kDop18, Method::kDop26}) {
    const auto ma = build_model(m, a);
    const auto mb = build_model(m, b);
    TraversalHint hint;
    int colliding = 0, hinted_hits = 0;
    std::uint64_t tests_hinted = 0, tests_plain = 0;
    for (int frame = 0; frame < 400; ++frame) {
      const Real s = 0.005 * frame;
      Transform X;
      X.R = Eigen::AngleAxisd(0.7 * s, Vec3(1, 2, 3).normalized()).toRotationMatrix();
      X.t = Vec3(-1.6 + 1.6 * s, 0.3 * std::sin(4 * s), 0.1);
      const bool was_valid = hint.valid;
      const CollideResult hinted = ma->collide(*mb, X, {.hint = &hint});
      const CollideResult plain = ma->collide(*mb, X);
      const bool expected = brute_a->collide(*brute_b, X).colliding;
      ASSERT_EQ(hinted.colliding, expected) << method_name(m) << " frame " << frame;
      ASSERT_EQ(plain.colliding, expected) << method_name(m) << " frame " << frame;
      colliding += expected;
      if (hinted.colliding) {
        ASSERT_TRUE(hint.valid);
        hinted_hits += was_valid;
      }
      tests_hinted += hinted.stats.volume_tests;
      tests_plain += plain.stats.volume_tests;
    }
    EXPECT_GT(colliding, 50) << method_name(m);
    EXPECT_LT(colliding, 350) << method_name(m);
    EXPECT_GT(hinted_hits, 0) << method_name(m);
    // The point of the hint: coherent motion costs fewer volume tests.
    EXPECT_LT(tests_hinted, tests_plain) << method_name(m);
    std::printf("%-6s volume tests with hints %llu, without %llu\n",
                std::string(method_name(m)).c_str(), static_cast<unsigned long long>(tests_hinted),
                static_cast<unsigned long long>(tests_plain));
  }
}

/// One query with a SeparationFront against the same query without: the same
/// verdict and the same pairs. A query with a front keeps the fixed order,
/// so it is compared with the query without in that order; with `hinted`,
/// first hits carry a hint too, with and without the front, and their hints
/// may then differ (the front's is set nearer the leaves), so their first
/// pairs need only both intersect. The query without a front in the
/// default, nearer-first order gives the same verdict and an intersecting
/// pair.
struct FrontCheck {
  std::shared_ptr<const CollisionModel> a, b;
  bool hinted = false;
  SeparationFront front{};
  TraversalHint hint_front{}, hint_plain{};
  std::uint64_t tests_front = 0, tests_plain = 0;
  std::uint64_t tests_fixed_order = 0, tests_nearer_first = 0;  ///< first hits, no front
  int colliding = 0, free = 0;

  void query(const Transform& X, bool all_pairs, const std::string& where) {
    TraversalHint* with_hint = hinted ? &hint_front : nullptr;
    TraversalHint* without_hint = hinted ? &hint_plain : nullptr;
    const CollideResult with =
        a->collide(*b, X, {.all_pairs = all_pairs, .hint = with_hint, .front = &front});
    const CollideResult without =
        a->collide(*b, X, {.all_pairs = all_pairs, .hint = without_hint, .nearer_first = false});
    const CollideResult nearer = a->collide(*b, X, {.all_pairs = all_pairs});
    ASSERT_EQ(with.colliding, without.colliding) << where;
    ASSERT_EQ(nearer.colliding, without.colliding) << where;
    if (!all_pairs && with.colliding) {
      const CollideResult all = a->collide(*b, X, {.all_pairs = true});
      const auto found = [&](const CollideResult& r) {
        return r.pairs.size() == 1 &&
               std::binary_search(all.pairs.begin(), all.pairs.end(), r.pairs.front());
      };
      ASSERT_TRUE(found(with)) << where;
      ASSERT_TRUE(found(without)) << where;
      ASSERT_TRUE(found(nearer)) << where;
    }
    if (!all_pairs) {
      tests_fixed_order += without.stats.volume_tests;
      tests_nearer_first += nearer.stats.volume_tests;
    }
    if (!(hinted && !all_pairs && with.colliding)) {
      ASSERT_EQ(with.pairs, without.pairs) << where;
    }
    if (all_pairs) {
      ASSERT_EQ(nearer.pairs, without.pairs) << where;
    }
    tests_front += with.stats.volume_tests;
    tests_plain += without.stats.volume_tests;
    (with.colliding ? colliding : free) += 1;
    // A query that visited the whole cut leaves a front of these trees behind.
    if (all_pairs || !with.colliding) {
      ASSERT_TRUE(front.valid) << where;
    }
  }
};

TEST(Hierarchies, SeparationFrontsChangeOnlyTheWork) {
  // A peg (0.25 mm clearance) going down a hole in micrometre steps with a
  // wobble that touches the wall now and then, queried as sliding does:
  // first hits and all pairs, from the front of the last complete query.
  const auto block = share(make_block_with_hole(Vec3(0.04, 0.03, 0.04), 0.01025, 0.04, 64));
  const auto peg = share(make_cylinder(0.01, 0.06, 96));
  FrontCheck slide{build_model(Method::kObb, block), build_model(Method::kObb, peg)};
  for (int step = 0; step < 300; ++step) {
    Transform X;  // the peg's axis (z) along the hole's (y), its end going down
    X.R = Eigen::AngleAxisd(-std::numbers::pi / 2, Vec3::UnitX()).toRotationMatrix() *
          Eigen::AngleAxisd(0.0004 * std::sin(0.3 * step), Vec3::UnitY()).toRotationMatrix();
    X.t = Vec3(0.00026 * std::sin(0.11 * step), -2e-5 * step, 2e-6 * std::cos(0.7 * step));
    slide.query(X, step % 5 == 4, "peg step " + std::to_string(step));
  }
  EXPECT_GT(slide.colliding, 20);
  EXPECT_GT(slide.free, 100);
  // The point of the front: small moves cost a fraction of the volume tests.
  EXPECT_LT(2 * slide.tests_front, slide.tests_plain);
  std::printf("peg in hole: volume tests with fronts %llu, without %llu\n",
              static_cast<unsigned long long>(slide.tests_front),
              static_cast<unsigned long long>(slide.tests_plain));

  // Large moves, most entries tested again: still the same answers, then with hints.
  const auto sphere = share(make_sphere(0.6, 3));
  const auto torus = share(make_torus(0.7, 0.25, 32, 16));
  FrontCheck sweep{build_model(Method::kObb, sphere), build_model(Method::kObb, torus)};
  for (int frame = 0; frame < 200; ++frame) {
    sweep.hinted = frame >= 100;
    const Real s = 0.01 * frame;
    Transform X;
    X.R = Eigen::AngleAxisd(0.7 * s, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    X.t = Vec3(-1.6 + 1.6 * s, 0.3 * std::sin(4 * s), 0.1);
    sweep.query(X, frame % 3 == 0, "torus frame " + std::to_string(frame));
  }
  EXPECT_GT(sweep.colliding, 20);
  EXPECT_GT(sweep.free, 20);
  std::printf("first hits without a front: volume tests nearer first %llu, fixed order %llu\n",
              static_cast<unsigned long long>(slide.tests_nearer_first + sweep.tests_nearer_first),
              static_cast<unsigned long long>(slide.tests_fixed_order + sweep.tests_fixed_order));

  // A front of other trees is not read: the answer is the plain one (in
  // the fixed order a front implies). A hit leaves the front as it was; a
  // query that finds none rewrites it.
  const void* block_tree = slide.front.tree_a;
  const CollideResult hit = sweep.a->collide(*sweep.b, Transform{}, {.front = &slide.front});
  EXPECT_TRUE(hit.colliding);
  EXPECT_EQ(hit.pairs, sweep.a->collide(*sweep.b, Transform{}, {.nearer_first = false}).pairs);
  EXPECT_EQ(slide.front.tree_a, block_tree);
  Transform apart;
  apart.t = Vec3(3, 0, 0);
  EXPECT_FALSE(sweep.a->collide(*sweep.b, apart, {.front = &slide.front}).colliding);
  EXPECT_EQ(slide.front.tree_a, sweep.front.tree_a);
  EXPECT_TRUE(slide.front.valid);
}

}  // namespace
}  // namespace dovetail::collision

namespace dovetail::collision {
namespace {

TEST(Hierarchies, ParallelQueriesEqualSerialAtAnyThreadCount) {
  const auto a = share(make_sphere(0.6, 3));
  const auto b = share(make_torus(0.7, 0.25, 48, 24));
  const std::vector<Transform> poses = random_poses(40, 0.8, 71);
  std::vector<std::shared_ptr<const CollisionModel>> models_a, models_b;
  for (Method m : all_methods()) {
    models_a.push_back(build_model(m, a));
    models_b.push_back(build_model(m, b));
  }
  // First hits of the split query with one thread, per method and pose.
  std::vector<CollideResult> first_serial;
  for (int threads : {1, 2, 8}) {
    // One task system at a time: each raises the process's thread limit while it lives.
    const auto tasks = make_task_system(threads);
    for (std::size_t m = 0; m < models_a.size(); ++m) {
      const std::string name(method_name(models_a[m]->method()));
      int colliding = 0;
      for (std::size_t p = 0; p < poses.size(); ++p) {
        const CollideResult reference =
            models_a[m]->collide(*models_b[m], poses[p], {.all_pairs = true});
        colliding += reference.colliding;
        const CollideResult all =
            models_a[m]->collide_parallel(*models_b[m], poses[p], {.all_pairs = true}, *tasks);
        EXPECT_EQ(all.pairs, reference.pairs) << name;
        EXPECT_EQ(all.stats.volume_tests, reference.stats.volume_tests) << name;
        EXPECT_EQ(all.stats.triangle_tests, reference.stats.triangle_tests) << name;
        const CollideResult first =
            models_a[m]->collide_parallel(*models_b[m], poses[p], {}, *tasks);
        EXPECT_EQ(first.colliding, reference.colliding) << name;
        if (threads == 1) {
          first_serial.push_back(first);
        } else {
          const CollideResult& one = first_serial[m * poses.size() + p];
          EXPECT_EQ(first.pairs, one.pairs) << name << " threads " << threads;
          EXPECT_EQ(first.stats.volume_tests, one.stats.volume_tests) << name;
        }
      }
      EXPECT_GT(colliding, 5) << name;
      EXPECT_LT(colliding, 38) << name;
    }
  }
}

}  // namespace
}  // namespace dovetail::collision

namespace dovetail::collision {
namespace {

TEST(Hierarchies, TimeCriticalQueriesAreConservativeAndExactWhenDeepEnough) {
  // Cut at depth d, the AABB, OBB and DOP trees report overlapping volumes as
  // a hit: never a miss; more false hits the shallower the cut; exact again
  // once the cut lies below every leaf pair.
  const auto a = share(make_sphere(0.6, 3));
  const auto b = share(make_torus(0.7, 0.25, 24, 12));
  const std::vector<Transform> poses = random_poses(300, 1.4, 7);
  const auto brute_a = build_model(Method::kBrute, a), brute_b = build_model(Method::kBrute, b);
  std::vector<bool> truth;
  for (const Transform& X : poses) truth.push_back(brute_a->collide(*brute_b, X).colliding);
  for (const Method m : {Method::kAabb, Method::kObb, Method::kDop18}) {
    const auto ma = build_model(m, a), mb = build_model(m, b);
    int previous_false = std::numeric_limits<int>::max();
    for (const int depth : {0, 2, 4, 8, 16, 64}) {
      int false_hits = 0;
      for (std::size_t p = 0; p < poses.size(); ++p) {
        const CollideResult r = ma->collide(*mb, poses[p], {.max_depth = depth});
        if (truth[p]) {
          EXPECT_TRUE(r.colliding) << method_name(m) << " depth " << depth << " pose " << p;
        }
        false_hits += r.colliding && !truth[p];
      }
      EXPECT_LE(false_hits, previous_false) << method_name(m) << " depth " << depth;
      previous_false = false_hits;
      if (depth == 0) {
        EXPECT_GT(false_hits, 0) << method_name(m);
      }
      if (depth == 64) {
        EXPECT_EQ(false_hits, 0) << method_name(m);
      }
    }
  }
}

}  // namespace
}  // namespace dovetail::collision
