#pragma once
// Pieces shared by every hierarchy: per-triangle build records, outward
// rounding to float, the conservative margin and the leaf-pair test.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "dovetail/collision/collide.h"
#include "dovetail/collision/mesh.h"
#include "dovetail/collision/model.h"
#include "dovetail/collision/task_system.h"
#include "dovetail/collision/tri_tri.h"

namespace dovetail::collision::detail {

/// Largest float <= x.
inline float round_down(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) > x) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return f;
}

/// Smallest float >= x.
inline float round_up(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

/// A triangle during top-down construction.
struct BuildTriangle {
  Vec3 lo;
  Vec3 hi;
  Vec3 centroid;
  std::uint32_t index = 0;  ///< into Mesh::triangles
};

inline std::vector<BuildTriangle> build_triangles(const Mesh& mesh) {
  std::vector<BuildTriangle> out(mesh.triangles.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    const TriangleIndices& t = mesh.triangles[i];
    const Vec3& p = mesh.vertices[t[0]];
    const Vec3& q = mesh.vertices[t[1]];
    const Vec3& r = mesh.vertices[t[2]];
    out[i].lo = p.cwiseMin(q).cwiseMin(r);
    out[i].hi = p.cwiseMax(q).cwiseMax(r);
    out[i].centroid = (p + q + r) / 3.0;
    out[i].index = static_cast<std::uint32_t>(i);
  }
  return out;
}

/// Largest absolute coordinate of a mesh (for the conservative margin).
inline Real max_abs_coordinate(const Mesh& mesh) {
  Real r = 0;
  for (const Vec3& v : mesh.vertices) r = std::max(r, v.cwiseAbs().maxCoeff());
  return r;
}

/// Margin added to every volume overlap test of a query. Transformed volumes
/// and transformed vertices are rounded differently; the margin, far above
/// that rounding (relative 2^-40) and far below any geometric feature, keeps
/// the culling conservative, so a hierarchy never misses a pair that the exact
/// triangle test (on the same transformed vertices) would report.
inline Real query_margin(Real max_abs_a, Real max_abs_b, const Transform& X_AB) {
  return 0x1.0p-40 * (max_abs_a + 3 * max_abs_b + X_AB.t.cwiseAbs().sum());
}

/// Whether two closed axis-aligned boxes, given by their corners, share a
/// point. On the bounds of two triangles' very coordinates it rejects pairs
/// the exact triangle test would reject too, before it.
inline bool aligned_boxes_meet(const Vec3& a_lo, const Vec3& a_hi, const Vec3& b_lo,
                               const Vec3& b_hi) {
  return !((a_lo.array() > b_hi.array()).any() || (b_lo.array() > a_hi.array()).any());
}

/// State of one query's traversal: meshes, pose, result, early exit.
class LeafTester {
 public:
  LeafTester(const Mesh& a, const Mesh& b, const Transform& X_AB, bool all_pairs,
             CollideResult& result)
      : a_(a), b_(b), X_AB_(X_AB), all_pairs_(all_pairs), result_(result) {}

  bool done() const { return done_; }

  /// Tests every triangle of one leaf against every triangle of another; B's
  /// triangles are transformed, and every triangle's bounding box computed,
  /// once per leaf pair.
  void test_leaves(const std::uint32_t* tris_a, int count_a, const std::uint32_t* tris_b,
                   int count_b) {
    constexpr int kMaxLeaf = 8;
    std::array<std::array<Vec3, 3>, kMaxLeaf> b;
    std::array<Vec3, kMaxLeaf> b_lo, b_hi;
    for (int j = 0; j < count_b; ++j) {
      const TriangleIndices& tb = b_.triangles[tris_b[j]];
      for (int k = 0; k < 3; ++k) b[j][k] = X_AB_.apply(b_.vertices[tb[k]]);
      b_lo[j] = b[j][0].cwiseMin(b[j][1]).cwiseMin(b[j][2]);
      b_hi[j] = b[j][0].cwiseMax(b[j][1]).cwiseMax(b[j][2]);
    }
    for (int i = 0; i < count_a && !done_; ++i) {
      const TriangleIndices& ta = a_.triangles[tris_a[i]];
      const Vec3& p = a_.vertices[ta[0]];
      const Vec3& q = a_.vertices[ta[1]];
      const Vec3& r = a_.vertices[ta[2]];
      const Vec3 a_lo = p.cwiseMin(q).cwiseMin(r), a_hi = p.cwiseMax(q).cwiseMax(r);
      for (int j = 0; j < count_b && !done_; ++j) {
        if (aligned_boxes_meet(a_lo, a_hi, b_lo[j], b_hi[j]))
          test_exact(tris_a[i], p, q, r, tris_b[j], b[j]);
      }
    }
  }

  /// The exact test, after comparing the two triangles' bounding boxes in A's
  /// frame. The boxes come from the very coordinates the exact test uses, so
  /// the comparison only saves work and never changes a verdict.
  void test_transformed(std::uint32_t ia, std::uint32_t ib, const std::array<Vec3, 3>& b) {
    const TriangleIndices& ta = a_.triangles[ia];
    const Vec3& p = a_.vertices[ta[0]];
    const Vec3& q = a_.vertices[ta[1]];
    const Vec3& r = a_.vertices[ta[2]];
    if (aligned_boxes_meet(p.cwiseMin(q).cwiseMin(r), p.cwiseMax(q).cwiseMax(r),
                           b[0].cwiseMin(b[1]).cwiseMin(b[2]),
                           b[0].cwiseMax(b[1]).cwiseMax(b[2]))) {
      test_exact(ia, p, q, r, ib, b);
    }
  }

  void count_volume_test() { ++result_.stats.volume_tests; }

  /// A time-critical query's cut: volumes that still overlap count as a hit.
  void volumes_hit() {
    result_.colliding = true;
    done_ = true;
  }

  /// Sorts all-pairs output by (a, b).
  void finish() {
    if (all_pairs_) std::sort(result_.pairs.begin(), result_.pairs.end());
  }

 private:
  void test_exact(std::uint32_t ia, const Vec3& p, const Vec3& q, const Vec3& r, std::uint32_t ib,
                  const std::array<Vec3, 3>& b) {
    ++result_.stats.triangle_tests;
    if (triangles_intersect(p, q, r, b[0], b[1], b[2])) {
      result_.colliding = true;
      result_.pairs.push_back({ia, ib});
      done_ = !all_pairs_;
    }
  }

  const Mesh& a_;
  const Mesh& b_;
  const Transform& X_AB_;
  bool all_pairs_;
  bool done_ = false;
  CollideResult& result_;
};

/// Folds the results of a query's independent parts into `result`: sorted
/// pairs, or for a first-hit query the smallest first hit.
inline void merge_parts(CollideResult& result, const std::vector<CollideResult>& parts,
                        const CollideRequest& request) {
  for (const CollideResult& part : parts) {
    result.colliding = result.colliding || part.colliding;
    result.stats.volume_tests += part.stats.volume_tests;
    result.stats.triangle_tests += part.stats.triangle_tests;
    result.pairs.insert(result.pairs.end(), part.pairs.begin(), part.pairs.end());
  }
  std::sort(result.pairs.begin(), result.pairs.end());
  if (!request.all_pairs && result.pairs.size() > 1) result.pairs.resize(1);
}

/// Node pairs a fine-grained parallel query is split into: fixed, not tied
/// to the thread count, so the result is the same for any number of threads.
inline constexpr std::size_t kFrontierTarget = 64;

/// A query divided into sub-traversals: `Context` holds the per-query state
/// (constructed from the pose, stored here, and the extra arguments) and
/// makes a traversal reporting to a given tester, with `frontier(target)`
/// (overlapping node pairs breadth-first from the roots) and `run_from(entry)`.
/// All-pairs results equal the serial query's exactly: the set of node pairs
/// visited does not depend on the order.
template <typename Context>
class SplitTraversal final : public SplitQuery {
 public:
  template <typename... Args>
  SplitTraversal(const Mesh& a, const Mesh& b, const Transform& X_AB, const CollideRequest& request,
                 Args&&... args)
      : a_(a), b_(b), X_AB_(X_AB), request_(request), context_(X_AB_, std::forward<Args>(args)...) {
    LeafTester head(a_, b_, X_AB_, request_.all_pairs, head_);
    entries_ = context_.make(head).frontier(kFrontierTarget);
    parts_.resize(entries_.size());
  }

  std::size_t parts() const override { return entries_.size(); }

  void run(std::size_t i) override {
    LeafTester tester(a_, b_, X_AB_, request_.all_pairs, parts_[i]);
    context_.make(tester).run_from(entries_[i]);
  }

  CollideResult result() override {
    CollideResult merged = head_;
    merge_parts(merged, parts_, request_);
    return merged;
  }

 private:
  const Mesh& a_;
  const Mesh& b_;
  const Transform X_AB_;
  const CollideRequest request_;
  const Context context_;
  CollideResult head_;
  std::vector<typename Context::Entry> entries_;
  std::vector<CollideResult> parts_;
};

}  // namespace dovetail::collision::detail
