#include "polygon/brute_force.h"

#include "polygon/hierarchy_common.h"

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

/// Brute force divided into a fixed number of chunks of A's rows.
class BruteForceSplit final : public SplitQuery {
 public:
  BruteForceSplit(const BruteForce& brute, const Mesh& mesh_a, const Mesh& mesh_b,
                  const Transform& X_AB, const CollideRequest& request)
      : brute_(brute),
        a_(mesh_a),
        b_(mesh_b),
        X_AB_(X_AB),
        request_(request),
        transformed_(mesh_b, X_AB_) {
    rows_ = mesh_a.triangles.size();
    chunk_ = (rows_ + detail::kFrontierTarget - 1) / detail::kFrontierTarget;
    parts_.resize((rows_ + chunk_ - 1) / chunk_);
  }

  std::size_t parts() const override { return parts_.size(); }

  void run(std::size_t i) override {
    detail::LeafTester tester(a_, b_, X_AB_, request_.all_pairs, parts_[i]);
    brute_.test_rows(static_cast<std::uint32_t>(i * chunk_),
                     static_cast<std::uint32_t>(std::min(rows_, (i + 1) * chunk_)), b_,
                     &transformed_, tester);
  }

  CollideResult result() override {
    CollideResult merged;
    detail::merge_parts(merged, parts_, request_);
    return merged;
  }

 private:
  const BruteForce& brute_;
  const Mesh& a_;
  const Mesh& b_;
  const Transform X_AB_;
  const CollideRequest request_;
  const TransformedB transformed_;
  std::size_t rows_ = 0, chunk_ = 1;
  std::vector<CollideResult> parts_;
};

std::unique_ptr<SplitQuery> BruteForce::split(const Mesh& mesh_a, const BruteForce& /*b*/,
                                              const Mesh& mesh_b, const Transform& X_AB,
                                              const CollideRequest& request) const {
  return std::make_unique<BruteForceSplit>(*this, mesh_a, mesh_b, X_AB, request);
}

}  // namespace dovetail::collision
