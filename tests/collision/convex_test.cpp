// Convex level: hull correctness (exact), the separating-plane test and GJK
// against an exact hull-versus-hull reference on random, touching and
// exactly representable configurations, warm start against cold start.

#include "dovetail/collision/convex.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "convex/convex_internal.h"
#include "dovetail/collision/predicates.h"
#include "dovetail/collision/primitives.h"
#include "dovetail/collision/tri_tri.h"

namespace dovetail::collision {
namespace {

constexpr Real kPi = 3.14159265358979323846;

/// Seeded generator from raw 64-bit draws (the same on every platform).
class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}
  Real unit() { return static_cast<Real>(engine_() >> 11) * 0x1p-53; }
  Real uniform(Real lo, Real hi) { return lo + (hi - lo) * unit(); }
  int integer(int lo, int hi) {
    return lo + static_cast<int>(engine_() % static_cast<std::uint64_t>(hi - lo + 1));
  }
  Real normal() {
    const Real u = 1 - unit(), v = unit();
    return std::sqrt(-2 * std::log(u)) * std::cos(2 * kPi * v);
  }
  Vec3 direction() {
    for (;;) {
      const Vec3 d(normal(), normal(), normal());
      const Real n = d.norm();
      if (n > 1e-6) return d / n;
    }
  }
  Mat3 rotation() {
    Eigen::Quaternion<Real> q(normal(), normal(), normal(), normal());
    q.normalize();
    return q.toRotationMatrix();
  }

 private:
  std::mt19937_64 engine_;
};

// ---------------------------------------------------------------------------
// Point sets

/// Points on an ellipsoid, plus interior points.
std::vector<Vec3> blob(Random& r, int n, const Vec3& axes) {
  std::vector<Vec3> p;
  for (int i = 0; i < n; ++i) p.push_back(r.direction().cwiseProduct(axes));
  for (int i = 0; i < n / 2; ++i) p.push_back(0.5 * r.unit() * r.direction().cwiseProduct(axes));
  return p;
}

/// Box corners plus points lying exactly on its faces (coplanar plateaus).
std::vector<Vec3> box_with_face_points(Random& r, const Vec3& half, int extra) {
  std::vector<Vec3> p;
  for (int i = 0; i < 8; ++i) {
    p.emplace_back(i & 1 ? half.x() : -half.x(), i & 2 ? half.y() : -half.y(),
                   i & 4 ? half.z() : -half.z());
  }
  for (int i = 0; i < extra; ++i) {
    Vec3 q(r.uniform(-1, 1) * half.x(), r.uniform(-1, 1) * half.y(), r.uniform(-1, 1) * half.z());
    const int axis = r.integer(0, 2);
    q[axis] = r.integer(0, 1) ? half[axis] : -half[axis];
    p.push_back(q);
  }
  return p;
}

/// Uniform points in a box (many interior points).
std::vector<Vec3> cloud(Random& r, int n, const Vec3& half) {
  std::vector<Vec3> p;
  for (int i = 0; i < n; ++i) {
    p.emplace_back(r.uniform(-1, 1) * half.x(), r.uniform(-1, 1) * half.y(),
                   r.uniform(-1, 1) * half.z());
  }
  return p;
}

/// Small integer points (exact arithmetic everywhere, many coplanar subsets).
std::vector<Vec3> integer_points(Random& r, int n, int range) {
  std::vector<Vec3> p;
  for (int i = 0; i < n; ++i) {
    p.emplace_back(r.integer(-range, range), r.integer(-range, range), r.integer(-range, range));
  }
  return p;
}

/// A grid on each face of a cube, turned by a rotation: rounded coordinates
/// of coplanar points, where qhull merges nearly coplanar facets.
std::vector<Vec3> rotated_grid_box(Random& r, int n) {
  const Mat3 R = r.rotation();
  std::vector<Vec3> p;
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) {
      const Real u = -1 + 2.0 * i / n, v = -1 + 2.0 * j / n;
      for (int s = -1; s <= 1; s += 2) {
        p.push_back(R * Vec3(u, v, s));
        p.push_back(R * Vec3(u, s, v));
        p.push_back(R * Vec3(s, u, v));
      }
    }
  }
  return p;
}

// ---------------------------------------------------------------------------
// Hull checks

/// Exact checks of a hull against its input points.
void expect_valid_hull(const ConvexHull& h, const std::vector<Vec3>& points,
                       const std::string& what) {
  SCOPED_TRACE(what);
  const std::size_t V = h.vertices.size(), F = h.faces.size();
  ASSERT_GE(V, 4u);
  ASSERT_EQ(h.neighbor_offsets.size(), V + 1);
  // Every hull vertex is an input point.
  std::vector<std::array<Real, 3>> sorted;
  for (const Vec3& p : points) sorted.push_back({p.x(), p.y(), p.z()});
  std::sort(sorted.begin(), sorted.end());
  for (const Vec3& v : h.vertices) {
    ASSERT_TRUE(
        std::binary_search(sorted.begin(), sorted.end(), std::array<Real, 3>{v.x(), v.y(), v.z()}));
  }
  // Every input point inside or on the hull: exact orient3d against every face.
  int outside = 0;
  for (const Vec3& p : points) {
    for (const TriangleIndices& f : h.faces) {
      if (orient3d(h.vertices[f[0]], h.vertices[f[1]], h.vertices[f[2]], p) > 0) {
        ++outside;
        break;
      }
    }
  }
  EXPECT_EQ(outside, 0);
  // Faces: non-degenerate and outward (some vertex strictly below each).
  for (const TriangleIndices& f : h.faces) {
    ASSERT_FALSE(is_degenerate_triangle(h.vertices[f[0]], h.vertices[f[1]], h.vertices[f[2]]));
  }
  // Euler's formula and a closed surface: each edge in two faces.
  const std::size_t E = h.neighbors.size() / 2;
  EXPECT_EQ(h.neighbors.size() % 2, 0u);
  EXPECT_EQ(2 * E, 3 * F);
  EXPECT_EQ(static_cast<long long>(V) - static_cast<long long>(E) + static_cast<long long>(F), 2);
  // Adjacency symmetric, no self loops, no repeats; it matches the face edges.
  for (std::uint32_t i = 0; i < V; ++i) {
    for (std::uint32_t k = h.neighbor_offsets[i]; k < h.neighbor_offsets[i + 1]; ++k) {
      const std::uint32_t j = h.neighbors[k];
      ASSERT_NE(i, j);
      if (k > h.neighbor_offsets[i]) {
        ASSERT_LT(h.neighbors[k - 1], j);
      }
      const auto begin = h.neighbors.begin() + h.neighbor_offsets[j];
      const auto end = h.neighbors.begin() + h.neighbor_offsets[j + 1];
      ASSERT_TRUE(std::find(begin, end, i) != end);
    }
  }
  for (const TriangleIndices& f : h.faces) {
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t i = f[k], j = f[(k + 1) % 3];
      const auto begin = h.neighbors.begin() + h.neighbor_offsets[i];
      const auto end = h.neighbors.begin() + h.neighbor_offsets[i + 1];
      ASSERT_TRUE(std::find(begin, end, j) != end);
    }
  }
  // Bounds.
  for (const Vec3& v : h.vertices) {
    EXPECT_LE(v.cwiseAbs().maxCoeff(), h.extent);
    EXPECT_LE((v - h.center).norm(), h.radius * (1 + 1e-12));
  }
}

/// Support against brute force: value equal to the computed maximum and no
/// vertex exactly better.
void expect_exact_support(const ConvexHull& h, Random& r, int directions) {
  const std::uint32_t V = static_cast<std::uint32_t>(h.vertices.size());
  for (int i = 0; i < directions; ++i) {
    Vec3 d = r.direction() * std::exp(r.uniform(-3, 3));
    if (i % 4 == 0) {  // axis and diagonal directions: plateaus on boxes and grids
      d = Vec3(r.integer(-1, 1), r.integer(-1, 1), r.integer(-1, 1));
      if (d == Vec3::Zero()) d = Vec3::UnitZ();
    }
    const std::uint32_t start = static_cast<std::uint32_t>(r.integer(0, static_cast<int>(V) - 1));
    const std::uint32_t s = h.support(d, start);
    ASSERT_LT(s, V);
    for (std::uint32_t k = 0; k < V; ++k) {
      ASSERT_LE(detail::dot_difference_sign(d, h.vertices[k], h.vertices[s]), 0)
          << "vertex " << k << " beats support " << s;
    }
    Real best = -std::numeric_limits<Real>::infinity();
    for (const Vec3& v : h.vertices) best = std::max(best, detail::dot(d, v));
    const Real got = detail::dot(d, h.vertices[s]);
    EXPECT_LE(best - got, 2 * detail::dot_error_bound(d, h.extent));
    // Deterministic: the same start gives the same vertex.
    ASSERT_EQ(h.support(d, start), s);
  }
}

TEST(ConvexHull, ExactOnManyPointSets) {
  Random r(11);
  int rebuilt = 0, total = 0;
  int kind_total[6] = {}, kind_rebuilt[6] = {};
  for (int i = 0; i < 300; ++i) {
    std::vector<Vec3> p;
    switch (i % 6) {
      case 0:
        p = blob(r, r.integer(4, 200),
                 Vec3(r.uniform(0.2, 2), r.uniform(0.2, 2), r.uniform(0.2, 2)));
        break;
      case 1:
        p = box_with_face_points(r, Vec3(r.uniform(0.1, 2), r.uniform(0.1, 2), r.uniform(0.1, 2)),
                                 r.integer(0, 60));
        break;
      case 2:
        p = cloud(r, r.integer(5, 300), Vec3(1, r.uniform(0.01, 1), r.uniform(0.001, 1)));
        break;
      case 3:
        p = integer_points(r, r.integer(6, 80), r.integer(1, 3));
        break;
      case 4:
        p = rotated_grid_box(r, r.integer(2, 12));
        break;
      default: {  // a far-away, tiny copy: magnitudes apart
        p = blob(r, 40, Vec3(1, 1, 1));
        const Vec3 offset = r.direction() * 1e6;
        for (Vec3& q : p) q = offset + 1e-4 * q;
      }
    }
    ConvexHull h;
    detail::HullBuildStats stats;
    try {
      h = detail::build_convex_hull(p, "set " + std::to_string(i), &stats,
                                    detail::HullPath::kQhull);
    } catch (const std::invalid_argument&) {
      continue;  // a degenerate integer set; covered by the degenerate test
    }
    ++total;
    rebuilt += stats.rebuilt_exactly;
    ++kind_total[i % 6];
    kind_rebuilt[i % 6] += stats.rebuilt_exactly;
    expect_valid_hull(h, p, "set " + std::to_string(i));
    expect_exact_support(h, r, 40);
  }
  std::printf("[ convex  ] hulls %d, rebuilt exactly after qhull's failed the exact check: %d\n",
              total, rebuilt);
  const char* kinds[6] = {"ellipsoid",      "box with face points",   "cloud",
                          "integer points", "rotated grid on a cube", "tiny and far"};
  for (int k = 0; k < 6; ++k) {
    std::printf("[ convex  ]   %-24s %3d hulls, %3d rebuilt\n", kinds[k], kind_total[k],
                kind_rebuilt[k]);
  }
  EXPECT_GT(total, 280);
}

TEST(ConvexHull, DirectPathGivesTheCornersOfQhullsHull) {
  Random r(13);
  int total = 0, fewer = 0;
  for (int i = 0; i < 300; ++i) {
    std::vector<Vec3> p;
    switch (i % 5) {
      case 0:
        p = blob(r, r.integer(4, 64), Vec3(1, r.uniform(0.1, 1), r.uniform(0.01, 1)));
        break;
      case 1:  // coplanar points on the faces and edges of a box
        p = box_with_face_points(r, Vec3(r.uniform(0.1, 2), r.uniform(0.1, 2), r.uniform(0.1, 2)),
                                 r.integer(0, 56));
        break;
      case 2:
        p = integer_points(r, r.integer(6, 64), r.integer(1, 3));
        break;
      case 3:
        p = rotated_grid_box(r, r.integer(2, 4));
        break;
      default:  // the hand's capsules: rings of a cylinder and two caps
        p = collision::make_sphere(r.uniform(0.005, 0.02), r.integer(0, 1)).vertices;
        for (Vec3& q : p) q.z() += q.z() > 0 ? r.uniform(0, 0.05) : 0;
    }
    ConvexHull direct, qhull;
    detail::HullBuildStats stats;
    bool direct_refused = false, qhull_refused = false;
    try {
      direct = detail::build_convex_hull(p, "direct", &stats, detail::HullPath::kDirect);
    } catch (const std::invalid_argument&) {
      direct_refused = true;
    }
    try {
      qhull = detail::build_convex_hull(p, "qhull", nullptr, detail::HullPath::kQhull);
    } catch (const std::invalid_argument&) {
      qhull_refused = true;
    }
    // A degenerate (flat) set is refused by both paths, or by neither.
    ASSERT_EQ(direct_refused, qhull_refused) << "set " << i;
    if (direct_refused) continue;
    ++total;
    SCOPED_TRACE("set " + std::to_string(i));
    EXPECT_TRUE(stats.direct);
    expect_valid_hull(direct, p, "direct " + std::to_string(i));
    expect_exact_support(direct, r, 20);
    // Every vertex of the direct hull is one of qhull's (a corner of the
    // polytope is a vertex of every hull of the points), and the two give
    // the same support value in every direction.
    std::set<std::array<Real, 3>> of_qhull;
    for (const Vec3& v : qhull.vertices) of_qhull.insert({v.x(), v.y(), v.z()});
    for (const Vec3& v : direct.vertices) EXPECT_TRUE(of_qhull.count({v.x(), v.y(), v.z()}));
    fewer += direct.vertices.size() < qhull.vertices.size();
    for (int k = 0; k < 20; ++k) {
      const Vec3 d = r.direction();
      EXPECT_EQ(detail::dot_difference_sign(d, direct.vertices[direct.support(d)],
                                            qhull.vertices[qhull.support(d)]),
                0);
    }
    // No vertex of the direct hull lies inside an edge or a facet: the
    // faces around each lie in three or more planes.
    for (std::uint32_t v = 0; v < direct.vertices.size(); ++v) {
      std::vector<TriangleIndices> planes;
      for (const TriangleIndices& f : direct.faces) {
        if (f[0] != v && f[1] != v && f[2] != v) continue;
        const bool known = std::any_of(planes.begin(), planes.end(), [&](const TriangleIndices& g) {
          for (std::uint32_t k : f) {
            if (orient3d(direct.vertices[g[0]], direct.vertices[g[1]], direct.vertices[g[2]],
                         direct.vertices[k]) != 0)
              return false;
          }
          return true;
        });
        if (!known) planes.push_back(f);
      }
      EXPECT_GE(planes.size(), 3u) << "vertex " << v << " is not a corner";
    }
  }
  std::printf("[ convex  ] direct hulls %d, with fewer vertices than qhull's: %d\n", total, fewer);
  EXPECT_GT(total, 250);
}

TEST(ConvexHull, TheDirectPathJudgesThinnessAtAnyScale) {
  // The same tetrahedra scaled by 1e-90 and 1e90 (the exact predicates
  // hold while products of three coordinates neither underflow nor
  // overflow) and moved far away: a width of 1e-12 of the size is a hull,
  // 1e-16 is flat, at every scale.
  for (const Real scale : {1e-90, 1e-3, 1.0, 1e3, 1e90}) {
    for (const Real offset : {0.0, 1e6}) {
      const auto set = [&](Real thickness) {
        std::vector<Vec3> p = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0),
                               Vec3(0.3, 0.3, thickness)};
        for (Vec3& q : p) q = (q + Vec3::Constant(offset)) * scale;
        return p;
      };
      SCOPED_TRACE("scale " + std::to_string(scale) + " offset " + std::to_string(offset));
      if (offset == 0) {
        EXPECT_NO_THROW(
            detail::build_convex_hull(set(1e-12), "thin", nullptr, detail::HullPath::kDirect));
      }
      EXPECT_THROW(
          detail::build_convex_hull(set(1e-16), "flat", nullptr, detail::HullPath::kDirect),
          std::invalid_argument);
    }
  }
}

TEST(ConvexHull, SmallPointSetsSkipQhull) {
  detail::HullBuildStats stats;
  const collision::Mesh capsule = collision::make_sphere(0.01, 1);  // 42 points
  detail::build_convex_hull(capsule.vertices, "small", &stats, detail::HullPath::kAuto);
  EXPECT_TRUE(stats.direct);
  const collision::Mesh larger = collision::make_sphere(0.01, 3);  // 642 points
  detail::build_convex_hull(larger.vertices, "larger", &stats, detail::HullPath::kAuto);
  EXPECT_FALSE(stats.direct);
}

TEST(ConvexHull, AcceptanceTestRejectsWrongSurfaces) {
  // Octahedron: top, bottom, then the equator counter-clockwise seen from above.
  std::vector<Vec3> p = {Vec3(0, 0, 1), Vec3(0, 0, -1), Vec3(1, 0, 0),
                         Vec3(0, 1, 0), Vec3(-1, 0, 0), Vec3(0, -1, 0)};
  std::vector<TriangleIndices> t;
  for (std::uint32_t k = 0; k < 4; ++k) {
    const std::uint32_t u = 2 + k, v = 2 + (k + 1) % 4;
    t.push_back({0, u, v});
    t.push_back({1, v, u});
  }
  EXPECT_TRUE(detail::is_exact_hull(p, t));
  // A point inside, and one on a face, are fine; one outside is not.
  std::vector<Vec3> q = p;
  q.push_back(Vec3(0.1, 0.2, 0.3));
  q.push_back(Vec3(1.0 / 4, 1.0 / 4, 1.0 / 2));
  EXPECT_TRUE(detail::is_exact_hull(q, t));
  q.push_back(Vec3(0.5, 0.5, 0.5));
  EXPECT_FALSE(detail::is_exact_hull(q, t));
  // Reversed orientation.
  std::vector<TriangleIndices> reversed = t;
  for (TriangleIndices& f : reversed) std::swap(f[1], f[2]);
  EXPECT_FALSE(detail::is_exact_hull(p, reversed));
  // A dent: one equator vertex pulled in makes reflex edges.
  std::vector<Vec3> dented = p;
  dented[2] = Vec3(-0.3, 0, 0);
  EXPECT_FALSE(detail::is_exact_hull(dented, t));
  // Open surface (a face missing), and a face repeated.
  std::vector<TriangleIndices> open(t.begin(), t.end() - 1);
  EXPECT_FALSE(detail::is_exact_hull(p, open));
  std::vector<TriangleIndices> repeated = t;
  repeated.push_back(t[0]);
  EXPECT_FALSE(detail::is_exact_hull(p, repeated));
}

TEST(ConvexHull, ExactRebuildPathOnAnyInput) {
  Random r(12);
  for (int i = 0; i < 120; ++i) {
    std::vector<Vec3> p = i % 3 == 0   ? integer_points(r, 60, 2)
                          : i % 3 == 1 ? rotated_grid_box(r, 6)
                                       : blob(r, 80, Vec3(1, 0.5, 0.2));
    ConvexHull forced, normal;
    try {
      forced = detail::build_convex_hull(p, "forced", nullptr, detail::HullPath::kRebuild);
      normal = compute_convex_hull(p, "normal");
    } catch (const std::invalid_argument&) {
      continue;
    }
    expect_valid_hull(forced, p, "forced " + std::to_string(i));
    expect_exact_support(forced, r, 20);
    // Both are the exact hull: the same support values in every direction.
    for (int k = 0; k < 20; ++k) {
      const Vec3 d = r.direction();
      EXPECT_EQ(detail::dot_difference_sign(d, forced.vertices[forced.support(d)],
                                            normal.vertices[normal.support(d)]),
                0);
    }
  }
}

TEST(ConvexHull, DegenerateInputThrowsNamingSource) {
  auto expect_throw = [](const std::vector<Vec3>& p) {
    try {
      compute_convex_hull(p, "part.stl");
      ADD_FAILURE() << "no exception";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("part.stl"), std::string::npos) << e.what();
    }
  };
  expect_throw({});
  expect_throw({Vec3(1, 2, 3)});
  expect_throw({Vec3(1, 2, 3), Vec3(1, 2, 3), Vec3(1, 2, 3), Vec3(1, 2, 3)});
  expect_throw({Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(2, 2, 2), Vec3(3, 3, 3), Vec3(-1, -1, -1)});
  // Flat: a square with its centre, in a tilted plane given exactly.
  expect_throw({Vec3(0, 0, 0), Vec3(1, 0, 1), Vec3(0, 1, 1), Vec3(1, 1, 2), Vec3(0.5, 0.5, 1)});
  expect_throw({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, std::nan(""))});
  expect_throw({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0),
                Vec3(0, 0, std::numeric_limits<Real>::infinity())});
  // Thinner than qhull's precision (2^-60 relative): qhull's error, naming the source.
  expect_throw({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0x1p-60)});
  // Thin but within qhull's precision: a hull, and exact.
  const std::vector<Vec3> thin = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 1e-12)};
  expect_valid_hull(compute_convex_hull(thin, "thin"), thin, "thin");
  // Duplicates and a tetrahedron.
  const std::vector<Vec3> tet = {Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(1, 0, 0),      Vec3(0, 1, 0),
                                 Vec3(0, 0, 1), Vec3(1, 0, 0), Vec3(0.1, 0.1, 0.1)};
  const ConvexHull h = compute_convex_hull(tet, "tet");
  EXPECT_EQ(h.vertices.size(), 4u);
  EXPECT_EQ(h.faces.size(), 4u);
  expect_valid_hull(h, tet, "tet");
}

// ---------------------------------------------------------------------------
// Exact reference: two convex polytopes (closed) intersect iff a triangle of
// one surface meets a triangle of the other, or a vertex of one lies inside
// or on the other. B's vertices are placed with X_AB.apply, as the polygon
// level places them.

struct Placed {
  std::vector<Vec3> v;
  const std::vector<TriangleIndices>* faces = nullptr;
  std::vector<std::array<Vec3, 2>> boxes;  ///< per face, exact
};

Placed place(const ConvexHull& h, const Transform& X) {
  Placed p;
  p.faces = &h.faces;
  for (const Vec3& v : h.vertices) p.v.push_back(X.apply(v));
  for (const TriangleIndices& f : h.faces) {
    const Vec3 lo = p.v[f[0]].cwiseMin(p.v[f[1]]).cwiseMin(p.v[f[2]]);
    const Vec3 hi = p.v[f[0]].cwiseMax(p.v[f[1]]).cwiseMax(p.v[f[2]]);
    p.boxes.push_back({lo, hi});
  }
  return p;
}

bool inside_or_on(const Placed& h, const Vec3& q) {
  for (const TriangleIndices& f : *h.faces) {
    if (orient3d(h.v[f[0]], h.v[f[1]], h.v[f[2]], q) > 0) return false;
  }
  return true;
}

bool reference_intersect(const Placed& a, const Placed& b) {
  for (std::size_t i = 0; i < a.faces->size(); ++i) {
    const auto& ba = a.boxes[i];
    const TriangleIndices& fa = (*a.faces)[i];
    for (std::size_t j = 0; j < b.faces->size(); ++j) {
      const auto& bb = b.boxes[j];
      if ((ba[1].array() < bb[0].array()).any() || (bb[1].array() < ba[0].array()).any()) continue;
      const TriangleIndices& fb = (*b.faces)[j];
      if (triangles_intersect(a.v[fa[0]], a.v[fa[1]], a.v[fa[2]], b.v[fb[0]], b.v[fb[1]],
                              b.v[fb[2]])) {
        return true;
      }
    }
  }
  return inside_or_on(b, a.v[0]) || inside_or_on(a, b.v[0]);
}

// Brute-force distance between the placed polytopes (used where GJK and the
// reference disagree, and on a sample to check GJK's distances).

Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const Real d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const Real d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const Real vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Vec3 cp = p - c;
  const Real d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const Real vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const Real va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  }
  const Real denom = 1 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

Real segment_distance(const Vec3& p1, const Vec3& q1, const Vec3& p2, const Vec3& q2) {
  const Vec3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const Real a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  Real s = 0, t = 0;
  if (a <= 0 && e <= 0) return r.norm();
  if (a <= 0) {
    t = std::clamp(f / e, Real{0}, Real{1});
  } else {
    const Real c = d1.dot(r);
    if (e <= 0) {
      s = std::clamp(-c / a, Real{0}, Real{1});
    } else {
      const Real b = d1.dot(d2), denom = a * e - b * b;
      s = denom > 0 ? std::clamp((b * f - c * e) / denom, Real{0}, Real{1}) : 0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, Real{0}, Real{1});
      } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, Real{0}, Real{1});
      }
    }
  }
  return ((p1 + d1 * s) - (p2 + d2 * t)).norm();
}

Real brute_distance(const Placed& a, const Placed& b) {
  Real best = std::numeric_limits<Real>::infinity();
  auto vertex_face = [&](const Placed& x, const Placed& y) {
    for (const Vec3& p : x.v) {
      for (const TriangleIndices& f : *y.faces) {
        best = std::min(best, (p - closest_on_triangle(p, y.v[f[0]], y.v[f[1]], y.v[f[2]])).norm());
      }
    }
  };
  vertex_face(a, b);
  vertex_face(b, a);
  for (const TriangleIndices& fa : *a.faces) {
    for (int i = 0; i < 3; ++i) {
      for (const TriangleIndices& fb : *b.faces) {
        for (int j = 0; j < 3; ++j) {
          best = std::min(best, segment_distance(a.v[fa[i]], a.v[fa[(i + 1) % 3]], b.v[fb[j]],
                                                 b.v[fb[(j + 1) % 3]]));
        }
      }
    }
  }
  return best;
}

// Closest features: the feature's vertices placed in A's frame, and distances
// to and between the convex hulls of up to three points.

std::vector<Vec3> feature_points(const ConvexHull& h, const HullFeature& f, const Transform& X) {
  std::vector<Vec3> p;
  for (int k = 0; k < f.size(); ++k) p.push_back(X.apply(h.vertices[f.vertices[k]]));
  return p;
}

Real point_to_feature(const Vec3& p, const std::vector<Vec3>& f) {
  if (f.size() == 1) return (p - f[0]).norm();
  if (f.size() == 2) return segment_distance(p, p, f[0], f[1]);
  return (p - closest_on_triangle(p, f[0], f[1], f[2])).norm();
}

/// Distance between the convex hulls of two disjoint features: the nearest
/// pair is a point of one against the other, or an edge against an edge.
Real feature_distance(const std::vector<Vec3>& fa, const std::vector<Vec3>& fb) {
  Real best = std::numeric_limits<Real>::infinity();
  for (const Vec3& p : fa) best = std::min(best, point_to_feature(p, fb));
  for (const Vec3& q : fb) best = std::min(best, point_to_feature(q, fa));
  for (std::size_t i = 0; i + 1 < fa.size(); ++i) {
    for (std::size_t i2 = i + 1; i2 < fa.size(); ++i2) {
      for (std::size_t j = 0; j + 1 < fb.size(); ++j) {
        for (std::size_t j2 = j + 1; j2 < fb.size(); ++j2) {
          best = std::min(best, segment_distance(fa[i], fa[i2], fb[j], fb[j2]));
        }
      }
    }
  }
  return best;
}

/// Checks GJK's closest features against its closest points: valid ascending
/// indices, the closest points in the features' convex hulls, and for
/// separated hulls the distance between the features equal to the distance.
/// Returns false (and reports) on a violation.
bool features_consistent(const ConvexHull& a, const ConvexHull& b, const Transform& X,
                         const GjkResult& g) {
  const Real tolerance = 1e-9 * (a.radius + b.radius);
  const bool none_a = g.feature_a.type == FeatureType::kNone;
  const bool none_b = g.feature_b.type == FeatureType::kNone;
  if (none_a || none_b) {
    if (none_a != none_b || !g.intersecting) {
      std::printf("GJK features: kNone on one side only, or on separated hulls\n");
      return false;
    }
    return true;
  }
  for (const auto& [h, f] : {std::pair{&a, &g.feature_a}, std::pair{&b, &g.feature_b}}) {
    for (int k = 0; k < f->size(); ++k) {
      if (f->vertices[k] >= h->vertices.size() || (k > 0 && f->vertices[k - 1] >= f->vertices[k])) {
        std::printf("GJK features: bad vertex indices\n");
        return false;
      }
    }
  }
  const std::vector<Vec3> fa = feature_points(a, g.feature_a, Transform::identity());
  const std::vector<Vec3> fb = feature_points(b, g.feature_b, X);
  const Real off_a = point_to_feature(g.closest_a, fa), off_b = point_to_feature(g.closest_b, fb);
  if (off_a > tolerance || off_b > tolerance) {
    std::printf("GJK features: closest point %.3g / %.3g from its feature\n", off_a, off_b);
    return false;
  }
  if (g.intersecting) {
    const Real band = kGjkContactTolerance * (a.extent + b.extent + X.t.cwiseAbs().maxCoeff());
    if ((g.closest_a - g.closest_b).norm() > band * (1 + 1e-6) + tolerance) {
      std::printf("GJK features: intersecting but closest points apart\n");
      return false;
    }
    return true;
  }
  const Real d = feature_distance(fa, fb);
  if (std::abs(d - g.distance) > tolerance) {
    std::printf("GJK features: feature distance %.17g, distance %.17g\n", d, g.distance);
    return false;
  }
  return true;
}

// ---------------------------------------------------------------------------
// Agreement on many configurations

struct Pool {
  std::vector<ConvexHull> hulls;
  std::vector<ConvexHull> exact;  ///< integer vertices (exact transforms below)
};

Pool make_pool(Random& r) {
  Pool pool;
  while (pool.hulls.size() < 48) {
    const int kind = static_cast<int>(pool.hulls.size() % 4);
    std::vector<Vec3> p;
    if (kind == 0)
      p = blob(r, r.integer(6, 24),
               Vec3(r.uniform(0.3, 1.5), r.uniform(0.3, 1.5), r.uniform(0.3, 1.5)));
    if (kind == 1)
      p = box_with_face_points(
          r, Vec3(r.uniform(0.2, 1.5), r.uniform(0.2, 1.5), r.uniform(0.05, 1)), r.integer(0, 8));
    if (kind == 2)
      p = cloud(r, r.integer(8, 40), Vec3(1.5, r.uniform(0.05, 1), r.uniform(0.05, 1)));
    if (kind == 3) p = blob(r, r.integer(4, 12), Vec3(1, 1, 1));
    pool.hulls.push_back(compute_convex_hull(p, "pool"));
  }
  while (pool.exact.size() < 16) {
    try {
      pool.exact.push_back(
          compute_convex_hull(integer_points(r, r.integer(6, 20), r.integer(1, 3)), "grid"));
    } catch (const std::invalid_argument&) {
    }
  }
  return pool;
}

/// A rotation taking unit vector `from` to unit vector `to` (Rodrigues).
Mat3 rotation_between(const Vec3& from, const Vec3& to) {
  const Vec3 axis = from.cross(to);
  const Real s = axis.norm(), c = from.dot(to);
  if (s < 1e-12) {
    if (c > 0) return Mat3::Identity();
    // Opposite: a half turn about any axis perpendicular to `from`.
    const Vec3 p = std::abs(from.x()) < 0.9 ? Vec3(Vec3::UnitX()) : Vec3(Vec3::UnitY());
    const Vec3 k = from.cross(p).normalized();
    return 2 * k * k.transpose() - Mat3::Identity();
  }
  return Eigen::AngleAxis<Real>(std::atan2(s, c), axis / s).toRotationMatrix();
}

/// The 24 rotations that permute and negate axes (exact transforms).
Mat3 axis_rotation(Random& r) {
  for (;;) {
    Mat3 R = Mat3::Zero();
    int perm[3] = {0, 1, 2};
    std::shuffle(perm, perm + 3, std::mt19937(static_cast<unsigned>(r.integer(0, 1 << 30))));
    for (int i = 0; i < 3; ++i) R(i, perm[i]) = r.integer(0, 1) ? 1 : -1;
    if (R.determinant() > 0) return R;
  }
}

struct Tally {
  long configurations = 0, intersecting = 0;
  long sp_false_separated = 0;    ///< must be 0
  long sp_gave_up_separated = 0;  ///< separated pairs answered "maybe colliding"
  long sp_gave_up_clear = 0;      ///< ... of which separated by a clear margin: must be 0
  long gjk_false_separated = 0;   ///< GJK separated, reference intersecting: must be 0
  long gjk_band = 0;              ///< GJK intersecting, reference separated (touching band)
  long gjk_band_outside = 0;      ///< ... with brute-force distance above the band: must be 0
  long gjk_cap = 0, gjk_nonfinite = 0;
  /// GJK warm-started from a cache carried from one configuration to the
  /// next (a stale start on unrelated hulls and poses: the worst case).
  GjkCache warm;
  long warm_false_separated = 0, warm_band_outside = 0, warm_cap = 0, warm_nonfinite = 0;
  long features_checked = 0, features_none = 0;
  long features_wrong = 0;  ///< features_consistent failed: must be 0
  int gjk_max_iterations = 0;
  int sp_max_iterations = 0;
  long sp_iterations = 0;
  Real sp_gave_up_farthest = 0;  ///< largest GJK distance / (radius A + radius B) of those
};

constexpr Real kClearMargin = 0.01;  // times (radius A + radius B)

void check(const ConvexHull& a, const ConvexHull& b, const Transform& X, Tally& t) {
  const Placed pa = place(a, Transform::identity()), pb = place(b, X);
  const bool ref = reference_intersect(pa, pb);
  ++t.configurations;
  t.intersecting += ref;
  SeparatingPlaneCache plane;
  const SeparatingPlaneResult sp = separating_plane_test(a, b, X, plane);
  const GjkResult g = gjk(a, b, X);
  const GjkResult warm = gjk(a, b, X, &t.warm);
  t.sp_iterations += sp.iterations;
  t.sp_max_iterations = std::max(t.sp_max_iterations, sp.iterations);
  t.gjk_max_iterations = std::max({t.gjk_max_iterations, g.iterations, warm.iterations});
  auto finite = [](const GjkResult& r) {
    return std::isfinite(r.distance) && r.closest_a.allFinite() && r.closest_b.allFinite();
  };
  t.gjk_nonfinite += !finite(g);
  t.warm_nonfinite += !finite(warm);
  t.gjk_cap += g.hit_iteration_cap;
  t.warm_cap += warm.hit_iteration_cap;
  for (const GjkResult* r : {&g, &warm}) {
    ++t.features_checked;
    t.features_none += r->feature_a.type == FeatureType::kNone;
    t.features_wrong += !features_consistent(a, b, X, *r);
  }
  t.warm_false_separated += ref && !warm.intersecting;
  if (ref && sp.separated) ++t.sp_false_separated;
  if (!ref && !sp.separated) {
    EXPECT_TRUE(sp.gave_up);
    ++t.sp_gave_up_separated;
    if (!g.intersecting) {
      const Real relative = g.distance / (a.radius + b.radius);
      t.sp_gave_up_farthest = std::max(t.sp_gave_up_farthest, relative);
      if (relative > kClearMargin) ++t.sp_gave_up_clear;
    }
  }
  if (ref && !g.intersecting) {
    ++t.gjk_false_separated;
    std::printf("GJK separated an intersecting pair: distance %.17g\n", g.distance);
  }
  if (!ref && (g.intersecting || warm.intersecting)) {
    t.gjk_band += g.intersecting;
    const Real band = kGjkContactTolerance * (a.extent + b.extent + X.t.cwiseAbs().maxCoeff());
    const Real d = brute_distance(pa, pb);
    if (d > band * (1 + 1e-6)) {
      t.gjk_band_outside += g.intersecting;
      t.warm_band_outside += warm.intersecting;
      std::printf("GJK intersecting outside the band: distance %.17g band %.3g\n", d, band);
    }
  }
}

void report(const char* name, const Tally& t) {
  std::printf(
      "[ convex  ] %-28s %7ld configs %7ld intersecting | SP: false separated %ld, gave up on "
      "separated %ld (farthest %.2g, clear margin %ld), mean iterations %.2f, max %d | GJK: false "
      "separated %ld, band %ld (outside band %ld), cap %ld, non-finite %ld | GJK from a stale "
      "cache: false separated %ld, outside band %ld, cap %ld, non-finite %ld | GJK most "
      "iterations %d (cap %d) | features: %ld results checked, %ld kNone, %ld wrong\n",
      name, t.configurations, t.intersecting, t.sp_false_separated, t.sp_gave_up_separated,
      t.sp_gave_up_farthest, t.sp_gave_up_clear,
      static_cast<double>(t.sp_iterations) / std::max(1L, t.configurations), t.sp_max_iterations,
      t.gjk_false_separated, t.gjk_band, t.gjk_band_outside, t.gjk_cap, t.gjk_nonfinite,
      t.warm_false_separated, t.warm_band_outside, t.warm_cap, t.warm_nonfinite,
      t.gjk_max_iterations, kGjkMaxIterations, t.features_checked, t.features_none,
      t.features_wrong);
}

void expect_clean(const Tally& t) {
  EXPECT_EQ(t.sp_false_separated, 0);
  EXPECT_EQ(t.sp_gave_up_clear, 0);
  EXPECT_EQ(t.gjk_false_separated, 0);
  EXPECT_EQ(t.gjk_band_outside, 0);
  EXPECT_EQ(t.gjk_cap, 0);
  EXPECT_EQ(t.gjk_nonfinite, 0);
  EXPECT_EQ(t.warm_false_separated, 0);
  EXPECT_EQ(t.warm_band_outside, 0);
  EXPECT_EQ(t.warm_cap, 0);
  EXPECT_EQ(t.warm_nonfinite, 0);
  EXPECT_LT(t.gjk_max_iterations, kGjkMaxIterations);
  EXPECT_EQ(t.features_wrong, 0);
}

TEST(ConvexAgreement, RandomPoses) {
  Random r(21);
  const Pool pool = make_pool(r);
  Tally t;
  for (int i = 0; i < 60000; ++i) {
    const ConvexHull& a = pool.hulls[r.integer(0, 47)];
    const ConvexHull& b = pool.hulls[r.integer(0, 47)];
    Transform X;
    X.R = r.rotation();
    const Real reach = a.radius + b.radius;
    X.t = a.center + r.direction() * reach * r.uniform(0, 1.3) - X.R * b.center;
    check(a, b, X, t);
  }
  report("random poses", t);
  expect_clean(t);
}

TEST(ConvexAgreement, TouchingAndNearlyTouching) {
  Random r(22);
  const Pool pool = make_pool(r);
  Tally t;
  const Real shifts[] = {0,     0,      0,    1e-15, -1e-15, 1e-12, -1e-12,
                         1e-10, -1e-10, 1e-8, -1e-8, 1e-5,   -1e-5};
  for (int i = 0; i < 40000; ++i) {
    const ConvexHull& a = pool.hulls[r.integer(0, 47)];
    const ConvexHull& b = pool.hulls[r.integer(0, 47)];
    Transform X;
    X.R = r.rotation();
    Vec3 u = r.direction();
    Vec3 on_a, on_b;
    if (i % 2 == 0) {
      // Vertex on vertex: A's highest vertex along u meets B's lowest.
      on_a = a.vertices[a.support(u)];
      on_b = b.vertices[b.support(-(X.R.transpose() * u))];
    } else {
      // Face on face: B turned so that one of its faces lies on one of A's, centroids together.
      const TriangleIndices& fa = a.faces[r.integer(0, static_cast<int>(a.faces.size()) - 1)];
      const TriangleIndices& fb = b.faces[r.integer(0, static_cast<int>(b.faces.size()) - 1)];
      const Vec3 na = (a.vertices[fa[1]] - a.vertices[fa[0]])
                          .cross(a.vertices[fa[2]] - a.vertices[fa[0]])
                          .normalized();
      const Vec3 nb = (b.vertices[fb[1]] - b.vertices[fb[0]])
                          .cross(b.vertices[fb[2]] - b.vertices[fb[0]])
                          .normalized();
      const Mat3 turn = rotation_between(nb, -na);
      const Mat3 spin = Eigen::AngleAxis<Real>(r.uniform(0, 2 * kPi), na).toRotationMatrix();
      X.R = spin * turn;
      u = na;
      on_a = (a.vertices[fa[0]] + a.vertices[fa[1]] + a.vertices[fa[2]]) / 3;
      on_b = (b.vertices[fb[0]] + b.vertices[fb[1]] + b.vertices[fb[2]]) / 3;
    }
    const Real scale = a.radius + b.radius;
    X.t = on_a - X.R * on_b + u * (shifts[i % 13] * scale);
    check(a, b, X, t);
  }
  report("touching and near-touching", t);
  expect_clean(t);
}

TEST(ConvexAgreement, ExactlyRepresentableTouching) {
  Random r(23);
  const Pool pool = make_pool(r);
  Tally t;
  for (int i = 0; i < 20000; ++i) {
    const ConvexHull& a = pool.exact[r.integer(0, 15)];
    const ConvexHull& b = pool.exact[r.integer(0, 15)];
    Transform X;
    X.R = axis_rotation(r);
    if (i % 2 == 0) {
      X.t = Vec3(r.integer(-7, 7), r.integer(-7, 7), r.integer(-7, 7));
    } else {
      // Exactly touching: A's highest vertex along u on B's lowest, plus 0 or 1 unit along u.
      Vec3 u(r.integer(-2, 2), r.integer(-2, 2), r.integer(-2, 2));
      if (u == Vec3::Zero()) u = Vec3::UnitX();
      const Vec3 on_a = a.vertices[a.support(u)];
      const Vec3 on_b = b.vertices[b.support(-(X.R.transpose() * u))];
      X.t = on_a - X.R * on_b + (i % 6 == 1 ? u : Vec3(Vec3::Zero()));
    }
    check(a, b, X, t);
  }
  report("integer hulls, exact poses", t);
  expect_clean(t);
}

// ---------------------------------------------------------------------------
// Coherent motion: warm-started GJK and the cached plane

TEST(ConvexCoherence, WarmStartSavesIterations) {
  Random r(31);
  const Pool pool = make_pool(r);
  long warm_iterations = 0, cold_iterations = 0, queries = 0, plane_hits = 0, plane_separated = 0;
  long witness_hits = 0, plane_iterations = 0, disagreements = 0;
  Tally t;
  for (int pair = 0; pair < 60; ++pair) {
    const ConvexHull& a = pool.hulls[r.integer(0, 47)];
    const ConvexHull& b = pool.hulls[r.integer(0, 47)];
    const Vec3 axis = r.direction(), spin = r.direction();
    const Mat3 R0 = r.rotation();
    const Real reach = a.radius + b.radius;
    GjkCache cache;
    SeparatingPlaneCache plane;
    for (int step = 0; step < 400; ++step) {
      // B tumbles and swings through A and out again.
      const Real time = step / 90.0;
      Transform X;
      X.R = Eigen::AngleAxis<Real>(1.5 * time, spin).toRotationMatrix() * R0;
      X.t = a.center + axis * reach * (0.2 + 1.2 * std::abs(std::cos(0.7 * time))) - X.R * b.center;
      const GjkResult warm = gjk(a, b, X, &cache);
      const GjkResult cold = gjk(a, b, X);
      const SeparatingPlaneResult sp = separating_plane_test(a, b, X, plane);
      warm_iterations += warm.iterations;
      cold_iterations += cold.iterations;
      plane_iterations += sp.iterations;
      plane_hits += sp.cache_hit;
      witness_hits += sp.witness_hit;
      plane_separated += sp.separated;
      ++queries;
      disagreements += warm.intersecting != cold.intersecting;
      EXPECT_FALSE(warm.hit_iteration_cap);
      if (!warm.intersecting && !cold.intersecting) {
        EXPECT_NEAR(warm.distance, cold.distance, 1e-9 * reach);
      }
      // Both cached answers against the exact reference.
      const bool ref = reference_intersect(place(a, Transform::identity()), place(b, X));
      ++t.configurations;
      t.intersecting += ref;
      t.sp_false_separated += ref && sp.separated;
      t.gjk_false_separated += ref && !warm.intersecting;
      t.gjk_band += !ref && warm.intersecting;
      if (!ref && !sp.separated && !warm.intersecting && warm.distance > kClearMargin * reach) {
        ++t.sp_gave_up_clear;
      }
    }
  }
  const double warm_mean = static_cast<double>(warm_iterations) / queries;
  const double cold_mean = static_cast<double>(cold_iterations) / queries;
  std::printf(
      "[ convex  ] coherent motion: %ld queries (%ld intersecting), GJK iterations warm %.2f cold "
      "%.2f; separating plane: %.2f iterations, %ld separated, %ld by the cached plane, %ld "
      "overlap witnesses still holding; false separated %ld/%ld (plane/GJK), GJK band %ld, plane "
      "gave up at a clear margin %ld\n",
      queries, t.intersecting, warm_mean, cold_mean,
      static_cast<double>(plane_iterations) / queries, plane_separated, plane_hits, witness_hits,
      t.sp_false_separated, t.gjk_false_separated, t.gjk_band, t.sp_gave_up_clear);
  EXPECT_LT(warm_mean, cold_mean);
  EXPECT_EQ(disagreements, 0);
  EXPECT_EQ(t.sp_false_separated, 0);
  EXPECT_EQ(t.gjk_false_separated, 0);
  EXPECT_EQ(t.gjk_band, 0);
  EXPECT_EQ(t.sp_gave_up_clear, 0);
}

// GJK distances against brute force on a sample of separated poses.
TEST(Gjk, DistanceMatchesBruteForce) {
  Random r(41);
  const Pool pool = make_pool(r);
  int separated = 0;
  for (int i = 0; i < 3000; ++i) {
    const ConvexHull& a = pool.hulls[r.integer(0, 47)];
    const ConvexHull& b = pool.hulls[r.integer(0, 47)];
    Transform X;
    X.R = r.rotation();
    X.t = a.center + r.direction() * (a.radius + b.radius) * r.uniform(0.5, 2) - X.R * b.center;
    const GjkResult g = gjk(a, b, X);
    if (g.intersecting) continue;
    ++separated;
    const Placed pa = place(a, Transform::identity()), pb = place(b, X);
    const Real d = brute_distance(pa, pb);
    EXPECT_NEAR(g.distance, d, 1e-9 * (a.radius + b.radius)) << i;
    EXPECT_NEAR((g.closest_a - g.closest_b).norm(), g.distance, 1e-9 * (a.radius + b.radius));
  }
  EXPECT_GT(separated, 1000);
}

// ---------------------------------------------------------------------------
// Closest features

/// Hull of a box's corners, each corner turned by R (in the hull's frame).
ConvexHull turned_box(const Vec3& half, const Mat3& R) {
  std::vector<Vec3> p;
  for (int i = 0; i < 8; ++i) {
    p.push_back(R * Vec3(i & 1 ? half.x() : -half.x(), i & 2 ? half.y() : -half.y(),
                         i & 4 ? half.z() : -half.z()));
  }
  return compute_convex_hull(p, "box");
}

/// Indices of the hull vertices whose z is the extreme one (max or min), ascending.
std::vector<std::uint32_t> extreme_z(const ConvexHull& h, bool highest) {
  Real best =
      highest ? -std::numeric_limits<Real>::infinity() : std::numeric_limits<Real>::infinity();
  for (const Vec3& v : h.vertices) best = highest ? std::max(best, v.z()) : std::min(best, v.z());
  std::vector<std::uint32_t> out;
  for (std::uint32_t i = 0; i < h.vertices.size(); ++i) {
    if (h.vertices[i].z() == best) out.push_back(i);
  }
  return out;
}

std::vector<std::uint32_t> indices(const HullFeature& f) {
  return {f.vertices.begin(), f.vertices.begin() + f.size()};
}

Transform translation(const Vec3& t) {
  Transform X;
  X.t = t;
  return X;
}

// B's corner over the inside of A's top face, off its diagonals: A's feature
// is a triangle of its top face, B's the corner; touching (gap 0) keeps them.
TEST(GjkFeatures, VertexOverFace) {
  const ConvexHull a = turned_box(Vec3(1, 1, 0.5), Mat3::Identity());
  const Mat3 corner_down = rotation_between(Vec3(-1, -1, -1).normalized(), -Vec3::UnitZ());
  const ConvexHull b = turned_box(Vec3(0.5, 0.5, 0.5), corner_down);
  const std::vector<std::uint32_t> top = extreme_z(a, true), low = extreme_z(b, false);
  ASSERT_EQ(top.size(), 4u);
  ASSERT_EQ(low.size(), 1u);
  for (const Real gap : {0.25, 1e-3, 1e-12, 0.0}) {
    SCOPED_TRACE(gap);
    const Transform X = translation(Vec3(0.3, -0.1, 0.5 + gap - b.vertices[low[0]].z()));
    const GjkResult g = gjk(a, b, X);
    EXPECT_EQ(g.intersecting, gap < 1e-9);
    EXPECT_NEAR(g.distance, g.intersecting ? 0 : gap, 1e-12);
    EXPECT_EQ(g.feature_b.type, FeatureType::kVertex);
    EXPECT_EQ(indices(g.feature_b), low);
    ASSERT_EQ(g.feature_a.type, FeatureType::kFace);
    for (std::uint32_t i : indices(g.feature_a)) {
      EXPECT_TRUE(std::find(top.begin(), top.end(), i) != top.end()) << i;
    }
    EXPECT_NEAR(g.closest_a.x(), 0.3, 1e-12);
    EXPECT_NEAR(g.closest_a.y(), -0.1, 1e-12);
    EXPECT_TRUE(features_consistent(a, b, X, g));
  }
}

// A's top edge (along x) across B's bottom edge (along y): edge and edge,
// exactly those two vertices on each side.
TEST(GjkFeatures, EdgeAcrossEdge) {
  const Mat3 about_x = Eigen::AngleAxis<Real>(kPi / 4, Vec3::UnitX()).toRotationMatrix();
  const Mat3 about_y = Eigen::AngleAxis<Real>(kPi / 4, Vec3::UnitY()).toRotationMatrix();
  const ConvexHull a = turned_box(Vec3(1, 0.5, 0.5), about_x);
  const ConvexHull b = turned_box(Vec3(0.5, 1, 0.5), about_y);
  const std::vector<std::uint32_t> top = extreme_z(a, true), low = extreme_z(b, false);
  ASSERT_EQ(top.size(), 2u);
  ASSERT_EQ(low.size(), 2u);
  for (const Real gap : {0.5, 1e-6}) {
    SCOPED_TRACE(gap);
    const Real z = a.vertices[top[0]].z() + gap - b.vertices[low[0]].z();
    // The edges cross above x = 0.2 on A's edge and 0.3 along B's.
    const Transform X =
        translation(Vec3(0.2 - b.vertices[low[0]].x(), a.vertices[top[0]].y() - 0.3, z));
    const GjkResult g = gjk(a, b, X);
    ASSERT_FALSE(g.intersecting);
    EXPECT_NEAR(g.distance, gap, 1e-12);
    EXPECT_EQ(g.feature_a.type, FeatureType::kEdge);
    EXPECT_EQ(indices(g.feature_a), top);
    EXPECT_EQ(g.feature_b.type, FeatureType::kEdge);
    EXPECT_EQ(indices(g.feature_b), low);
    EXPECT_TRUE(features_consistent(a, b, X, g));
  }
}

// Parallel faces: a long bar across another (no corner of either above the
// other's face). The closest points are not unique; each feature is an edge
// (possibly a diagonal) or a triangle of the facing face, holding the
// closest point, and the features are as far apart as the faces.
TEST(GjkFeatures, ParallelFacesGiveEdgeOrFace) {
  const ConvexHull a = turned_box(Vec3(2, 0.5, 0.5), Mat3::Identity());
  const ConvexHull b = turned_box(Vec3(0.5, 2, 0.5), Mat3::Identity());
  const std::vector<std::uint32_t> top = extreme_z(a, true), low = extreme_z(b, false);
  int edges = 0, faces = 0;
  Random r(43);
  for (int i = 0; i < 200; ++i) {
    const Real gap = i % 4 == 0 ? 1e-6 : r.uniform(0.01, 2);
    const Transform X = translation(Vec3(r.uniform(-1.4, 1.4), r.uniform(-1.4, 1.4), 1 + gap));
    const GjkResult g = gjk(a, b, X);
    ASSERT_FALSE(g.intersecting);
    EXPECT_NEAR(g.distance, gap, 1e-12);
    for (const auto& [f, face] : {std::pair{&g.feature_a, &top}, std::pair{&g.feature_b, &low}}) {
      ASSERT_TRUE(f->type == FeatureType::kEdge || f->type == FeatureType::kFace);
      edges += f->type == FeatureType::kEdge;
      faces += f->type == FeatureType::kFace;
      for (std::uint32_t v : indices(*f)) {
        EXPECT_TRUE(std::find(face->begin(), face->end(), v) != face->end()) << v;
      }
    }
    EXPECT_TRUE(features_consistent(a, b, X, g));
  }
  std::printf("[ convex  ] parallel faces: %d edge and %d face features\n", edges, faces);
}

// A small box deep inside a large one: the final simplex is a tetrahedron
// holding the origin, and there are no closest features.
TEST(GjkFeatures, DeepOverlapHasNoFeatures) {
  Random r(44);
  const ConvexHull a = turned_box(Vec3(1, 1, 1), Mat3::Identity());
  const ConvexHull b = turned_box(Vec3(0.2, 0.3, 0.1), r.rotation());
  const GjkResult g = gjk(a, b, translation(Vec3(0.1, 0.05, -0.1)));
  EXPECT_TRUE(g.intersecting);
  EXPECT_EQ(g.feature_a.type, FeatureType::kNone);
  EXPECT_EQ(g.feature_b.type, FeatureType::kNone);
}

// Random separated poses: the features hold the closest points, lie on the
// supporting planes facing the other hull, and are as far apart as the hulls
// (brute force), cold and warm-started alike.
TEST(GjkFeatures, RandomPosesFeaturesAreClosest) {
  Random r(45);
  const Pool pool = make_pool(r);
  int separated = 0;
  int types[4] = {};
  for (int i = 0; i < 3000; ++i) {
    const ConvexHull& a = pool.hulls[r.integer(0, 47)];
    const ConvexHull& b = pool.hulls[r.integer(0, 47)];
    Transform X;
    X.R = r.rotation();
    X.t = a.center + r.direction() * (a.radius + b.radius) * r.uniform(0.3, 1.5) - X.R * b.center;
    GjkCache cache;
    const GjkResult g = gjk(a, b, X, &cache);
    ASSERT_TRUE(features_consistent(a, b, X, g)) << i;
    if (g.intersecting) continue;
    ++separated;
    ++types[static_cast<int>(g.feature_a.type)];
    ++types[static_cast<int>(g.feature_b.type)];
    const Real tolerance = 1e-9 * (a.radius + b.radius);
    const Placed pa = place(a, Transform::identity()), pb = place(b, X);
    const Real d = brute_distance(pa, pb);
    EXPECT_NEAR(g.distance, d, tolerance);
    EXPECT_NEAR(feature_distance(feature_points(a, g.feature_a, Transform::identity()),
                                 feature_points(b, g.feature_b, X)),
                d, tolerance);
    // Every feature vertex on the supporting plane: n . x minimal over A, n . y maximal over B.
    const Vec3 n = (g.closest_b - g.closest_a) / g.distance;
    Real low_b = std::numeric_limits<Real>::infinity(), high_a = -low_b;
    for (const Vec3& v : pa.v) high_a = std::max(high_a, n.dot(v));
    for (const Vec3& v : pb.v) low_b = std::min(low_b, n.dot(v));
    for (const Vec3& v : feature_points(a, g.feature_a, Transform::identity()))
      EXPECT_NEAR(n.dot(v), high_a, tolerance);
    for (const Vec3& v : feature_points(b, g.feature_b, X)) EXPECT_NEAR(n.dot(v), low_b, tolerance);
    // Warm-started again at a nearby pose: still consistent.
    Transform moved = X;
    moved.t += 1e-3 * r.direction();
    EXPECT_TRUE(features_consistent(a, b, moved, gjk(a, b, moved, &cache))) << i;
  }
  std::printf("[ convex  ] random poses: %d separated, features: %d vertices, %d edges, %d faces\n",
              separated, types[1], types[2], types[3]);
  EXPECT_GT(separated, 1000);
}

TEST(Gjk, NonFiniteAndExtremeInputStayFinite) {
  Random r(42);
  const ConvexHull a = compute_convex_hull(blob(r, 20, Vec3(1, 1, 1)), "a");
  Transform X;
  X.t = Vec3(std::nan(""), 0, 0);
  const GjkResult g = gjk(a, a, X);
  EXPECT_TRUE(std::isfinite(g.distance));
  EXPECT_TRUE(g.closest_a.allFinite());
  SeparatingPlaneCache plane;
  EXPECT_FALSE(separating_plane_test(a, a, X, plane).separated);
  X.t = Vec3(1e300, 0, 0);
  const GjkResult far = gjk(a, a, X);
  EXPECT_TRUE(std::isfinite(far.distance));
  EXPECT_FALSE(far.hit_iteration_cap);
}

}  // namespace
}  // namespace dovetail::collision

namespace dovetail::collision {
namespace {

ConvexHull hull_of_points(const std::vector<Vec3>& points) {
  return compute_convex_hull(points, "test");
}

std::vector<Vec3> box_points(const Vec3& half) {
  std::vector<Vec3> p;
  for (int c = 0; c < 8; ++c) {
    p.emplace_back(c & 1 ? half.x() : -half.x(), c & 2 ? half.y() : -half.y(),
                   c & 4 ? half.z() : -half.z());
  }
  return p;
}

TEST(PenetrationDepth, CrossedBarsAndBoxes) {
  // Two bars laid crosswise, 8 deep along y: no vertex of either is inside the other.
  const ConvexHull a = hull_of_points(box_points(Vec3(50, 5, 5)));
  const ConvexHull b = hull_of_points(box_points(Vec3(5, 5, 50)));
  Transform X_AB;
  X_AB.t = Vec3(0, 2, 0);
  const auto pd = convex_penetration_depth(a, b, X_AB);
  ASSERT_TRUE(pd.has_value());
  EXPECT_NEAR(pd->depth, 8, 1e-12);
  EXPECT_NEAR(std::abs(pd->normal.y()), 1, 1e-12);
  // Apart and touching: 0.
  X_AB.t = Vec3(0, 10, 0);
  EXPECT_EQ(convex_penetration_depth(a, b, X_AB)->depth, 0);
  X_AB.t = Vec3(0, 11, 0);
  EXPECT_EQ(convex_penetration_depth(a, b, X_AB)->depth, 0);
  // Too many edge pairs for the limit: nothing.
  EXPECT_FALSE(convex_penetration_depth(a, b, X_AB, 10).has_value());
}

TEST(PenetrationDepth, NoDirectionSeparatesWithLessAndItsOwnDoes) {
  // Random polytopes at random overlapping poses: moving B along the normal by
  // the depth (and a hair) separates them, and no sampled direction needs less.
  Random random(20261127);
  for (int trial = 0; trial < 60; ++trial) {
    std::vector<Vec3> pa, pb;
    for (int k = 0; k < 12; ++k) {
      pa.push_back(Vec3(random.normal(), random.normal(), random.normal()).normalized());
      pb.push_back(Vec3(random.normal(), random.normal(), random.normal()).normalized() * 0.7);
    }
    const ConvexHull a = hull_of_points(pa), b = hull_of_points(pb);
    Transform X_AB;
    const Vec3 axis = Vec3(random.normal(), random.normal(), random.normal()).normalized();
    X_AB.R = Eigen::AngleAxisd(random.uniform(0, 2 * kPi), axis).toRotationMatrix();
    X_AB.t = Vec3(random.uniform(-0.8, 0.8), random.uniform(-0.8, 0.8), random.uniform(-0.8, 0.8));
    const auto pd = convex_penetration_depth(a, b, X_AB);
    ASSERT_TRUE(pd.has_value());
    if (!gjk(a, b, X_AB).intersecting) {
      EXPECT_EQ(pd->depth, 0);
      continue;
    }
    ASSERT_GT(pd->depth, 0);
    Transform moved = X_AB;
    moved.t += pd->normal * (pd->depth + 1e-6);
    EXPECT_FALSE(gjk(a, b, moved).intersecting) << trial;
    moved.t = X_AB.t + pd->normal * (pd->depth - 1e-6);
    EXPECT_TRUE(gjk(a, b, moved).intersecting) << trial;
    // The overlap along any direction is at least the depth.
    for (int k = 0; k < 200; ++k) {
      const Vec3 n = Vec3(random.normal(), random.normal(), random.normal()).normalized();
      Real max_a = -1e300, min_b = 1e300;
      for (const Vec3& v : a.vertices) max_a = std::max(max_a, n.dot(v));
      for (const Vec3& v : b.vertices) min_b = std::min(min_b, n.dot(X_AB.apply(v)));
      EXPECT_GE(max_a - min_b, pd->depth - 1e-12) << trial;
    }
  }
}

}  // namespace
}  // namespace dovetail::collision
