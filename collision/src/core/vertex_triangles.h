#pragma once
// The triangles around each vertex of a mesh, for walks over its surface:
// following a moving contact to a neighbouring triangle, growing a contact
// patch, walking a region bounded by an intersection curve.

#include <cstdint>
#include <numeric>
#include <vector>

#include "dovetail/collision/mesh.h"

namespace dovetail::collision::detail {

/// Triangles around each vertex, in compressed rows: those of vertex v are
/// triangles[offsets[v] .. offsets[v + 1]), in increasing order.
struct VertexTriangles {
  std::vector<std::uint32_t> offsets;
  std::vector<std::uint32_t> triangles;

  VertexTriangles() = default;
  explicit VertexTriangles(const Mesh& mesh) : offsets(mesh.vertices.size() + 1, 0) {
    for (const TriangleIndices& f : mesh.triangles) {
      for (std::uint32_t v : f) ++offsets[v + 1];
    }
    std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
    triangles.resize(offsets.back());
    std::vector<std::uint32_t> fill(offsets.begin(), offsets.end() - 1);
    for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
      for (std::uint32_t v : mesh.triangles[t]) triangles[fill[v]++] = t;
    }
  }

  /// Calls visit(t) for every triangle sharing a vertex with `f` (f's own included).
  template <typename Visit>
  void around(const TriangleIndices& f, Visit&& visit) const {
    for (std::uint32_t v : f) {
      for (std::uint32_t k = offsets[v]; k < offsets[v + 1]; ++k) visit(triangles[k]);
    }
  }
};

}  // namespace dovetail::collision::detail
