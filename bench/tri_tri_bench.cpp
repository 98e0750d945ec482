// Cost of one exact triangle-triangle test (triangles_intersect) against a
// plain floating-point Moller-style test with an epsilon, on several pair
// distributions. Prints ns per test as the median of 5 runs, and how often the
// plain test disagrees with the exact one.
//
// Built as the `tri_tri_bench` target with DOVETAIL_BUILD_BENCH=ON, or alone
// from the repository root:
//   g++ -O3 -DNDEBUG -std=c++20 -ffp-contract=off -I collision/include -I collision/src
//       -I /usr/include/eigen3 bench/tri_tri_bench.cpp collision/src/core/predicates.cpp
//       collision/src/core/tri_tri.cpp -o tri_tri_bench
// An optional argument runs only the workloads whose name contains it.

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "dovetail/collision/tri_tri.h"

namespace {

using dovetail::collision::Mat3;
using dovetail::collision::Real;
using dovetail::collision::Vec3;

struct Tri {
  Vec3 a, b, c;
};

struct Pair {
  Tri t1, t2;
};

// ---------------------------------------------------------------------------
// Baseline: Moller, "A Fast Triangle-Triangle Intersection Test" (1997), in
// plain double arithmetic with an absolute epsilon on the plane distances.

constexpr Real kPlainEpsilon = 1e-12;

Real snap(Real d) { return std::abs(d) < kPlainEpsilon ? 0 : d; }

/// Interval of a triangle on the planes' common line, from projections p and
/// plane distances d, when vertex `lone` is alone on its side.
std::pair<Real, Real> plain_interval(const Real p[3], const Real d[3], int lone) {
  const int i = (lone + 1) % 3, j = (lone + 2) % 3;
  const Real t0 = p[lone] + (p[i] - p[lone]) * d[lone] / (d[lone] - d[i]);
  const Real t1 = p[lone] + (p[j] - p[lone]) * d[lone] / (d[lone] - d[j]);
  return {std::min(t0, t1), std::max(t0, t1)};
}

int plain_lone_vertex(const Real d[3]) {
  if (d[0] * d[1] > 0) return 2;
  if (d[0] * d[2] > 0) return 1;
  if (d[1] * d[2] > 0 || d[0] != 0) return 0;
  if (d[1] != 0) return 1;
  return 2;
}

bool plain_edges_cross(Real ax, Real ay, Real bx, Real by, Real cx, Real cy, Real dx, Real dy) {
  const auto side = [](Real px, Real py, Real qx, Real qy, Real rx, Real ry) {
    return (qx - px) * (ry - py) - (qy - py) * (rx - px);
  };
  const Real s1 = side(ax, ay, bx, by, cx, cy), s2 = side(ax, ay, bx, by, dx, dy);
  const Real s3 = side(cx, cy, dx, dy, ax, ay), s4 = side(cx, cy, dx, dy, bx, by);
  return s1 * s2 <= 0 && s3 * s4 <= 0;
}

bool plain_point_in(const Real t[3][2], Real px, Real py) {
  Real s[3];
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    s[i] = (t[j][0] - t[i][0]) * (py - t[i][1]) - (t[j][1] - t[i][1]) * (px - t[i][0]);
  }
  return (s[0] >= 0 && s[1] >= 0 && s[2] >= 0) || (s[0] <= 0 && s[1] <= 0 && s[2] <= 0);
}

bool plain_coplanar(const Vec3& n, const Tri& t1, const Tri& t2) {
  const Vec3 a = n.cwiseAbs();
  const int drop = a.x() > a.y() ? (a.x() > a.z() ? 0 : 2) : (a.y() > a.z() ? 1 : 2);
  const int i = (drop + 1) % 3, j = (drop + 2) % 3;
  const Real p[3][2] = {{t1.a[i], t1.a[j]}, {t1.b[i], t1.b[j]}, {t1.c[i], t1.c[j]}};
  const Real q[3][2] = {{t2.a[i], t2.a[j]}, {t2.b[i], t2.b[j]}, {t2.c[i], t2.c[j]}};
  for (int e = 0; e < 3; ++e) {
    for (int f = 0; f < 3; ++f) {
      if (plain_edges_cross(p[e][0], p[e][1], p[(e + 1) % 3][0], p[(e + 1) % 3][1], q[f][0],
                            q[f][1], q[(f + 1) % 3][0], q[(f + 1) % 3][1])) {
        return true;
      }
    }
  }
  return plain_point_in(p, q[0][0], q[0][1]) || plain_point_in(q, p[0][0], p[0][1]);
}

__attribute__((noipa)) bool plain_triangles_intersect(const Tri& t1, const Tri& t2) {
  const Vec3 n2 = (t2.b - t2.a).cross(t2.c - t2.a);
  const Real d2 = -n2.dot(t2.a);
  const Real du[3] = {snap(n2.dot(t1.a) + d2), snap(n2.dot(t1.b) + d2), snap(n2.dot(t1.c) + d2)};
  if (du[0] * du[1] > 0 && du[0] * du[2] > 0) return false;
  const Vec3 n1 = (t1.b - t1.a).cross(t1.c - t1.a);
  const Real d1 = -n1.dot(t1.a);
  const Real dv[3] = {snap(n1.dot(t2.a) + d1), snap(n1.dot(t2.b) + d1), snap(n1.dot(t2.c) + d1)};
  if (dv[0] * dv[1] > 0 && dv[0] * dv[2] > 0) return false;
  if (du[0] == 0 && du[1] == 0 && du[2] == 0) return plain_coplanar(n1, t1, t2);
  const Vec3 dir = n1.cross(n2).cwiseAbs();
  const int axis = dir.x() > dir.y() ? (dir.x() > dir.z() ? 0 : 2) : (dir.y() > dir.z() ? 1 : 2);
  const Real p1[3] = {t1.a[axis], t1.b[axis], t1.c[axis]};
  const Real p2[3] = {t2.a[axis], t2.b[axis], t2.c[axis]};
  const auto [lo1, hi1] = plain_interval(p1, du, plain_lone_vertex(du));
  const auto [lo2, hi2] = plain_interval(p2, dv, plain_lone_vertex(dv));
  return !(hi1 < lo2 || hi2 < lo1);
}

__attribute__((noipa)) bool exact_triangles_intersect(const Tri& t1, const Tri& t2) {
  return dovetail::collision::triangles_intersect(t1.a, t1.b, t1.c, t2.a, t2.b, t2.c);
}

// ---------------------------------------------------------------------------
// Workloads.

class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}
  Real uniform(Real lo, Real hi) {
    return lo + (hi - lo) * static_cast<Real>(engine_() >> 11) * 0x1p-53;
  }
  std::int64_t integer(std::int64_t lo, std::int64_t hi) {
    return lo + static_cast<std::int64_t>(engine_() % static_cast<std::uint64_t>(hi - lo + 1));
  }
  Vec3 point(Real lo, Real hi) { return Vec3(uniform(lo, hi), uniform(lo, hi), uniform(lo, hi)); }

 private:
  std::mt19937_64 engine_;
};

Tri near(Random& r, const Vec3& centre, Real size) {
  return {centre + r.point(-size, size), centre + r.point(-size, size),
          centre + r.point(-size, size)};
}

bool boxes_overlap(const Tri& s, const Tri& t) {
  for (int k = 0; k < 3; ++k) {
    const Real s_lo = std::min({s.a[k], s.b[k], s.c[k]}), s_hi = std::max({s.a[k], s.b[k], s.c[k]});
    const Real t_lo = std::min({t.a[k], t.b[k], t.c[k]}), t_hi = std::max({t.a[k], t.b[k], t.c[k]});
    if (s_hi < t_lo || t_hi < s_lo) return false;
  }
  return true;
}

/// Exactly coplanar pair: integer combinations of integer vectors.
Pair coplanar_pair(Random& r) {
  const Vec3 o(Real(r.integer(-100, 100)), Real(r.integer(-100, 100)), Real(r.integer(-100, 100)));
  const Vec3 e1(1, Real(r.integer(-3, 3)), 2), e2(Real(r.integer(-3, 3)), 1, -1);
  const auto at = [&] { return o + Real(r.integer(-8, 8)) * e1 + Real(r.integer(-8, 8)) * e2; };
  for (;;) {
    Pair p{{at(), at(), at()}, {at(), at(), at()}};
    const bool degenerate = (p.t1.b - p.t1.a).cross(p.t1.c - p.t1.a).squaredNorm() == 0 ||
                            (p.t2.b - p.t2.a).cross(p.t2.c - p.t2.a).squaredNorm() == 0;
    if (!degenerate) return p;
  }
}

struct Workload {
  std::string name;
  std::function<Pair(Random&)> make;
};

std::vector<Workload> workloads() {
  return {
      {"random pairs in a box",
       [](Random& r) {
         return Pair{near(r, r.point(-1, 1), 0.5), near(r, r.point(-1, 1), 0.5)};
       }},
      {"leaf pairs (overlapping boxes)",
       [](Random& r) {
         for (;;) {
           Pair p{near(r, r.point(-1, 1), 0.5), near(r, r.point(-1, 1), 0.5)};
           if (boxes_overlap(p.t1, p.t2)) return p;
         }
       }},
      {"shared edge (mesh neighbours)",
       [](Random& r) {
         Pair p{near(r, Vec3::Zero(), 1), near(r, Vec3::Zero(), 1)};
         p.t2.a = p.t1.b;
         p.t2.b = p.t1.a;
         return p;
       }},
      {"coplanar, touching or overlapping", coplanar_pair},
      {"near-coplanar (coplanar, then rotated)",
       [](Random& r) {
         const Pair p = coplanar_pair(r);
         Eigen::Quaternion<Real> q(r.uniform(-1, 1), r.uniform(-1, 1), r.uniform(-1, 1),
                                   r.uniform(-1, 1));
         const Mat3 R = q.normalized().toRotationMatrix();
         return Pair{{R * p.t1.a, R * p.t1.b, R * p.t1.c}, {R * p.t2.a, R * p.t2.b, R * p.t2.c}};
       }},
  };
}

double ns_per_test(const std::vector<Pair>& pairs, bool (*test)(const Tri&, const Tri&),
                   long& hits) {
  const auto start = std::chrono::steady_clock::now();
  long count = 0;
  long repeats = 0;
  double elapsed = 0;
  do {
    for (const Pair& p : pairs) count += test(p.t1, p.t2);
    ++repeats;
    elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  } while (elapsed < 0.2);
  hits = count / repeats;
  return elapsed * 1e9 / (static_cast<double>(repeats) * static_cast<double>(pairs.size()));
}

double median_of_5(const std::vector<Pair>& pairs, bool (*test)(const Tri&, const Tri&),
                   long& hits) {
  std::array<double, 5> runs;
  for (double& run : runs) run = ns_per_test(pairs, test, hits);
  std::sort(runs.begin(), runs.end());
  return runs[2];
}

}  // namespace

int main(int argc, char** argv) {
  const std::string only = argc > 1 ? argv[1] : "";
  constexpr int kPairs = 1 << 16;
  std::printf("%-36s %12s %12s %9s %9s %12s\n", "workload", "exact ns", "plain ns", "ratio", "hits",
              "plain wrong");
  std::uint64_t seed = 7;
  for (const Workload& w : workloads()) {
    Random random(seed++);
    if (w.name.find(only) == std::string::npos) continue;
    std::vector<Pair> pairs;
    pairs.reserve(kPairs);
    for (int i = 0; i < kPairs; ++i) pairs.push_back(w.make(random));
    long exact_hits = 0, plain_hits = 0, wrong = 0;
    const double exact_ns = median_of_5(pairs, exact_triangles_intersect, exact_hits);
    const double plain_ns = median_of_5(pairs, plain_triangles_intersect, plain_hits);
    for (const Pair& p : pairs) {
      wrong += exact_triangles_intersect(p.t1, p.t2) != plain_triangles_intersect(p.t1, p.t2);
    }
    std::printf("%-36s %12.1f %12.1f %9.2f %8.1f%% %11.2f%%\n", w.name.c_str(), exact_ns, plain_ns,
                exact_ns / plain_ns, 100.0 * exact_hits / kPairs, 100.0 * wrong / kPairs);
  }
  return 0;
}
