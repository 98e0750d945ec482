/// \file gjk.cpp
/// GJK distance between two convex hulls (Gilbert, Johnson and Keerthi), with
/// the signed-volume sub-distance of Montanari, Petrinic and Barbieri (2017)
/// and a warm start from the previous call's simplex.
///
/// The Minkowski difference M = A - B (B brought into A's frame with
/// X_AB.apply) is explored through support pairs; v is the point of the
/// current simplex nearest the origin, an upper bound |v| on the distance,
/// and the support point w of M in direction -v gives the lower bound
/// (v . w) / |v|. Stops when
///  * the simplex is a tetrahedron holding the origin, or |v| is at most the
///    touching band kGjkContactTolerance * scale: intersecting;
///  * |v|^2 - v . w <= kGjkRelativeTolerance |v|^2: converged;
///  * w is already a simplex vertex, or the new simplex is no nearer the
///    origin than the old one (rounding has taken over): converged;
///  * kGjkMaxIterations support pairs were used (reported).
/// Every candidate simplex point is a difference of two hull points, so |v|
/// never underestimates the distance by more than rounding.

#include <algorithm>
#include <array>
#include <cmath>

#include "convex/convex_internal.h"
#include "convex/convex_simplex.h"
#include "dovetail/collision/convex.h"

namespace dovetail::collision {

using detail::Nearest;
using detail::Simplex;
using detail::SimplexPoint;

namespace {

/// The distinct vertex indices among `count` (1 to 3) simplex points,
/// ascending: the feature they span.
HullFeature feature_of(const std::array<std::uint32_t, 3>& indices, int count) {
  HullFeature feature;
  int size = 0;
  for (int k = 0; k < count; ++k) {
    // Insert indices[k] into the sorted distinct prefix, unless already there.
    int at = 0;
    while (at < size && feature.vertices[at] < indices[k]) ++at;
    if (at < size && feature.vertices[at] == indices[k]) continue;
    for (int m = size; m > at; --m) feature.vertices[m] = feature.vertices[m - 1];
    feature.vertices[at] = indices[k];
    ++size;
  }
  feature.type = static_cast<FeatureType>(size);
  return feature;
}

}  // namespace

GjkResult gjk(const ConvexHull& a, const ConvexHull& b, const Transform& X_AB, GjkCache* cache) {
  GjkResult result;
  // Non-finite pose or empty hulls: a conservative, finite answer.
  if (!X_AB.R.allFinite() || !X_AB.t.allFinite() || a.vertices.empty() || b.vertices.empty()) {
    result.intersecting = true;
    return result;
  }
  const Mat3& R = X_AB.R;
  const Real scale = a.extent + b.extent + X_AB.t.cwiseAbs().maxCoeff();
  const Real contact = kGjkContactTolerance * scale;
  const auto na = static_cast<std::uint32_t>(a.vertices.size());
  const auto nb = static_cast<std::uint32_t>(b.vertices.size());

  auto make_point = [&](std::uint32_t ia, std::uint32_t ib) {
    return detail::simplex_point(a.vertices, b.vertices, X_AB, ia, ib,
                                 detail::Difference::kAMinusB);
  };
  // Support pair of M = A - B in direction -v: A lowest along v, B highest.
  std::uint32_t last_a = 0, last_b = 0;
  auto support = [&](const Vec3& v) {
    last_a = detail::hull_support(a, -v, last_a);
    last_b = detail::hull_support(b, R.transpose() * v, last_b);
    return make_point(last_a, last_b);
  };

  // Start from the cached simplex, else from one support pair.
  Simplex simplex;
  if (cache && cache->valid) {
    last_a = cache->support_a < na ? cache->support_a : 0;
    last_b = cache->support_b < nb ? cache->support_b : 0;
    simplex.load(cache->simplex_a, cache->simplex_b, cache->simplex_size, na, nb, make_point);
    if (simplex.size == 0) simplex.add(make_point(last_a, last_b));
  } else {
    const Vec3 v0 = a.center - X_AB.apply(b.center);
    simplex.add(support(v0 == Vec3::Zero() ? Vec3(Vec3::UnitX()) : v0));
    result.iterations = 1;
  }
  Nearest current = simplex.nearest();
  simplex.reduce(current);

  for (;;) {
    // Origin inside a tetrahedron, or within the touching band.
    if (simplex.size == 4 || !(current.vv > contact * contact)) {
      result.intersecting = true;
      break;
    }
    if (result.iterations >= kGjkMaxIterations) {
      result.hit_iteration_cap = true;
      break;
    }
    const SimplexPoint w = support(current.v);
    ++result.iterations;
    // Upper bound |v| and lower bound (v . w) / |v| agree: converged.
    if (current.vv - current.v.dot(w.w) <= kGjkRelativeTolerance * current.vv) break;
    if (simplex.contains(w.ia, w.ib)) break;
    // Add w; keep the sub-simplex nearest the origin, if it is nearer.
    Simplex next = simplex;
    next.add(w);
    const Nearest candidate = next.nearest();
    if (!(candidate.vv < current.vv)) break;
    next.reduce(candidate);
    simplex = next;
    current = candidate;
  }

  // Closest points from the barycentric weights.
  Vec3 pa = Vec3::Zero(), pb = Vec3::Zero();
  for (int k = 0; k < simplex.size; ++k) {
    pa += simplex.lambda[k] * simplex.p[k].a;
    pb += simplex.lambda[k] * simplex.p[k].b;
  }
  result.closest_a = pa;
  result.closest_b = pb;
  result.distance = result.intersecting ? 0 : std::sqrt(current.vv);
  // Closest features: the support pairs of a final simplex of one to three
  // points (every one of them carries positive weight); none for a
  // tetrahedron holding the origin.
  if (simplex.size >= 1 && simplex.size <= 3) {
    std::array<std::uint32_t, 3> ia{}, ib{};
    for (int k = 0; k < simplex.size; ++k) {
      ia[k] = simplex.p[k].ia;
      ib[k] = simplex.p[k].ib;
    }
    result.feature_a = feature_of(ia, simplex.size);
    result.feature_b = feature_of(ib, simplex.size);
  }
  if (!result.closest_a.allFinite() || !result.closest_b.allFinite() ||
      !std::isfinite(result.distance)) {
    // Overflow in the arithmetic (coordinates near the double range): be conservative.
    result.intersecting = true;
    result.distance = 0;
    result.closest_a = result.closest_b = Vec3::Zero();
    result.feature_a = result.feature_b = HullFeature{};
  }

  if (cache) {
    cache->valid = true;
    cache->support_a = last_a;
    cache->support_b = last_b;
    cache->direction = current.v;
    simplex.store(cache->simplex_a, cache->simplex_b, cache->simplex_size);
  }
  return result;
}

}  // namespace dovetail::collision
