#pragma once
// Box frames for the OBB tree. The covariance frame (Gottschalk, Lin,
// Manocha) is a good start but not the tightest box, and near contact a
// traversal tests every pair of boxes that the gap cannot separate, so each
// box's size counts. Every node of nine or more triangles starts from the
// best of its covariance frame, its children's frames and the mesh's frame,
// then turns the frame about its own axes while that shrinks the box (its
// volume, with a little of its area for flat nodes). The search measures
// boxes on a node's support set (its extreme vertices along the 26-DOP's
// directions), which keeps it cheap; the tree then fits each box to all the
// node's vertices in the frame found.

#include <vector>

#include "dovetail/collision/mesh.h"
#include "polygon/binary_layout.h"

namespace dovetail::collision::detail {

/// Axes (columns: orthonormal, right-handed) of every node's box, in the
/// layout's node order.
std::vector<Mat3> fit_box_axes(const BinaryLayout& layout, const Mesh& mesh);

}  // namespace dovetail::collision::detail
