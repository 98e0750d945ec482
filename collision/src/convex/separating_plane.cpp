/// \file separating_plane.cpp
/// The separating-plane test of the convex level: re-check last frame's plane
/// with one support query per hull, else search a plane by the perceptron
/// rule, and certify every "separated" answer with a rounding-error bound.
///
/// Search. A plane with normal n separates A from B when the gap
/// min_B n . y - max_A n . x is positive; the two extremes are support
/// queries, and w = y* - x* (B's lowest vertex minus A's highest) is the pair
/// the plane classifies worst. The perceptron rule moves the normal towards
/// that pair, n <- n + lambda (w - n). Here the step is fully corrective: n
/// becomes the point nearest the origin of the hull of w and the worst pairs
/// that still carry weight (at most four, Gilbert's and GJK's sub-problem,
/// solved by signed volumes), so n stays a point of the Minkowski difference
/// B - A and its length falls towards the distance of the hulls; once n
/// points into the cone of separating directions, the gap is positive. The
/// plain perceptron step (lambda on the segment alone) zig-zags between the
/// vertices of nearly parallel faces; with the corrective step, separated
/// random pairs need a handful of iterations down to gaps of 10^-3 of their
/// size (docs/convex.md). When four pairs enclose the origin, the hulls
/// overlap: the search gives up and keeps the four pairs as a witness that
/// the next test re-checks before anything else.
///
/// Proof of "separated". With u = 2^-53, rA = a.extent, rB = b.extent,
/// d = fl(-R^T n) and q* = b.support(d) (the exact maximiser of d . q),
/// x* = a.support(n):
///   every x of hull A:  n . x <= n . x* <= hA + g3 |n|_1 rA,  hA = fl(n . x*);
///   every q of hull B, y = X_AB.apply(q) as the polygon level computes it:
///     |y_i - (R q + t)_i| <= g4 (sum_j |R_ij| |q_j| + |t_i|),
///     (R^T n) . q >= -d . q - g3 SR rB  with SR = sum_ij |n_i| |R_ij|,
///     -d . q >= -d . q* >= -fl(d . q*) - g3 |d|_1 rB,
///   so n . y >= hB - (g3 + g4)(SR rB + Nt) - g3 |d|_1 rB - u |hB|,
///   hB = fl(fl(n . t) - fl(d . q*)), Nt = sum |n_i t_i|.
/// "Separated" requires fl(hB - hA) > 8u (|n|_1 rA + SR rB + |d|_1 rB + Nt +
/// |hA| + |hB|) + 64 * 2^-1074, which exceeds (1 + u) times the sum of both
/// bounds (g3 <= 3.01u, g4 <= 4.01u). Then every vertex of A's mesh lies
/// strictly below and every transformed vertex of B's mesh strictly above the
/// plane n . p = (hA + hB) / 2, hence so do both meshes: no triangle pair can
/// touch. The support queries are exact maxima (convex_internal.h) and the
/// hulls contain their points exactly (convex_hull.cpp).

#include <algorithm>
#include <cmath>
#include <limits>

#include "convex/convex_internal.h"
#include "convex/convex_simplex.h"
#include "dovetail/collision/convex.h"

namespace dovetail::collision {

namespace {

constexpr Real kUnit = 0x1p-53;

/// d = fl(-R^T n), B's search direction in its own frame.
inline Vec3 minus_rotated_back(const Mat3& R, const Vec3& n) {
  return Vec3(-((R(0, 0) * n.x() + R(1, 0) * n.y()) + R(2, 0) * n.z()),
              -((R(0, 1) * n.x() + R(1, 1) * n.y()) + R(2, 1) * n.z()),
              -((R(0, 2) * n.x() + R(1, 2) * n.y()) + R(2, 2) * n.z()));
}

inline Real norm1(const Vec3& v) { return std::abs(v.x()) + std::abs(v.y()) + std::abs(v.z()); }

using detail::Nearest;
using detail::Simplex;
using detail::SimplexPoint;

}  // namespace

SeparatingPlaneResult separating_plane_test(const ConvexHull& a, const ConvexHull& b,
                                            const Transform& X_AB, SeparatingPlaneCache& cache,
                                            const SeparatingPlaneSettings& settings) {
  SeparatingPlaneResult result;
  if (!X_AB.R.allFinite() || !X_AB.t.allFinite() || a.vertices.empty() || b.vertices.empty()) {
    result.gave_up = true;
    return result;
  }
  const Mat3& R = X_AB.R;
  const Vec3& t = X_AB.t;
  const auto na = static_cast<std::uint32_t>(a.vertices.size());
  const auto nb = static_cast<std::uint32_t>(b.vertices.size());
  const Real contact = kSeparatingPlaneContact * (a.radius + b.radius);
  auto make_point = [&](std::uint32_t ia, std::uint32_t ib) {
    return detail::simplex_point(a.vertices, b.vertices, X_AB, ia, ib,
                                 detail::Difference::kBMinusA);
  };

  // Last call's simplex at the new pose: loaded first when it is an overlap
  // witness, which settles the test without a support query while it still
  // encloses the origin; otherwise only when the cached normal fails.
  Simplex simplex;
  Nearest current;
  bool loaded = false;
  auto load = [&]() {
    loaded = true;
    if (cache.valid) {
      simplex.load(cache.simplex_a, cache.simplex_b, cache.simplex_size, na, nb, make_point);
    }
    if (simplex.size > 0) {
      current = simplex.nearest();
      if (current.count < 4) simplex.reduce(current);
    }
  };
  if (cache.valid && cache.simplex_size == 4) {
    load();
    if (current.count == 4) {
      result.gave_up = result.overlap = result.witness_hit = true;
      return result;
    }
  }

  // Start from last frame's normal, else from the direction between the centres.
  Vec3 n = cache.valid ? cache.normal : Vec3(X_AB.apply(b.center) - a.center);
  if (!n.allFinite() || n == Vec3::Zero()) n = Vec3::UnitX();
  std::uint32_t ia = cache.support_a < na ? cache.support_a : 0;
  std::uint32_t ib = cache.support_b < nb ? cache.support_b : 0;
  const Mat3 R_abs = R.cwiseAbs();
  const Vec3 t_abs = t.cwiseAbs();
  const bool warm = cache.valid;
  Real hA = 0, hB = 0;

  const int max_iterations = std::max(1, settings.max_iterations);
  for (int iteration = 1;; ++iteration) {
    result.iterations = iteration;
    // Support pair: A's highest vertex along n, B's lowest.
    ia = detail::hull_support(a, n, ia);
    const Vec3 d = minus_rotated_back(R, n);
    ib = detail::hull_support(b, d, ib);
    hA = detail::dot(n, a.vertices[ia]);
    hB = detail::dot(n, t) - detail::dot(d, b.vertices[ib]);

    // Certified gap (see the file comment).
    const Vec3 n_abs = n.cwiseAbs();
    const Real SR = (R_abs.transpose() * n_abs).sum();
    const Real bound = 8 * kUnit *
                           (norm1(n) * a.extent + (SR + norm1(d)) * b.extent + n_abs.dot(t_abs) +
                            std::abs(hA) + std::abs(hB)) +
                       64 * std::numeric_limits<Real>::denorm_min();
    if (hB - hA > bound) {
      result.separated = true;
      result.cache_hit = warm && iteration == 1;
      break;
    }
    if (iteration >= max_iterations) break;

    // Perceptron step, fully corrective: n becomes the point nearest the
    // origin of the hull of the pairs in use and the new worst pair.
    if (!loaded) load();
    if (iteration == 1 && simplex.size > 0) {
      // The cached normal failed; continue from the cached simplex instead.
    } else if (simplex.size == 0) {
      simplex.add(make_point(ia, ib));
      current = simplex.nearest();
    } else {
      // The pair is already in use: n cannot be shortened any more.
      if (simplex.contains(ia, ib)) break;
      Simplex next = simplex;
      next.add(make_point(ia, ib));
      const Nearest candidate = next.nearest();
      if (candidate.count == 4) {
        // The origin is enclosed: the hulls overlap. Keep the witness.
        simplex = next;
        result.overlap = true;
        break;
      }
      if (!(candidate.vv < current.vv)) break;
      next.reduce(candidate);
      simplex = next;
      current = candidate;
    }
    // Hulls within `contact` of each other (a point of B - A that short): stop.
    if (!(current.vv > contact * contact)) break;
    n = current.v;
  }
  result.gave_up = !result.separated;

  // Keep the plane (or the last candidate), the support vertices and the simplex.
  const Real length = n.norm();
  if (length > 0 && std::isfinite(length)) {
    cache.normal = n / length;
    cache.offset = 0.5 * (hA + hB) / length;
  }
  cache.valid = true;
  cache.support_a = ia;
  cache.support_b = ib;
  simplex.store(cache.simplex_a, cache.simplex_b, cache.simplex_size);
  return result;
}

}  // namespace dovetail::collision
