#pragma once
// The reference method: every triangle of A against every triangle of B.

#include <vector>

#include "dovetail/collision/collide.h"
#include "dovetail/collision/mesh.h"
#include "dovetail/collision/model.h"

namespace dovetail::collision {

namespace detail {
class LeafTester;
}

/// Exhaustive reference. Each pair is first compared by the exact bounding
/// boxes of the two triangles (computed from the same transformed vertices the
/// triangle test uses, so the filter never changes a verdict), then by the
/// exact triangle test.
class BruteForce {
 public:
  explicit BruteForce(const Mesh& mesh);

  CollideResult collide(const Mesh& mesh_a, const BruteForce& b, const Mesh& mesh_b,
                        const Transform& X_AB, const CollideRequest& request) const;

  /// The same query divided into independent parts (see SplitQuery).
  std::unique_ptr<SplitQuery> split(const Mesh& mesh_a, const BruteForce& b, const Mesh& mesh_b,
                                    const Transform& X_AB, const CollideRequest& request) const;

  std::size_t bytes() const;

 private:
  friend class BruteForceSplit;

  /// Rows [begin, end) of A against every triangle of B (`transformed`: B in A's frame).
  void test_rows(std::uint32_t begin, std::uint32_t end, const Mesh& mesh_b,
                 const void* transformed, detail::LeafTester& tester) const;

  std::vector<Vec3> lo_, hi_;  ///< per-triangle bounds in the mesh's own frame
};

}  // namespace dovetail::collision
