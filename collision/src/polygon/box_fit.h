#pragma once
// Box frames for the OBB tree. The covariance frame (Gottschalk, Lin,
// Manocha) is a good start but not the tightest box, and near contact a
// traversal tests every pair of boxes that the gap cannot separate, so each
// box's size counts. Every node of 16 or more triangles starts from the
// best of its covariance frame, its children's frames and the mesh's frame,
// then turns the frame about its own axes while that shrinks the box (its
// volume, with a little of its area for flat nodes). The search measures
// boxes on a node's support set (its extreme vertices along the 26-DOP's
// directions), which keeps it cheap; the tree then fits each box to all the
// node's vertices in the frame found, and the searched frame is kept only
// where that box is smaller than the covariance frame's.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "dovetail/collision/mesh.h"
#include "polygon/binary_layout.h"

namespace dovetail::collision::detail {

/// Nodes with fewer triangles keep their covariance frame (a single
/// triangle, its own). Searching from nine triangles up saved two more of
/// the bunny's volume tests a query (159 against 161) for about 50% more
/// build time.
inline constexpr int kBoxSearchMinTriangles = 16;

/// A node's box: its axes (columns: orthonormal, right-handed) and the
/// extent of the node's vertices along them.
struct FittedBox {
  Mat3 axes = Mat3::Identity();
  Vec3 lo = Vec3::Zero();  ///< in the box's frame
  Vec3 hi = Vec3::Zero();
};

/// The 26-DOP's directions, one of each opposite pair: a node's extreme
/// vertices along them stand for it in a frame search.
extern const std::array<Vec3, 13> kBoxSearchDirections;

/// What a frame search minimises for a box of edges `e`: its volume, plus a
/// little of its surface area times its edge sum so that a flat set (no
/// volume in any frame that holds its plane) still prefers the tighter
/// rectangle.
Real box_search_cost(const Vec3& e);

/// The best of `start` and `others` for the box of the `support` vertices,
/// turned about its own axes while that shrinks the box (turns of 0.3, 0.1,
/// 0.03 and 0.01 rad, at most four steps of each); orthonormal, right-handed.
Mat3 search_box_frame(const Mesh& mesh, const Mat3& start, std::span<const Mat3> others,
                      std::span<const std::uint32_t> support);

/// Every node's box, in the layout's node order. A searched box is kept only
/// where it is smaller than the covariance frame's, measured on all the
/// node's vertices.
std::vector<FittedBox> fit_boxes(const BinaryLayout& layout, const Mesh& mesh);

}  // namespace dovetail::collision::detail
