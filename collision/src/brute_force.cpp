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

namespace {

/// B's vertices in A's frame and its triangles' bounds there, from the
/// vertices exactly as the triangle test sees them.
struct TransformedB {
  std::vector<Vec3> vertices, lo, hi;
  TransformedB(const Mesh& mesh_b, const Transform& X_AB) : vertices(mesh_b.vertices.size()) {
    for (std::size_t i = 0; i < vertices.size(); ++i) vertices[i] = X_AB.apply(mesh_b.vertices[i]);
    lo.resize(mesh_b.triangles.size());
    hi.resize(mesh_b.triangles.size());
    for (std::size_t j = 0; j < lo.size(); ++j) {
      const TriangleIndices& t = mesh_b.triangles[j];
      lo[j] = vertices[t[0]].cwiseMin(vertices[t[1]]).cwiseMin(vertices[t[2]]);
      hi[j] = vertices[t[0]].cwiseMax(vertices[t[1]]).cwiseMax(vertices[t[2]]);
    }
  }
};

}  // namespace

void BruteForce::test_rows(std::uint32_t begin, std::uint32_t end, const Mesh& mesh_b,
                           const void* transformed, detail::LeafTester& tester) const {
  const auto& b = *static_cast<const TransformedB*>(transformed);
  for (std::uint32_t i = begin; i < end && !tester.done(); ++i) {
    for (std::uint32_t j = 0; j < b.lo.size() && !tester.done(); ++j) {
      if (lo_[i].x() > b.hi[j].x() || b.lo[j].x() > hi_[i].x() || lo_[i].y() > b.hi[j].y() ||
          b.lo[j].y() > hi_[i].y() || lo_[i].z() > b.hi[j].z() || b.lo[j].z() > hi_[i].z()) {
        continue;
      }
      const TriangleIndices& t = mesh_b.triangles[j];
      tester.test_transformed(i, j, {b.vertices[t[0]], b.vertices[t[1]], b.vertices[t[2]]});
    }
  }
}

CollideResult BruteForce::collide(const Mesh& mesh_a, const BruteForce& /*b*/, const Mesh& mesh_b,
                                  const Transform& X_AB, const CollideRequest& request) const {
  CollideResult result;
  detail::LeafTester tester(mesh_a, mesh_b, X_AB, request.all_pairs, result);
  const TransformedB transformed(mesh_b, X_AB);
  test_rows(0, static_cast<std::uint32_t>(lo_.size()), mesh_b, &transformed, tester);
  tester.finish();
  return result;
}

CollideResult BruteForce::collide_parallel(const Mesh& mesh_a, const BruteForce& /*b*/,
                                           const Mesh& mesh_b, const Transform& X_AB,
                                           const CollideRequest& request, TaskSystem& tasks) const {
  const TransformedB transformed(mesh_b, X_AB);
  // Rows of A in a fixed number of chunks, independent of the thread count.
  const std::size_t rows = lo_.size();
  const std::size_t chunk = (rows + detail::kFrontierTarget - 1) / detail::kFrontierTarget;
  const std::size_t chunks = (rows + chunk - 1) / chunk;
  std::vector<CollideResult> parts(chunks);
  tasks.parallel_for(chunks, 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t c = begin; c < end; ++c) {
      detail::LeafTester tester(mesh_a, mesh_b, X_AB, request.all_pairs, parts[c]);
      test_rows(static_cast<std::uint32_t>(c * chunk), static_cast<std::uint32_t>(std::min(rows, (c + 1) * chunk)),
                mesh_b, &transformed, tester);
    }
  });
  CollideResult result;
  detail::merge_parts(result, parts, request);
  return result;
}

}  // namespace dovetail::collision
