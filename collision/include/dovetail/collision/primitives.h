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

/// A box with a blind cylindrical hole: the box spans x, z in [-hx, hx] x [-hz, hz]
/// and y in [-hy, hy]; the hole, of radius `hole_radius`, opens in the top face (y = hy)
/// around the y axis and goes `hole_depth` down, with a flat bottom. The hole's wall is a
/// prism of `sides` flat faces whose flats (not corners) lie at hole_radius from the axis,
/// so a cylinder of radius hole_radius fits however coarse the tessellation; the flats face
/// +x, +z, -x and -z when `sides` is a multiple of 4. Closed, outward (the wall's normals
/// point toward the axis). Throws std::invalid_argument when a size is not positive and
/// finite, when the hole does not fit inside the box (the polygon's corner radius
/// hole_radius / cos(pi / sides) >= min(hx, hz)), when hole_depth >= 2 hy, or sides < 3.
/// A tube along z from 0 to `height`: outer and inner walls of `sides` facets
/// each, closed by flat rings at both ends; a washer, a ring or (with 6 sides)
/// a nut with a hexagon socket. The outer wall's corners lie on outer_radius
/// (the tube fits a hole of that radius), the bore's flats on inner_radius
/// (a shaft of that radius fits the bore), as block_with_hole's hole. Throws
/// std::invalid_argument unless 0 < inner < outer, height > 0, sides >= 3 and
/// the bore's corners (inner_radius / cos(pi / sides)) stay inside outer_radius.
Mesh make_tube(Real outer_radius, Real inner_radius, Real height, int sides);

Mesh make_block_with_hole(const Vec3& half_extents, Real hole_radius, Real hole_depth, int sides);

/// Open height field z = amplitude * sin(x * freq) * cos(y * freq) over
/// [-half, half]^2 sampled n x n: many parallel close faces in contact tests.
Mesh make_wavy_sheet(Real half, Real amplitude, Real freq, int n);

}  // namespace dovetail::collision
