#include "polygon/binary_layout.h"

#include <algorithm>
#include <array>
#include <limits>
#include <stdexcept>

namespace dovetail::collision::detail {

namespace {

struct Aabb {
  Vec3 lo = Vec3::Constant(std::numeric_limits<Real>::infinity());
  Vec3 hi = Vec3::Constant(-std::numeric_limits<Real>::infinity());
  void grow(const Vec3& l, const Vec3& h) {
    lo = lo.cwiseMin(l);
    hi = hi.cwiseMax(h);
  }
  Real half_area() const {
    if (!(lo.x() <= hi.x())) return 0;
    const Vec3 e = hi - lo;
    return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
  }
};

class LayoutBuilder {
 public:
  LayoutBuilder(BinaryLayout& out, int max_leaf) : out_(out), max_leaf_(max_leaf) {}

  void build(std::uint32_t node, std::uint32_t begin, std::uint32_t end, std::size_t depth) {
    out_.depth = std::max(out_.depth, depth);
    out_.nodes[node].begin = begin;
    out_.nodes[node].end = end;
    if (end - begin <= static_cast<std::uint32_t>(max_leaf_)) {
      ++out_.leaves;
      return;
    }
    const std::uint32_t mid = partition(begin, end, depth);
    const auto child = static_cast<std::uint32_t>(out_.nodes.size());
    out_.nodes.resize(out_.nodes.size() + 2);
    out_.nodes[node].first_child = child;
    build(child, begin, mid, depth + 1);
    build(child + 1, mid, end, depth + 1);
  }

 private:
  std::uint32_t partition(std::uint32_t begin, std::uint32_t end, std::size_t depth) {
    constexpr int kBins = 16;
    constexpr std::size_t kMaxCostDepth = 48;  // beyond it, median splits bound the depth
    std::vector<BuildTriangle>& t = out_.triangles;
    Aabb centroids;
    for (std::uint32_t i = begin; i < end; ++i) centroids.grow(t[i].centroid, t[i].centroid);

    int best_axis = -1, best_bin = 0;
    Real best_cost = std::numeric_limits<Real>::infinity();
    for (int k = 0; k < 3 && depth < kMaxCostDepth; ++k) {
      const Real extent = centroids.hi[k] - centroids.lo[k];
      if (!(extent > 0)) continue;
      const Real scale = kBins / extent;
      std::array<Aabb, kBins> bins;
      std::array<std::size_t, kBins> count{};
      for (std::uint32_t i = begin; i < end; ++i) {
        const int b =
            std::min(kBins - 1, static_cast<int>((t[i].centroid[k] - centroids.lo[k]) * scale));
        bins[b].grow(t[i].lo, t[i].hi);
        ++count[b];
      }
      std::array<Real, kBins> right_cost{};
      Aabb right;
      std::size_t right_count = 0;
      for (int b = kBins - 1; b > 0; --b) {
        right.grow(bins[b].lo, bins[b].hi);
        right_count += count[b];
        right_cost[b] = right_count * right.half_area();
      }
      Aabb left;
      std::size_t left_count = 0;
      for (int b = 0; b + 1 < kBins; ++b) {
        left.grow(bins[b].lo, bins[b].hi);
        left_count += count[b];
        if (left_count == 0 || left_count == end - begin) continue;
        const Real cost = left_count * left.half_area() + right_cost[b + 1];
        if (cost < best_cost) best_cost = cost, best_axis = k, best_bin = b;
      }
    }
    if (best_axis < 0) {
      // All centroids coincide (or the tree is deep): split at the median of the longest axis.
      int axis = 0;
      const Vec3 e = centroids.hi - centroids.lo;
      for (int k = 1; k < 3; ++k)
        if (e[k] > e[axis]) axis = k;
      const std::uint32_t mid = begin + (end - begin) / 2;
      std::nth_element(t.begin() + begin, t.begin() + mid, t.begin() + end,
                       [axis](const BuildTriangle& x, const BuildTriangle& y) {
                         return x.centroid[axis] < y.centroid[axis] ||
                                (x.centroid[axis] == y.centroid[axis] && x.index < y.index);
                       });
      return mid;
    }
    const Real lo = centroids.lo[best_axis];
    const Real scale = kBins / (centroids.hi[best_axis] - lo);
    const auto split =
        std::partition(t.begin() + begin, t.begin() + end, [&](const BuildTriangle& p) {
          return std::min(kBins - 1, static_cast<int>((p.centroid[best_axis] - lo) * scale)) <=
                 best_bin;
        });
    return static_cast<std::uint32_t>(split - t.begin());
  }

  BinaryLayout& out_;
  int max_leaf_;
};

}  // namespace

BinaryLayout build_binary_layout(const Mesh& mesh, int max_leaf) {
  if (max_leaf < 1 || max_leaf >= (1 << NodeLink::kCountBits)) {
    throw std::invalid_argument("hierarchy: leaf size must be 1..7");
  }
  if (mesh.triangles.size() >= (1u << (31 - NodeLink::kCountBits))) {
    throw std::invalid_argument(mesh.source + ": too many triangles for one hierarchy");
  }
  BinaryLayout layout;
  layout.triangles = build_triangles(mesh);
  layout.nodes.reserve(2 * mesh.triangles.size());
  layout.nodes.emplace_back();
  LayoutBuilder(layout, max_leaf)
      .build(0, 0, static_cast<std::uint32_t>(layout.triangles.size()), 1);
  return layout;
}

}  // namespace dovetail::collision::detail
