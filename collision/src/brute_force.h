#pragma once
// The reference method: every triangle of A against every triangle of B.

#include <vector>

#include "dovetail/collision/collide.h"
#include "dovetail/collision/mesh.h"

namespace dovetail::collision {

/// Exhaustive reference. Each pair is first compared by the exact bounding
/// boxes of the two triangles (computed from the same transformed vertices the
/// triangle test uses, so the filter never changes a verdict), then by the
/// exact triangle test.
class BruteForce {
 public:
  explicit BruteForce(const Mesh& mesh);

  CollideResult collide(const Mesh& mesh_a, const BruteForce& b, const Mesh& mesh_b,
                        const Transform& X_AB, const CollideRequest& request) const;

  std::size_t bytes() const;

 private:
  std::vector<Vec3> lo_, hi_;  ///< per-triangle bounds in the mesh's own frame
};

}  // namespace dovetail::collision
