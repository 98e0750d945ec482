#include "dovetail/collision/distance.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "polygon/hierarchy_common.h"
#include "proximity/rss_tree.h"
#include "proximity/tri_distance.h"

namespace dovetail::collision {

DistanceModel::DistanceModel(std::shared_ptr<const Mesh> mesh,
                             std::unique_ptr<const detail::RssTree> tree)
    : mesh_(std::move(mesh)), tree_(std::move(tree)) {}

DistanceModel::~DistanceModel() = default;

ModelInfo DistanceModel::info() const {
  ModelInfo info;
  info.nodes = tree_->nodes().size();
  info.leaves = tree_->leaf_count();
  info.depth = tree_->depth();
  info.bytes = tree_->bytes();
  info.bytes_per_triangle =
      static_cast<double>(info.bytes) / static_cast<double>(mesh_->triangle_count());
  return info;
}

std::shared_ptr<const DistanceModel> build_distance_model(std::shared_ptr<const Mesh> mesh,
                                                          const DistanceModelSettings& settings) {
  if (!mesh) throw std::invalid_argument("build_distance_model: null mesh");
  if (settings.max_leaf_size < 1 || settings.max_leaf_size > 7)
    throw std::invalid_argument("build_distance_model: max_leaf_size must be 1..7");
  auto tree = std::make_unique<const detail::RssTree>(*mesh, settings.max_leaf_size);
  return std::shared_ptr<const DistanceModel>(new DistanceModel(std::move(mesh), std::move(tree)));
}

namespace {

/// A tolerance or an allowed error: a number >= 0 (NaN is refused too).
void check_non_negative(Real value, const char* what) {
  if (!(value >= 0)) {
    throw std::invalid_argument(std::string(what) + " must be a number >= 0, got " +
                                std::to_string(value));
  }
}

}  // namespace

DistanceResult distance(const DistanceModel& a, const DistanceModel& b, const Transform& X_AB,
                        const DistanceRequest& request) {
  check_non_negative(request.relative_error, "distance: relative_error");
  check_non_negative(request.absolute_error, "distance: absolute_error");
  return a.tree().distance(a.mesh(), b.tree(), b.mesh(), X_AB, request);
}

ToleranceResult within_tolerance(const DistanceModel& a, const DistanceModel& b,
                                 const Transform& X_AB, Real tolerance) {
  check_non_negative(tolerance, "within_tolerance: the tolerance");
  return a.tree().within(a.mesh(), b.tree(), b.mesh(), X_AB, tolerance);
}

namespace {

/// Both meshes' triangles in A's frame, B's vertices mapped by
/// Transform::apply exactly as the hierarchy's leaf test maps them, with
/// each triangle's bounding box.
class BrutePairs {
 public:
  BrutePairs(const Mesh& a, const Mesh& b, const Transform& X_AB)
      : a_(a),
        b_(b),
        margin_(detail::query_margin(detail::max_abs_coordinate(a), detail::max_abs_coordinate(b),
                                     X_AB)) {
    vertices_b_.reserve(b.vertices.size());
    for (const Vec3& p : b.vertices) vertices_b_.push_back(X_AB.apply(p));
    boxes(a_, a.vertices, lo_a_, hi_a_);
    boxes(b_, vertices_b_, lo_b_, hi_b_);
  }

  /// Calls visit(i, j, triangle distance) for every pair whose boxes are not
  /// provably farther apart than limit() (re-read after every pair), until
  /// visit returns false.
  template <typename Limit, typename Visit>
  void run(Limit&& limit, Visit&& visit, CollideStats& stats) const {
    for (std::uint32_t i = 0; i < a_.triangles.size(); ++i) {
      for (std::uint32_t j = 0; j < b_.triangles.size(); ++j) {
        Real gap2 = 0;
        for (int k = 0; k < 3; ++k) {
          const Real g = std::max({Real{0}, lo_b_[j][k] - hi_a_[i][k], lo_a_[i][k] - hi_b_[j][k]});
          gap2 += g * g;
        }
        const Real reach = limit() + margin_;
        if (gap2 > reach * reach) continue;
        ++stats.triangle_tests;
        if (!visit(i, j,
                   detail::triangle_distance(triangle(a_, a_.vertices, i),
                                             triangle(b_, vertices_b_, j))))
          return;
      }
    }
  }

 private:
  static detail::TriangleVertices triangle(const Mesh& m, const std::vector<Vec3>& v,
                                           std::uint32_t i) {
    const TriangleIndices& t = m.triangles[i];
    return {v[t[0]], v[t[1]], v[t[2]]};
  }

  static void boxes(const Mesh& m, const std::vector<Vec3>& v, std::vector<Vec3>& lo,
                    std::vector<Vec3>& hi) {
    for (const TriangleIndices& t : m.triangles) {
      lo.push_back(v[t[0]].cwiseMin(v[t[1]]).cwiseMin(v[t[2]]));
      hi.push_back(v[t[0]].cwiseMax(v[t[1]]).cwiseMax(v[t[2]]));
    }
  }

  const Mesh& a_;
  const Mesh& b_;
  Real margin_;
  std::vector<Vec3> vertices_b_, lo_a_, hi_a_, lo_b_, hi_b_;
};

}  // namespace

TrianglePairDistance triangle_pair_distance(const std::array<Vec3, 3>& a,
                                            const std::array<Vec3, 3>& b) {
  const detail::TriangleDistance d = detail::triangle_distance(a, b);
  return {d.distance, d.p, d.q};
}

DistanceResult distance_brute(const Mesh& a, const Mesh& b, const Transform& X_AB) {
  DistanceResult result;
  const BrutePairs pairs(a, b, X_AB);
  pairs.run([&] { return result.distance; },
            [&](std::uint32_t i, std::uint32_t j, const detail::TriangleDistance& d) {
              if (d.distance < result.distance) {
                result.distance = d.distance;
                result.p_A = d.p;
                result.q_A = d.q;
                result.triangle_a = i;
                result.triangle_b = j;
              }
              return result.distance > 0;
            },
            result.stats);
  return result;
}

ToleranceResult within_tolerance_brute(const Mesh& a, const Mesh& b, const Transform& X_AB,
                                       Real tolerance) {
  check_non_negative(tolerance, "within_tolerance_brute: the tolerance");
  ToleranceResult result;
  const BrutePairs pairs(a, b, X_AB);
  pairs.run([&] { return tolerance; },
            [&](std::uint32_t i, std::uint32_t j, const detail::TriangleDistance& d) {
              if (d.distance > tolerance) return true;
              result.within = true;
              result.distance = d.distance;
              result.p_A = d.p;
              result.q_A = d.q;
              result.triangle_a = i;
              result.triangle_b = j;
              return false;
            },
            result.stats);
  return result;
}

}  // namespace dovetail::collision
