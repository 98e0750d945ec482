#pragma once
/// \file tri_tri.h
/// Exact triangle-triangle intersection test.
///
/// Touching policy: triangles are closed sets. Two triangles collide when
/// they share at least one point, so touching at a vertex, along an edge or
/// over a face counts as colliding. Every decision is the sign of an exact
/// orient3d/orient2d determinant of the input coordinates (Guigue-Devillers),
/// so the verdict is exact for the given coordinates and does not depend on
/// vertex order or on any epsilon.
///
/// Precondition: both triangles are non-degenerate (not collinear). Meshes
/// remove degenerate triangles on construction (see mesh.h); for degenerate
/// input the result is defined (no crash, no UB) but unspecified.

#include "dovetail/collision/types.h"

namespace dovetail::collision {

/// True when closed triangles (p1, q1, r1) and (p2, q2, r2) share a point.
bool triangles_intersect(const Vec3& p1, const Vec3& q1, const Vec3& r1, const Vec3& p2,
                         const Vec3& q2, const Vec3& r2);

}  // namespace dovetail::collision
