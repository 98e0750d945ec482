#pragma once
/// \file mesh.h
/// Triangle mesh with validation.
///
/// Why: every hierarchy, every query and every report works on this one plain
/// struct. A Mesh that exists has passed validation: finite coordinates,
/// indices in range, at least one triangle, sizes within limits, and no
/// degenerate (zero-area) triangles, which are removed and counted.

#include <cstddef>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "dovetail/collision/types.h"

namespace dovetail::collision {

/// A validated triangle mesh: vertex positions in the part's own frame and
/// counter-clockwise triangles (orientation is kept but not relied on).
struct Mesh {
  std::vector<Vec3> vertices;
  std::vector<TriangleIndices> triangles;
  std::string source;  ///< file or generator the mesh came from, for messages

  std::size_t triangle_count() const { return triangles.size(); }
  std::size_t vertex_count() const { return vertices.size(); }
};

/// Limits checked by validation; inputs beyond them are rejected, not truncated.
struct MeshLimits {
  std::size_t max_vertices = std::size_t{1} << 26;   ///< 67,108,864
  std::size_t max_triangles = std::size_t{1} << 26;  ///< 67,108,864
  Real max_abs_coordinate = 1e30;                    ///< keeps exact predicates free of overflow
};

/// What validation found and repaired.
struct MeshValidation {
  std::size_t input_vertices = 0;
  std::size_t input_triangles = 0;
  std::size_t degenerate_removed = 0;  ///< zero-area triangles dropped
  std::size_t unused_vertices = 0;     ///< vertices no triangle references (kept)
};

/// Thrown for input that cannot become a Mesh. what() names the source.
class MeshError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Builds a validated Mesh, throwing MeshError (message starts with `source`)
/// for non-finite or over-limit coordinates, out-of-range indices, an empty
/// mesh (no vertices, no triangles, or only degenerate triangles), or sizes
/// over the limits. Degenerate triangles are removed and counted in
/// `validation` when it is given.
Mesh make_mesh(std::vector<Vec3> vertices, std::vector<TriangleIndices> triangles,
               std::string source, const MeshLimits& limits = {},
               MeshValidation* validation = nullptr);

/// Throws MeshError (message starts with mesh.source) for a mesh the
/// hierarchies cannot take: no triangles, a coordinate that is not finite,
/// or an index out of range. For a mesh built by hand rather than by
/// make_mesh; no coordinate or size limit is applied (the importer chooses
/// those), and degenerate triangles are allowed.
void check_mesh(const Mesh& mesh);

/// For each vertex, the smallest index of a vertex at exactly the same
/// position (equal coordinates, so -0 is 0): vertices welded by equality,
/// never by distance.
std::vector<std::uint32_t> welded_ids(std::span<const Vec3> vertices);

/// Axis-aligned bounds of all vertices.
struct Bounds {
  Vec3 min;
  Vec3 max;
};
Bounds mesh_bounds(const Mesh& mesh);
/// Bounds of the 8 corners of `local` moved by X_WP: a box that contains
/// whatever `local` contains, in the frame W.
Bounds transformed_bounds(const Bounds& local, const Transform& X_WP);

}  // namespace dovetail::collision
