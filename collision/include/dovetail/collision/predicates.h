#pragma once
/// \file predicates.h
/// Exact geometric predicates on double coordinates: a floating-point filter
/// with a proven error bound, falling back to exact expansion arithmetic when
/// the filter cannot decide. The sign returned is the sign of the exact
/// determinant of the given (already rounded) input coordinates.

#include "dovetail/collision/types.h"

namespace dovetail::collision {

/// Sign (+1, 0, -1) of det[b - a, c - a, d - a] = ((b - a) x (c - a)) . (d - a).
/// Positive when d lies on the side of plane (a, b, c) that its normal
/// (b - a) x (c - a) points to.
int orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

/// Sign (+1, 0, -1) of (b - a) x (c - a) for 2-D points: +1 when a, b, c turn
/// counter-clockwise.
int orient2d(Real ax, Real ay, Real bx, Real by, Real cx, Real cy);

/// True when a, b, c are exactly collinear (including coincident points): the
/// triangle has zero area.
bool is_degenerate_triangle(const Vec3& a, const Vec3& b, const Vec3& c);

}  // namespace dovetail::collision
