// Penetration depth of two convex parts by the separating-axis candidates.
#include <algorithm>
#include <limits>
#include <utility>
#include <vector>

#include "dovetail/collision/convex.h"

namespace dovetail::collision {

namespace {

/// Each hull edge once (a < b), from the vertex adjacency.
std::vector<std::pair<std::uint32_t, std::uint32_t>> hull_edges(const ConvexHull& hull) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
  for (std::uint32_t i = 0; i + 1 < hull.neighbor_offsets.size(); ++i) {
    for (std::uint32_t k = hull.neighbor_offsets[i]; k < hull.neighbor_offsets[i + 1]; ++k) {
      if (i < hull.neighbors[k]) edges.emplace_back(i, hull.neighbors[k]);
    }
  }
  return edges;
}

}  // namespace

std::optional<PenetrationDepth> convex_penetration_depth(const ConvexHull& a, const ConvexHull& b,
                                                         const Transform& X_AB,
                                                         std::size_t max_edge_pairs) {
  if (a.vertices.empty() || b.vertices.empty()) return std::nullopt;
  const auto edges_a = hull_edges(a), edges_b = hull_edges(b);
  if (edges_a.size() * edges_b.size() > max_edge_pairs) return std::nullopt;
  // B's vertices and edge directions in A's frame.
  std::vector<Vec3> vb(b.vertices.size());
  for (std::size_t i = 0; i < vb.size(); ++i) vb[i] = X_AB.apply(b.vertices[i]);
  PenetrationDepth best;
  best.depth = std::numeric_limits<Real>::infinity();
  std::uint32_t start_a = 0, start_b = 0;
  // How far B must move along unit n to leave A: max over A of n.x minus min over B.
  const auto try_direction = [&](Vec3 n) {
    const Real length = n.norm();
    if (!(length > 1e-12)) return;
    n /= length;
    for (int side = 0; side < 2; ++side, n = -n) {
      start_a = a.support(n, start_a);
      start_b = b.support(X_AB.R.transpose() * -n, start_b);
      const Real overlap = n.dot(a.vertices[start_a]) - n.dot(vb[start_b]);
      if (overlap < best.depth) {
        best.depth = overlap;
        best.normal = n;
      }
    }
  };
  for (const TriangleIndices& f : a.faces) {
    try_direction((a.vertices[f[1]] - a.vertices[f[0]]).cross(a.vertices[f[2]] - a.vertices[f[0]]));
  }
  for (const TriangleIndices& f : b.faces) {
    try_direction((vb[f[1]] - vb[f[0]]).cross(vb[f[2]] - vb[f[0]]));
  }
  for (const auto& [i, j] : edges_a) {
    const Vec3 ea = a.vertices[j] - a.vertices[i];
    for (const auto& [k, l] : edges_b) try_direction(ea.cross(vb[l] - vb[k]));
  }
  if (!(best.depth > 0)) best.depth = 0;  // apart or touching along some direction
  return best;
}

}  // namespace dovetail::collision
