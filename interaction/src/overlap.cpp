#include "dovetail/interaction/overlap.h"

#include <algorithm>
#include <cstddef>
#include <stdexcept>

#include "dovetail/collision/contacts.h"
#include "dovetail/collision/containment.h"

namespace dovetail::interaction {

std::optional<std::string> surface_flaw(const collision::Mesh& mesh) {
  const collision::SurfaceEdges edges = collision::surface_edges(mesh);
  if (edges.closed()) return std::nullopt;
  const auto count = [](std::size_t n, const char* what) {
    return std::to_string(n) + " " + what + (n == 1 ? " edge" : " edges");
  };
  std::string text;
  if (edges.open > 0) text = count(edges.open, "open") + " (a hole or a missing face)";
  if (edges.misoriented > 0) {
    if (!text.empty()) text += " and ";
    text +=
        count(edges.misoriented, "wrongly wound") + " (neighbouring faces facing opposite ways)";
  }
  return text;
}

Real OverlapGauge::depth(const std::shared_ptr<const collision::Mesh>& a, const Transform& X_WA,
                         const std::shared_ptr<const collision::Mesh>& b, const Transform& X_WB) {
  const Transform X_AB{X_WA.R.transpose() * X_WB.R, X_WA.R.transpose() * (X_WB.t - X_WA.t)};
  // Two convex parts: the exact penetration depth, which no vertex depth
  // exceeds, and which also sees a part inside the other without a vertex
  // deeper than its surface (a pebble under a peg, sharing its bottom face).
  const collision::ConvexHull* hull_a = convex_hull(a);
  const collision::ConvexHull* hull_b = hull_a ? convex_hull(b) : nullptr;
  if (hull_a && hull_b) {
    if (const auto pd = collision::convex_penetration_depth(*hull_a, *hull_b, X_AB)) {
      return pd->depth;
    }
  }
  Real deepest = 0;
  for (const collision::ContactPatch& patch :
       collision::compute_contacts(*model(a), *model(b), X_AB)) {
    deepest = std::max(deepest, patch.depth);
  }
  return deepest;
}

const std::shared_ptr<const collision::CollisionModel>& OverlapGauge::model(
    const std::shared_ptr<const collision::Mesh>& mesh) {
  auto& slot = models_[mesh.get()];
  if (!slot) slot = collision::build_model(collision::Method::kObb, mesh);
  return slot;
}

const collision::ConvexHull* OverlapGauge::convex_hull(
    const std::shared_ptr<const collision::Mesh>& mesh) {
  const auto [it, fresh] = hulls_.try_emplace(mesh.get());
  if (fresh) {
    try {
      auto hull = std::make_shared<const collision::ConvexHull>(
          collision::compute_convex_hull(mesh->vertices, mesh->source));
      if (collision::is_closed(*mesh) &&
          collision::surface_on_hull(*hull, mesh->vertices, mesh->triangles)) {
        it->second = std::move(hull);
      }
    } catch (const std::invalid_argument&) {
      // A flat part has no hull: the contact depth is all there is.
    }
  }
  return it->second.get();
}

}  // namespace dovetail::interaction
