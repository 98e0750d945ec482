#include "brute_force.h"

#include "hierarchy_common.h"

namespace dovetail::collision {

BruteForce::BruteForce(const Mesh& mesh) {
  for (const detail::BuildTriangle& t : detail::build_triangles(mesh)) {
    lo_.push_back(t.lo);
    hi_.push_back(t.hi);
  }
}

std::size_t BruteForce::bytes() const {
  return sizeof(*this) + (lo_.capacity() + hi_.capacity()) * sizeof(Vec3);
}

CollideResult BruteForce::collide(const Mesh& mesh_a, const BruteForce& /*b*/, const Mesh& mesh_b,
                                  const Transform& X_AB, const CollideRequest& request) const {
  CollideResult result;
  detail::LeafTester tester(mesh_a, mesh_b, X_AB, request.all_pairs, result);
  // B's triangle bounds in A's frame, from the vertices exactly as the triangle test sees them.
  std::vector<Vec3> vertices_b(mesh_b.vertices.size());
  for (std::size_t i = 0; i < vertices_b.size(); ++i) vertices_b[i] = X_AB.apply(mesh_b.vertices[i]);
  std::vector<Vec3> lo_b(mesh_b.triangles.size()), hi_b(mesh_b.triangles.size());
  for (std::size_t j = 0; j < lo_b.size(); ++j) {
    const TriangleIndices& t = mesh_b.triangles[j];
    lo_b[j] = vertices_b[t[0]].cwiseMin(vertices_b[t[1]]).cwiseMin(vertices_b[t[2]]);
    hi_b[j] = vertices_b[t[0]].cwiseMax(vertices_b[t[1]]).cwiseMax(vertices_b[t[2]]);
  }
  for (std::uint32_t i = 0; i < lo_.size() && !tester.done(); ++i) {
    for (std::uint32_t j = 0; j < lo_b.size() && !tester.done(); ++j) {
      if (lo_[i].x() > hi_b[j].x() || lo_b[j].x() > hi_[i].x() || lo_[i].y() > hi_b[j].y() ||
          lo_b[j].y() > hi_[i].y() || lo_[i].z() > hi_b[j].z() || lo_b[j].z() > hi_[i].z()) {
        continue;
      }
      const TriangleIndices& t = mesh_b.triangles[j];
      tester.test_transformed(i, j, {vertices_b[t[0]], vertices_b[t[1]], vertices_b[t[2]]});
    }
  }
  tester.finish();
  return result;
}

}  // namespace dovetail::collision
