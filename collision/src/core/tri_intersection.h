#pragma once
/// \file tri_intersection.h
/// The intersection geometry of one intersecting triangle pair, the piece
/// that contact patches are assembled from (see contacts.h).
///
/// Why: the triangle test (tri_tri.h) only answers yes or no. Contacts need
/// where and how the two surfaces meet: a segment where they cross or touch
/// transversally, a polygon where they lie in one plane. This code only
/// measures the pair it is given, so rounding here can shrink or grow a piece
/// by a few ulps; which pairs are measured is decided elsewhere (the exact
/// test, plus the nearly coplanar pairs contacts.cpp adds on purpose).

#include <array>
#include <vector>

#include "dovetail/collision/types.h"

namespace dovetail::collision::detail {

/// Three vertices of a triangle, all in one frame (A's).
using TriangleVertices = std::array<Vec3, 3>;

/// The intersection of closed triangles T_a and T_b, in A's frame.
struct TrianglePiece {
  /// Coplanar pieces: the overlap polygon (counter-clockwise about n_a; two
  /// points when it degenerates to a segment, one for a point). Transversal
  /// pieces: the two end points of the segment (equal for a point).
  std::vector<Vec3> points;
  Vec3 n_a = Vec3::UnitZ();  ///< unit outward normal of T_a
  Vec3 n_b = Vec3::UnitZ();  ///< unit outward normal of T_b, in A's frame
  /// The piece's contact normal, unit, pointing from A to B (see contacts.h).
  Vec3 normal = Vec3::UnitZ();
  Vec3 centroid = Vec3::Zero();  ///< area centroid (polygons) or midpoint
  Real area = 0;                 ///< polygon area; 0 for segments and points
  Real length = 0;               ///< segment length (longest extent of a degenerate polygon)
  /// Share of the segment this pair owns: a segment along a mesh edge is
  /// found once for each of the edge's two triangles, so it counts half for
  /// each (a quarter when it lies on an edge of both meshes).
  Real share = 1;
  bool coplanar = false;  ///< the triangles were treated as lying in one plane
  bool opposed = false;   ///< coplanar with opposite normals: face on face
};

/// Geometry of a pair that triangles_intersect() reported. Triangles are
/// treated as coplanar when every vertex of each lies within
/// `coplanar_tolerance` of the other's plane (or exactly in it).
TrianglePiece intersect_triangles(const TriangleVertices& t_a, const TriangleVertices& t_b,
                                  Real coplanar_tolerance);

/// Distance between two pieces (0 when they meet). Exact up to rounding for
/// segments and points; for polygons it is the smallest distance between
/// their edges and from the vertices of one to the other, which is the true
/// distance unless a piece crosses another polygon's interior transversally
/// (a self-intersecting surface).
Real piece_distance(const TrianglePiece& p, const TrianglePiece& q);

}  // namespace dovetail::collision::detail
