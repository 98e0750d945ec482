#pragma once
// Distance between two triangles, the leaf test of the distance and
// tolerance queries (hierarchy and brute force alike).
//
// Two closed triangles that do not intersect are closest at one of 15 feature
// pairs: one of the 3 x 3 edge pairs, or a vertex of one triangle and the
// interior of the other. Whether they intersect is decided by the exact
// triangle test (tri_tri.h), so a distance of 0 means exactly what `collide`
// means by colliding.

#include <array>

#include "dovetail/collision/types.h"

namespace dovetail::collision::detail {

/// A triangle by its three vertices, all in one frame.
using TriangleVertices = std::array<Vec3, 3>;

/// Closest points of two triangles and their distance.
struct TriangleDistance {
  Real distance = 0;
  Vec3 p = Vec3::Zero();  ///< on the first triangle
  Vec3 q = Vec3::Zero();  ///< on the second triangle
};

/// Squared distance between segments [p0, p1] and [q0, q1], with the closest
/// points x (on the first) and y (on the second). Parallel and zero-length
/// segments are handled: the result is then one of the closest pairs.
Real segment_distance_squared(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1,
                              Vec3& x, Vec3& y);

/// Closest point of triangle t to point p.
Vec3 closest_point_on_triangle(const Vec3& p, const TriangleVertices& t);

/// Distance between closed triangles a and b. Exactly 0 when the exact
/// triangle test says they intersect (then p = q is a point near both, found
/// from the edges crossing the other triangle); otherwise the smallest of the
/// 15 feature distances, positive (a computed 0 for disjoint triangles closer
/// than rounding becomes the smallest positive double).
TriangleDistance triangle_distance(const TriangleVertices& a, const TriangleVertices& b);

/// Squared distance of the 15 feature pairs only, with no intersection test:
/// the distance of a and b when they do not intersect. Sets p and q.
Real feature_distance_squared(const TriangleVertices& a, const TriangleVertices& b, Vec3& p,
                              Vec3& q);

}  // namespace dovetail::collision::detail
