#include "dovetail/collision/tri_tri.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "../support/random_geometry.h"
#include "dovetail/collision/predicates.h"

namespace dovetail::collision {
namespace {

struct Tri {
  Vec3 a, b, c;
  const Vec3& operator[](int i) const { return i == 0 ? a : (i == 1 ? b : c); }
};

struct Case {
  std::string name;
  Tri t1;
  Tri t2;
  bool expected;
  bool margin;  ///< the verdict survives perturbations of the coordinates (inexact transforms)
};

constexpr Real kUlp1 = 0x1p-52;  // one ulp of 1.0

const Tri kBase{Vec3(0, 0, 0), Vec3(4, 0, 0), Vec3(0, 4, 0)};

std::vector<Case> designed_cases() {
  const Real g = 0x1p-50;
  return {
      {"separated_parallel", kBase, {Vec3(0, 0, 1), Vec3(4, 0, 1), Vec3(0, 4, 1)}, false, true},
      {"separated_crossing_plane",
       kBase,
       {Vec3(5, 5, -1), Vec3(6, 5, 1), Vec3(5, 6, 1)},
       false,
       true},
      {"crossing_edge", kBase, {Vec3(1, 1, -2), Vec3(1, 1, 2), Vec3(-3, 1, 0)}, true, true},
      {"piercing_interior", kBase, {Vec3(1, 1, -1), Vec3(1.5, 1, 1), Vec3(1, 1.5, 1)}, true, true},
      {"vertex_touching_face", kBase, {Vec3(1, 1, 0), Vec3(2, 1, 3), Vec3(1, 2, 3)}, true, false},
      {"vertex_above_face_by_ulp",
       kBase,
       {Vec3(1, 1, kUlp1), Vec3(2, 1, 3), Vec3(1, 2, 3)},
       false,
       false},
      {"vertex_below_face_by_ulp",
       kBase,
       {Vec3(1, 1, -kUlp1), Vec3(2, 1, 3), Vec3(1, 2, 3)},
       true,
       false},
      {"vertex_touching_edge", kBase, {Vec3(2, 0, 0), Vec3(2, -1, 3), Vec3(3, -1, 3)}, true, false},
      {"vertex_touching_vertex",
       kBase,
       {Vec3(4, 0, 0), Vec3(5, 1, 1), Vec3(5, -1, 1)},
       true,
       false},
      {"edge_touching_edge", kBase, {Vec3(2, -2, -2), Vec3(2, 2, 2), Vec3(2, -2, 2)}, true, false},
      {"edge_missing_edge_by_gap",
       kBase,
       {Vec3(2, -2 - g, -2), Vec3(2, 2 - g, 2), Vec3(2, -2 - g, 2)},
       false,
       false},
      {"edge_on_face", kBase, {Vec3(1, 1, 0), Vec3(2, 1, 0), Vec3(1, 1, 2)}, true, false},
      {"shared_edge_folded", kBase, {Vec3(0, 0, 0), Vec3(4, 0, 0), Vec3(1, 0, 3)}, true, false},
      {"shared_edge_coplanar_neighbours",
       kBase,
       {Vec3(4, 0, 0), Vec3(0, 4, 0), Vec3(4, 4, 0)},
       true,
       false},
      {"shared_vertex", kBase, {Vec3(0, 0, 0), Vec3(-1, -2, 1), Vec3(-2, -1, 3)}, true, false},
      {"shared_vertex_coplanar",
       kBase,
       {Vec3(0, 0, 0), Vec3(-4, 0, 0), Vec3(0, -4, 0)},
       true,
       false},
      {"coplanar_overlapping", kBase, {Vec3(1, 1, 0), Vec3(5, 1, 0), Vec3(1, 5, 0)}, true, false},
      {"coplanar_vertex_on_edge",
       kBase,
       {Vec3(2, 2, 0), Vec3(5, 3, 0), Vec3(3, 5, 0)},
       true,
       false},
      {"coplanar_gap_of_one_ulp",
       kBase,
       {Vec3(2 + 2 * kUlp1, 2, 0), Vec3(5, 3, 0), Vec3(3, 5, 0)},
       false,
       false},
      {"coplanar_disjoint", kBase, {Vec3(3, 3, 0), Vec3(5, 3, 0), Vec3(3, 5, 0)}, false, true},
      {"coplanar_contained", kBase, {Vec3(1, 1, 0), Vec3(2, 1, 0), Vec3(1, 2, 0)}, true, false},
      {"coplanar_containing",
       kBase,
       {Vec3(-1, -1, 0), Vec3(10, -1, 0), Vec3(-1, 10, 0)},
       true,
       false},
      {"coplanar_identical", kBase, kBase, true, false},
      {"coplanar_star",
       {Vec3(0, 0, 0), Vec3(6, 0, 0), Vec3(3, 6, 0)},
       {Vec3(0, 4, 0), Vec3(6, 4, 0), Vec3(3, -2, 0)},
       true,
       false},
      {"coplanar_collinear_edges_overlapping",
       kBase,
       {Vec3(2, 0, 0), Vec3(6, 0, 0), Vec3(4, -2, 0)},
       true,
       false},
      {"coplanar_collinear_edges_disjoint",
       kBase,
       {Vec3(5, 0, 0), Vec3(7, 0, 0), Vec3(6, -2, 0)},
       false,
       false},
      {"near_coplanar_lifted",
       kBase,
       {Vec3(1, 1, 0x1p-40), Vec3(5, 1, 0x1p-40), Vec3(1, 5, 0x1p-40)},
       false,
       false},
      {"near_coplanar_tilted_crossing",
       kBase,
       {Vec3(1, 1, -0x1p-40), Vec3(5, 1, 0x1p-40), Vec3(1, 5, 0x1p-40)},
       true,
       false},
      {"sliver_pierced",
       {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 0x1p-40, 0)},
       {Vec3(0.5, 0x1p-42, -1), Vec3(0.5, 0x1p-42, 1), Vec3(5, 3, 0)},
       true,
       false},
      {"sliver_missed",
       {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 0x1p-40, 0)},
       {Vec3(0.5, 0x1p-39, -1), Vec3(0.5, 0x1p-39, 1), Vec3(0.5, 5, 0)},
       false,
       false},
      {"sliver_grazing_apex",
       {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 0x1p-40, 0)},
       {Vec3(0.5, 0x1p-40, -1), Vec3(0.5, 0x1p-40, 1), Vec3(0.5, 5, 0)},
       true,
       false},
      {"tiny_far_from_origin_touching",
       {Vec3(1, 1, 1), Vec3(1 + 0x1p-30, 1, 1), Vec3(1, 1 + 0x1p-30, 1)},
       {Vec3(1 + 0x1p-32, 1 + 0x1p-32, 1), Vec3(1, 1, 1 + 0x1p-30),
        Vec3(1 + 0x1p-31, 1, 1 + 0x1p-30)},
       true,
       false},
      {"tiny_far_from_origin_gap",
       {Vec3(1, 1, 1), Vec3(1 + 0x1p-30, 1, 1), Vec3(1, 1 + 0x1p-30, 1)},
       {Vec3(1 + 0x1p-32, 1 + 0x1p-32, 1 + kUlp1), Vec3(1, 1, 1 + 0x1p-30),
        Vec3(1 + 0x1p-31, 1, 1 + 0x1p-30)},
       false,
       false},
  };
}

/// Verdict for every vertex order (6 x 6) and both argument orders; all 72
/// must agree, and the common verdict is returned.
bool verdict_in_all_orders(const Tri& t1, const Tri& t2, const std::string& label) {
  std::array<int, 3> order1 = {0, 1, 2};
  const bool reference = triangles_intersect(t1.a, t1.b, t1.c, t2.a, t2.b, t2.c);
  do {
    std::array<int, 3> order2 = {0, 1, 2};
    do {
      const Vec3& p1 = t1[order1[0]];
      const Vec3& q1 = t1[order1[1]];
      const Vec3& r1 = t1[order1[2]];
      const Vec3& p2 = t2[order2[0]];
      const Vec3& q2 = t2[order2[1]];
      const Vec3& r2 = t2[order2[2]];
      EXPECT_EQ(triangles_intersect(p1, q1, r1, p2, q2, r2), reference)
          << label << " orders " << order1[0] << order1[1] << order1[2] << " / " << order2[0]
          << order2[1] << order2[2];
      EXPECT_EQ(triangles_intersect(p2, q2, r2, p1, q1, r1), reference) << label << " swapped";
    } while (std::next_permutation(order2.begin(), order2.end()));
  } while (std::next_permutation(order1.begin(), order1.end()));
  return reference;
}

/// x + t when the sum is exact, else nothing (two-sum error term is zero).
bool exact_sum(Real x, Real t, Real& out) {
  const Real s = x + t;
  const Real t_virtual = s - x;
  const Real x_virtual = s - t_virtual;
  const Real error = (x - x_virtual) + (t - t_virtual);
  out = s;
  return error == 0;
}

/// An exact affine map: signed axis permutation, power-of-two scale, translation.
struct ExactMap {
  std::array<int, 3> axes = {0, 1, 2};
  std::array<Real, 3> signs = {1, 1, 1};
  int scale_exponent = 0;
  Vec3 translation = Vec3::Zero();

  /// Maps p, returning false when the translation would round.
  bool apply(const Vec3& p, Vec3& out) const {
    for (int k = 0; k < 3; ++k) {
      const Real v = signs[k] * std::ldexp(p[axes[k]], scale_exponent);
      if (!exact_sum(v, translation[k], out[k])) return false;
    }
    return true;
  }
  bool apply(const Tri& t, Tri& out) const {
    return apply(t.a, out.a) && apply(t.b, out.b) && apply(t.c, out.c);
  }
};

using test::Random;

TEST(TrianglesIntersect, DesignedCasesInEveryVertexOrder) {
  for (const Case& c : designed_cases()) {
    ASSERT_FALSE(is_degenerate_triangle(c.t1.a, c.t1.b, c.t1.c)) << c.name;
    ASSERT_FALSE(is_degenerate_triangle(c.t2.a, c.t2.b, c.t2.c)) << c.name;
    EXPECT_EQ(verdict_in_all_orders(c.t1, c.t2, c.name), c.expected) << c.name;
  }
}

TEST(TrianglesIntersect, ExactTransformsKeepEveryVerdict) {
  int mapped = 0;
  int translations_skipped = 0;
  for (const Case& c : designed_cases()) {
    std::array<int, 3> axes = {0, 1, 2};
    do {
      for (int flips = 0; flips < 8; ++flips) {
        for (int e = -10; e <= 10; e += 5) {
          for (const Vec3& shift : {Vec3(0, 0, 0), Vec3(3, -7, 11), Vec3(-1024, 4096, 1)}) {
            ExactMap map;
            map.axes = axes;
            for (int k = 0; k < 3; ++k) map.signs[k] = (flips >> k) & 1 ? -1.0 : 1.0;
            map.scale_exponent = e;
            map.translation = shift;
            Tri t1, t2;
            if (!map.apply(c.t1, t1) || !map.apply(c.t2, t2)) {
              ++translations_skipped;
              continue;
            }
            ++mapped;
            ASSERT_EQ(triangles_intersect(t1.a, t1.b, t1.c, t2.a, t2.b, t2.c), c.expected)
                << c.name << " scale 2^" << e << " shift " << shift.transpose() << " flips "
                << flips;
            ASSERT_EQ(triangles_intersect(t2.c, t2.a, t2.b, t1.b, t1.a, t1.c), c.expected)
                << c.name << " reordered";
          }
        }
      }
    } while (std::next_permutation(axes.begin(), axes.end()));
  }
  // Most cases must be exercised with translations too, not only scalings.
  EXPECT_GT(mapped, 20 * 6 * 8 * 5 * 2);
  RecordProperty("mapped", mapped);
  RecordProperty("translations_skipped", translations_skipped);
}

TEST(TrianglesIntersect, PowerOfTwoScalingsFromTwoToMinusTenToTen) {
  for (const Case& c : designed_cases()) {
    for (int e = -10; e <= 10; ++e) {
      const Real s = std::ldexp(1.0, e);
      EXPECT_EQ(triangles_intersect(s * c.t1.a, s * c.t1.b, s * c.t1.c, s * c.t2.a, s * c.t2.b,
                                    s * c.t2.c),
                c.expected)
          << c.name << " 2^" << e;
    }
  }
}

TEST(TrianglesIntersect, RigidMotionsAndScalingsKeepMarginVerdicts) {
  Random random(21);
  int checked = 0;
  for (const Case& c : designed_cases()) {
    if (!c.margin) continue;
    for (int i = 0; i < 500; ++i) {
      Transform X;
      X.R = random.rotation();
      X.t = Vec3(random.uniform(-100, 100), random.uniform(-100, 100), random.uniform(-100, 100));
      const Real scale = std::pow(10.0, random.uniform(-3, 3));
      const auto map = [&](const Vec3& p) { return X.apply(scale * p); };
      const Tri t1{map(c.t1.a), map(c.t1.b), map(c.t1.c)};
      const Tri t2{map(c.t2.a), map(c.t2.b), map(c.t2.c)};
      ASSERT_EQ(verdict_in_all_orders(t1, t2, c.name), c.expected) << c.name << " motion " << i;
      ++checked;
    }
  }
  EXPECT_GE(checked, 5 * 500);
}

TEST(TrianglesIntersect, SmallGapsAreSeenAtEveryScale) {
  // A vertex approaching a face along its normal: touching at gap 0, apart
  // at a gap of one ulp of the coordinates, crossing at minus one ulp.
  for (int e = -300; e <= 90; e += 13) {
    const Real s = std::ldexp(1.0, e);
    const Tri face{Vec3(0, 0, 0) * s, Vec3(4, 0, 0) * s, Vec3(0, 4, 0) * s};
    const Real z = 3 * s;
    for (const Real gap : {Real(0), kUlp1 * s, -kUlp1 * s}) {
      const Tri probe{Vec3(1 * s, 1 * s, gap), Vec3(2 * s, 1 * s, z), Vec3(1 * s, 2 * s, z)};
      EXPECT_EQ(verdict_in_all_orders(face, probe, "gap"), gap <= 0) << "2^" << e << " " << gap;
    }
  }
}

// Independent reference for coplanar pairs: closed segment intersection with
// collinear overlap plus vertex containment, in exact integer arithmetic.
struct IPoint {
  std::int64_t x, y;
};

std::int64_t cross(const IPoint& a, const IPoint& b, const IPoint& c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

bool on_segment(const IPoint& a, const IPoint& b, const IPoint& p) {
  return cross(a, b, p) == 0 && std::min(a.x, b.x) <= p.x && p.x <= std::max(a.x, b.x) &&
         std::min(a.y, b.y) <= p.y && p.y <= std::max(a.y, b.y);
}

bool segments_meet(const IPoint& a, const IPoint& b, const IPoint& c, const IPoint& d) {
  const std::int64_t d1 = cross(c, d, a), d2 = cross(c, d, b);
  const std::int64_t d3 = cross(a, b, c), d4 = cross(a, b, d);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) {
    return true;
  }
  return on_segment(c, d, a) || on_segment(c, d, b) || on_segment(a, b, c) || on_segment(a, b, d);
}

bool contains(const std::array<IPoint, 3>& t, const IPoint& p) {
  const std::int64_t s0 = cross(t[0], t[1], p), s1 = cross(t[1], t[2], p),
                     s2 = cross(t[2], t[0], p);
  return (s0 >= 0 && s1 >= 0 && s2 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0);
}

bool reference_coplanar(const std::array<IPoint, 3>& t1, const std::array<IPoint, 3>& t2) {
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (segments_meet(t1[i], t1[(i + 1) % 3], t2[j], t2[(j + 1) % 3])) return true;
    }
  }
  return contains(t1, t2[0]) || contains(t2, t1[0]);
}

TEST(TrianglesIntersect, AllCoplanarPairsOnSmallGridsMatchReference) {
  // Every non-degenerate triangle on an n x n grid, embedded in the plane z = 0
  // and, by an exact integer map, in a tilted plane.
  const auto embed_flat = [](const IPoint& p) { return Vec3(Real(p.x), Real(p.y), 0); };
  const auto embed_tilted = [](const IPoint& p) {
    return Vec3(Real(p.x + 2 * p.y), Real(3 * p.x - p.y), Real(p.x + p.y + 5));
  };
  for (const int n : {3, 4}) {
    std::vector<std::array<IPoint, 3>> triangles;
    std::vector<IPoint> points;
    for (int x = 0; x < n; ++x) {
      for (int y = 0; y < n; ++y) points.push_back({x, y});
    }
    for (std::size_t i = 0; i < points.size(); ++i) {
      for (std::size_t j = i + 1; j < points.size(); ++j) {
        for (std::size_t k = j + 1; k < points.size(); ++k) {
          if (cross(points[i], points[j], points[k]) != 0) {
            triangles.push_back({points[i], points[j], points[k]});
          }
        }
      }
    }
    int intersecting = 0;
    int pairs = 0;
    for (const auto& t1 : triangles) {
      for (const auto& t2 : triangles) {
        const bool expected = reference_coplanar(t1, t2);
        intersecting += expected;
        ++pairs;
        for (const auto& embed : {+embed_flat, +embed_tilted}) {
          const Tri a{embed(t1[0]), embed(t1[1]), embed(t1[2])};
          const Tri b{embed(t2[0]), embed(t2[1]), embed(t2[2])};
          if (n == 3) {
            ASSERT_EQ(verdict_in_all_orders(a, b, "grid"), expected);
          } else {
            ASSERT_EQ(triangles_intersect(a.a, a.b, a.c, b.a, b.b, b.c), expected);
          }
        }
      }
    }
    // Both verdicts occur often: the comparison is not vacuous.
    EXPECT_GT(intersecting, pairs / 50);
    EXPECT_GT(pairs - intersecting, pairs / 50);
  }
}

// A triangle rounded flat (a far pose can do that to a mesh's triangle) is
// the segment or point it spans: exact verdicts against a proper triangle,
// in every vertex order and either argument order. Before, a flat triangle
// high above the base was "coplanar" with it and met its shadow.
TEST(TrianglesIntersect, AFlatTriangleIsTheSegmentItSpans) {
  const struct {
    const char* name;
    Tri flat;
    bool expected;
  } cases[] = {
      {"segment above the base", {Vec3(1, 1, 5), Vec3(2, 1, 5), Vec3(3, 1, 5)}, false},
      {"far segment above the base", {Vec3(1, 1, 1e16), Vec3(1, 1, 1e16), Vec3(2, 1, 1e16)}, false},
      {"segment through the base", {Vec3(1, 1, -1), Vec3(1, 1, 1), Vec3(1, 1, 3)}, true},
      {"segment through the plane outside", {Vec3(5, 5, -1), Vec3(5, 5, 2), Vec3(5, 5, 1)}, false},
      {"segment ending on the base", {Vec3(1, 1, 0), Vec3(1, 1, 1), Vec3(1, 1, 2)}, true},
      {"segment ending on an edge", {Vec3(2, 0, 0), Vec3(2, -1, 1), Vec3(2, -2, 2)}, true},
      {"segment ending beside the base", {Vec3(2, -0.5, 0), Vec3(2, -1, 1), Vec3(2, -2, 3)}, false},
      {"slanted segment through an edge", {Vec3(2, -1, -1), Vec3(2, 1, 1), Vec3(2, 0, 0)}, true},
      {"point inside the base", {Vec3(1, 1, 0), Vec3(1, 1, 0), Vec3(1, 1, 0)}, true},
      {"point in the plane outside", {Vec3(3, 3, 0), Vec3(3, 3, 0), Vec3(3, 3, 0)}, false},
      {"segment in the plane across", {Vec3(-1, 1, 0), Vec3(1, 1, 0), Vec3(3, 1, 0)}, true},
      {"segment in the plane outside", {Vec3(3, 3, 0), Vec3(4, 4, 0), Vec3(5, 5, 0)}, false},
  };
  for (const auto& c : cases) {
    ASSERT_TRUE(is_degenerate_triangle(c.flat.a, c.flat.b, c.flat.c)) << c.name;
    EXPECT_EQ(verdict_in_all_orders(kBase, c.flat, c.name), c.expected) << c.name;
  }
}

TEST(TrianglesIntersect, DegenerateInputDoesNotCrash) {
  const std::vector<Tri> degenerate = {
      {Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(0, 0, 0)},
      {Vec3(1, 1, 0), Vec3(1, 1, 0), Vec3(2, 2, 0)},
      {Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(2, 2, 2)},
      {Vec3(-1, 1, 0), Vec3(3, 1, 0), Vec3(1, 1, 0)},
      {Vec3(1, 1, -1), Vec3(1, 1, 1), Vec3(1, 1, 0)},
  };
  std::vector<Tri> others = degenerate;
  others.push_back(kBase);
  others.push_back({Vec3(1, 1, -1), Vec3(2, 1, 1), Vec3(1, 2, 1)});
  for (const Tri& d : degenerate) {
    for (const Tri& o : others) {
      // The verdict is unspecified, but it is defined and repeatable.
      const bool first = triangles_intersect(d.a, d.b, d.c, o.a, o.b, o.c);
      EXPECT_EQ(triangles_intersect(d.a, d.b, d.c, o.a, o.b, o.c), first);
      (void)triangles_intersect(o.c, o.b, o.a, d.b, d.c, d.a);
    }
  }
}

}  // namespace
}  // namespace dovetail::collision
