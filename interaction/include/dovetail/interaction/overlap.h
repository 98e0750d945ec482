#pragma once
/// \file overlap.h
/// How deep two placed parts overlap: the measure of a scenario's
/// `max_penetration` and of a mate's snap (a part is not snapped into a pose
/// where it would overlap another).
///
/// Why one gauge: the two must agree on what "overlap" is. For two convex
/// parts (closed, every triangle on the hull) it is exact: the penetration
/// depth, the shortest move that parts them. For any other pair it is the
/// collision layer's contact depth estimate (docs/proximity.md, "Depth
/// estimate"): the deepest point of one part's edges inside the other,
/// measured to the other's surface, which misses an overlap deepest in the
/// middle of a face.

#include <map>
#include <memory>
#include <optional>
#include <string>

#include "dovetail/collision/convex.h"
#include "dovetail/collision/mesh.h"
#include "dovetail/collision/model.h"
#include "dovetail/collision/types.h"

namespace dovetail::interaction {

using collision::Real;
using collision::Transform;

/// What the gauge needs of a part's surface, for warnings: what the surface
/// lacks ("48 open edges (a hole or a missing face)", "4 wrongly wound edges",
/// or both), or nullopt when it is closed and consistently wound
/// (collision::surface_edges).
///
/// Why it matters: an open or inconsistently wound surface has no inside, so
/// a part can sit deep in it unmeasured (the depth reads 0), and the depth of
/// an overlap that is found is measured against faces that may not bound the
/// part (a hole far from the contact can make it read tens of millimetres
/// too deep). The depth is not refused for such a part, since a scenario
/// whose parts never overlap still runs as it should; the warning says
/// which numbers not to trust.
std::optional<std::string> surface_flaw(const collision::Mesh& mesh);

/// What an open or wrongly wound surface affects, to follow surface_flaw in
/// a warning.
inline constexpr const char* kSurfaceFlawEffect =
    "penetration depth (max_penetration, a snap's overlap check) and inside tests need a "
    "closed, consistently wound surface, so overlaps with this part may read 0 or too deep";

/// Keeps each mesh's OBB tree and, for a convex part, its hull, built on
/// first use. The meshes must outlive the gauge's use of them.
class OverlapGauge {
 public:
  /// 0 when the parts are apart or only touch.
  Real depth(const std::shared_ptr<const collision::Mesh>& a, const Transform& X_WA,
             const std::shared_ptr<const collision::Mesh>& b, const Transform& X_WB);

  /// The mesh's OBB tree, built on first use: for callers that query the
  /// same meshes otherwise too (sliding), so that each is built once.
  const std::shared_ptr<const collision::CollisionModel>& model(
      const std::shared_ptr<const collision::Mesh>& mesh);

 private:
  /// The hull of a convex part's mesh; null for a part that is not convex.
  const collision::ConvexHull* convex_hull(const std::shared_ptr<const collision::Mesh>& mesh);

  std::map<const collision::Mesh*, std::shared_ptr<const collision::CollisionModel>> models_;
  std::map<const collision::Mesh*, std::shared_ptr<const collision::ConvexHull>> hulls_;
};

}  // namespace dovetail::interaction
