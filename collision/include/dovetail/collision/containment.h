#pragma once
/// \file containment.h
/// Point in closed mesh, and whether one part lies fully inside another.
///
/// Why: a part dropped inside a housing, or swallowed whole by a grasp
/// volume, has no intersecting triangles, so the collision query reports
/// nothing. When the surfaces do not meet, each connected shell of a part is
/// inside the other exactly when one of its points is, and that is decided
/// exactly: a winding number counted along a ray with orient3d signs only.
/// See docs/proximity.md, "Containment".

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "dovetail/collision/mesh.h"
#include "dovetail/collision/model.h"
#include "dovetail/collision/types.h"

namespace dovetail::collision {

/// True when every edge of `mesh` is used as often in one direction as in
/// the other by its triangles: a closed, consistently oriented surface, or
/// several, which may share edges and vertices (bodies that touch, exported
/// as one mesh). Vertices at equal positions count as one, so meshes with
/// split vertices are judged by their geometry.
bool is_closed(const Mesh& mesh);

/// How a mesh's triangles meet along their edges, counted per edge (its two
/// vertices, welded by position as in is_closed). A mesh with at least one
/// triangle is closed exactly when both counts are 0.
struct SurfaceEdges {
  /// Edges on an odd number of triangles (usually one): the rim of a hole or
  /// of a missing face, so the surface has no inside there.
  std::size_t open = 0;
  /// Edges on an even number of triangles, but not as many running each
  /// way: neighbours wound opposite ways, so their normals disagree on which
  /// side is inside.
  std::size_t misoriented = 0;
  bool closed() const { return open == 0 && misoriented == 0; }
};

/// What keeps `mesh` from being closed (is_closed), edge by edge, so that a
/// warning can say how much of a part's surface is wrong.
SurfaceEdges surface_edges(const Mesh& mesh);

/// Where a point lies against a closed mesh.
enum class PointLocation {
  kOutside,
  kInside,     ///< inside the solid: odd number of surface crossings to infinity
  kOnSurface,  ///< on a triangle (closed), decided exactly
};

/// Exact location of `p_M` (in the mesh's frame) against closed `mesh`, by
/// the winding number of the surface about it: signed crossings of a
/// segment from the point to beyond the mesh's bounds, inside when not 0.
/// Every decision is an exact orient3d sign; a segment that grazes an edge
/// or vertex, or lies in a triangle's plane, is discarded and the next of a
/// fixed list of directions is tried, so the answer is exact and
/// deterministic. For an open mesh the answer is unspecified (see
/// is_closed).
PointLocation locate_point(const Mesh& mesh, const Vec3& p_M);

/// locate_point(mesh, p_M) != kOutside: the closed solid contains the point.
bool point_inside(const Mesh& mesh, const Vec3& p_M);

/// locate_point for many points against one mesh: the mesh's closedness is
/// found once, in the constructor. The mesh is placed in a frame
/// F by X_FM (its vertices mapped by X_FM.apply, as the collision query maps
/// B's), and points are given in F, so a point and the surface it is tested
/// against are rounded the same way the collision query rounded them.
class PointLocator {
 public:
  explicit PointLocator(const Mesh& mesh, const Transform& X_FM = {});
  /// is_closed(mesh).
  bool closed() const { return closed_; }
  /// Where p_F lies against the placed mesh (locate_point in frame F).
  PointLocation locate(const Vec3& p_F) const;

 private:
  const Mesh& mesh_;
  std::vector<Vec3> vertices_F_;
  bool closed_ = false;
  std::vector<std::uint32_t> shell_;  ///< all 0: a location needs no shells
  std::size_t shell_count_ = 0;
  /// The placed triangles' bounding boxes: a ray tests only the triangles
  /// whose box it meets (exact all the same: the others cannot be crossed).
  struct Boxes;
  std::shared_ptr<const Boxes> boxes_;
};

/// Three-valued answer: an open mesh has no inside.
enum class Inside { kNo, kYes, kUnknown };

/// Containment of two parts, `inner` at pose X_outer_inner in outer's frame.
struct ContainmentResult {
  /// The surfaces share a point (touching included): neither part is then
  /// contained in the other; the contact is reported by compute_contacts.
  bool surfaces_intersect = false;
  /// Inner lies in outer's solid (its whole surface strictly inside).
  /// kUnknown when outer is not closed.
  Inside inner_in_outer = Inside::kUnknown;
  /// Outer lies in inner's solid. kUnknown when inner is not closed.
  Inside outer_in_inner = Inside::kUnknown;
  /// Inner lies inside some shell of outer, in its solid or in a cavity the
  /// shell encloses (a part inside a hollow housing). kUnknown when outer is
  /// not closed.
  Inside inner_enclosed_by_outer = Inside::kUnknown;
  /// The same for outer inside a shell of inner.
  Inside outer_enclosed_by_inner = Inside::kUnknown;
};

/// Containment of meshes `outer` and `inner` (inner at X_outer_inner). The
/// surfaces are tested with every triangle pair through an AABB tree built
/// for the call; pass models to reuse built ones.
ContainmentResult contains(const Mesh& outer, const Mesh& inner, const Transform& X_outer_inner);

/// The same with built models (any method, both the same).
ContainmentResult contains(const CollisionModel& outer, const CollisionModel& inner,
                           const Transform& X_outer_inner);

}  // namespace dovetail::collision
