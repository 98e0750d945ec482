#pragma once
/// \file primitives.h
/// Generated meshes: built-in parts for the default job, tests and benchmarks.
/// All are closed, consistently oriented (outward normals) triangle meshes.

#include "dovetail/collision/mesh.h"

namespace dovetail::collision {

/// Axis-aligned box centred at the origin with the given half extents.
Mesh make_box(const Vec3& half_extents);

/// Geodesic sphere: an icosahedron subdivided `subdivisions` times
/// (20 * 4^subdivisions triangles), vertices on the sphere of `radius`.
Mesh make_sphere(Real radius, int subdivisions);

/// Torus around the z axis: `major` ring radius, `minor` tube radius,
/// `rings` x `sides` quads, two triangles each.
Mesh make_torus(Real major, Real minor, int rings, int sides);

/// Closed cylinder along z from z = 0 to z = `height`, `sides` facets.
Mesh make_cylinder(Real radius, Real height, int sides);

/// Open height field z = amplitude * sin(x * freq) * cos(y * freq) over
/// [-half, half]^2 sampled n x n: many parallel close faces in contact tests.
Mesh make_wavy_sheet(Real half, Real amplitude, Real freq, int n);

}  // namespace dovetail::collision
