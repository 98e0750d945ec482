#include "dovetail/collision/contacts.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <optional>
#include <unordered_map>
#include <unordered_set>

#include "core/disjoint_sets.h"
#include "core/tri_intersection.h"
#include "core/vertex_triangles.h"
#include "dovetail/collision/containment.h"
#include "dovetail/collision/predicates.h"
#include "proximity/tri_distance.h"

namespace dovetail::collision {

namespace {

using detail::DisjointSets;
using detail::VertexTriangles;

/// One pair with its triangles in A's frame and its piece of intersection.
struct PairPiece {
  detail::TriangleVertices t_a;
  detail::TriangleVertices t_b;
  detail::TrianglePiece piece;
  Vec3 lo;  ///< piece bounds, widened by the merge distance
  Vec3 hi;
};

/// Most distance queries one search of the edges' deepest points makes
/// (InsideReach::edge_reach), beyond one at each end of every stretch; past
/// it, the deepest point found so far counts.
constexpr std::size_t kEdgeProbes = 4096;

/// A face counts for the depth when its normal is within 60 degrees of the patch normal.
constexpr Real kFacingCosine = 0.5;

/// Largest distance behind `face` (outward unit normal `n`) of a vertex of
/// `other` whose projection along n falls in the closed face.
Real depth_behind(const detail::TriangleVertices& face, const Vec3& n,
                  const detail::TriangleVertices& other) {
  Real depth = 0;
  for (const Vec3& v : other) {
    const Real d = (face[0] - v).dot(n);
    if (d <= depth) continue;
    bool in_face = true;
    for (int k = 0; k < 3 && in_face; ++k) {
      const Vec3& e0 = face[k];
      const Vec3& e1 = face[(k + 1) % 3];
      const Vec3 edge = e1 - e0;
      // Inside the edge's line, with a rounding allowance relative to the edge.
      in_face = edge.cross(v - e0).dot(n) >= -1e-12 * edge.squaredNorm();
    }
    if (in_face) depth = d;
  }
  return depth;
}

/// The geometry the coplanar search asks for again and again, computed once
/// per triangle and vertex it meets: B's vertices mapped into A's frame by the
/// same Transform::apply as the collision query, and each triangle's unit
/// normal in A's frame.
class CoplanarGeometry {
 public:
  CoplanarGeometry(const Mesh& a, const Mesh& b, const Transform& X_AB)
      : a_(a),
        b_(b),
        X_AB_(X_AB),
        b_vertices_(b.vertices.size()),
        b_mapped_(b.vertices.size(), 0),
        normals_a_(a.triangles.size()),
        normals_b_(b.triangles.size()),
        has_normal_a_(a.triangles.size(), 0),
        has_normal_b_(b.triangles.size(), 0) {}

  detail::TriangleVertices triangle_a(std::uint32_t t) const {
    const TriangleIndices& f = a_.triangles[t];
    return {a_.vertices[f[0]], a_.vertices[f[1]], a_.vertices[f[2]]};
  }
  detail::TriangleVertices triangle_b(std::uint32_t t) {
    const TriangleIndices& f = b_.triangles[t];
    return {vertex_b(f[0]), vertex_b(f[1]), vertex_b(f[2])};
  }

  /// Every vertex of each triangle within `tolerance` of the other's plane.
  bool nearly_coplanar(std::uint32_t ta, std::uint32_t tb, Real tolerance) {
    const Vec3& n_a = normal(ta, has_normal_a_, normals_a_, triangle_a(ta));
    const Vec3& n_b = normal(tb, has_normal_b_, normals_b_, triangle_b(tb));
    const TriangleIndices& fa = a_.triangles[ta];
    const TriangleIndices& fb = b_.triangles[tb];
    const Vec3& a0 = a_.vertices[fa[0]];
    const Vec3& b0 = vertex_b(fb[0]);
    for (int i = 0; i < 3; ++i) {
      if (std::abs((vertex_b(fb[i]) - a0).dot(n_a)) > tolerance) return false;
      if (std::abs((a_.vertices[fa[i]] - b0).dot(n_b)) > tolerance) return false;
    }
    return true;
  }

 private:
  const Vec3& vertex_b(std::uint32_t v) {
    if (!b_mapped_[v]) {
      b_vertices_[v] = X_AB_.apply(b_.vertices[v]);
      b_mapped_[v] = 1;
    }
    return b_vertices_[v];
  }

  static const Vec3& normal(std::uint32_t t, std::vector<char>& known, std::vector<Vec3>& normals,
                            const detail::TriangleVertices& v) {
    if (!known[t]) {
      normals[t] = (v[1] - v[0]).cross(v[2] - v[0]).normalized();
      known[t] = 1;
    }
    return normals[t];
  }

  const Mesh& a_;
  const Mesh& b_;
  const Transform& X_AB_;
  std::vector<Vec3> b_vertices_;
  std::vector<char> b_mapped_;
  std::vector<Vec3> normals_a_, normals_b_;
  std::vector<char> has_normal_a_, has_normal_b_;
};

/// Adds the pairs of faces that lie on each other within the coplanar
/// tolerance but that the exact test separates by a rounding-size gap
/// (faces of a rotated part resting on another): starting next to the
/// reported pairs, pairs one triangle step apart are tried, and every pair
/// found with an overlap of positive area spreads the search further. The
/// pairs found are appended in (a, b) order.
///
/// A vertex shared by many triangles (the centre of a fanned cap) puts each
/// of them next to every pair of the fan, so the same candidate comes up
/// from many pairs; a candidate just tried with the same partner is skipped
/// (one partner remembered per triangle), and the plane test, on cached
/// vertices and normals, comes before the set of pairs already tried.
void add_nearly_coplanar_pairs(const Mesh& a, const Mesh& b, const Transform& X_AB, Real tolerance,
                               const VertexTriangles& around_a, const VertexTriangles& around_b,
                               std::vector<TrianglePair>& pairs, std::vector<PairPiece>& pieces) {
  const auto key = [](std::uint32_t ta, std::uint32_t tb) {
    return (static_cast<std::uint64_t>(ta) << 32) | tb;
  };
  std::unordered_set<std::uint64_t> tried;
  for (const TrianglePair& p : pairs) tried.insert(key(p.a, p.b));
  CoplanarGeometry geometry(a, b, X_AB);
  constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> last_b_of_a(a.triangles.size(), kNone);
  std::vector<std::uint32_t> last_a_of_b(b.triangles.size(), kNone);
  const std::size_t first_found = pairs.size();
  const auto consider = [&](std::uint32_t ta, std::uint32_t tb) {
    if (!geometry.nearly_coplanar(ta, tb, tolerance)) return;
    if (!tried.insert(key(ta, tb)).second) return;
    PairPiece candidate;
    candidate.t_a = geometry.triangle_a(ta);
    candidate.t_b = geometry.triangle_b(tb);
    candidate.piece = detail::intersect_triangles(candidate.t_a, candidate.t_b, tolerance);
    if (candidate.piece.area <= 0) return;
    pairs.push_back({ta, tb});
    pieces.push_back(std::move(candidate));
  };
  // The pairs found join the end of the list and spread in their turn. A
  // vertex whose triangles were all tried with the same partner is skipped whole.
  std::vector<std::uint32_t> row_done_a(a.vertices.size(), kNone);
  std::vector<std::uint32_t> row_done_b(b.vertices.size(), kNone);
  const auto spread = [&](const VertexTriangles& around, const TriangleIndices& f,
                          std::uint32_t partner, std::vector<std::uint32_t>& row_done,
                          std::vector<std::uint32_t>& last_partner, auto&& try_pair) {
    for (const std::uint32_t v : f) {
      if (row_done[v] == partner) continue;
      row_done[v] = partner;
      for (std::uint32_t k = around.offsets[v]; k < around.offsets[v + 1]; ++k) {
        const std::uint32_t t = around.triangles[k];
        if (last_partner[t] == partner) continue;
        last_partner[t] = partner;
        try_pair(t);
      }
    }
  };
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const TrianglePair p = pairs[i];
    spread(around_a, a.triangles[p.a], p.b, row_done_a, last_b_of_a,
           [&](std::uint32_t t) { consider(t, p.b); });
    spread(around_b, b.triangles[p.b], p.a, row_done_b, last_a_of_b,
           [&](std::uint32_t t) { consider(p.a, t); });
  }
  // The order of the search is not the result's: the pairs found in pair order.
  std::vector<std::size_t> order(pairs.size() - first_found);
  std::iota(order.begin(), order.end(), first_found);
  std::sort(order.begin(), order.end(),
            [&](std::size_t i, std::size_t j) { return pairs[i] < pairs[j]; });
  std::vector<TrianglePair> found_pairs;
  std::vector<PairPiece> found_pieces;
  for (const std::size_t i : order) {
    found_pairs.push_back(pairs[i]);
    found_pieces.push_back(std::move(pieces[i]));
  }
  std::copy(found_pairs.begin(), found_pairs.end(), pairs.begin() + first_found);
  std::move(found_pieces.begin(), found_pieces.end(), pieces.begin() + first_found);
}

/// Closed segment [v, w] against closed triangle t: do they share a point?
/// Exact signs; a segment in the triangle's plane counts as crossing.
bool segment_meets_triangle(const Vec3& v, const Vec3& w, const detail::TriangleVertices& t) {
  const int sv = orient3d(t[0], t[1], t[2], v);
  const int sw = orient3d(t[0], t[1], t[2], w);
  if (sv * sw > 0) return false;
  if (sv == 0 && sw == 0) return true;
  const int o0 = orient3d(v, w, t[0], t[1]);
  const int o1 = orient3d(v, w, t[1], t[2]);
  const int o2 = orient3d(v, w, t[2], t[0]);
  return (o0 >= 0 && o1 >= 0 && o2 >= 0) || (o0 <= 0 && o1 <= 0 && o2 <= 0);
}

/// Nearest distance from a point to a set of triangles (all in one frame),
/// through a bounding-box tree built once: median splits, four triangles a leaf.
class TriangleDistanceTree {
 public:
  explicit TriangleDistanceTree(std::vector<detail::TriangleVertices> triangles)
      : triangles_(std::move(triangles)), order_(triangles_.size()) {
    std::iota(order_.begin(), order_.end(), std::uint32_t{0});
    centroids_.reserve(triangles_.size());
    for (const detail::TriangleVertices& t : triangles_)
      centroids_.push_back((t[0] + t[1] + t[2]) / 3.0);
    if (!triangles_.empty()) build(0, static_cast<std::uint32_t>(order_.size()));
  }

  /// The nearest triangle to a point and its distance.
  struct Nearest {
    Real distance = std::numeric_limits<Real>::infinity();
    std::uint32_t triangle = 0;
  };

  /// Distance from p to the nearest triangle, and which (the first of equals).
  Nearest nearest(const Vec3& p) const {
    Nearest best;
    if (nodes_.empty()) return best;
    std::vector<std::uint32_t> stack{0};
    while (!stack.empty()) {
      const Node& node = nodes_[stack.back()];
      stack.pop_back();
      if (box_distance(node, p) >= best.distance) continue;
      if (node.right == 0) {
        for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
          const Real d = distance_to(p, order_[k]);
          if (d < best.distance) best = {d, order_[k]};
        }
        continue;
      }
      // The nearer child pushed last, so it is searched first.
      const std::uint32_t left = node.first, right = node.right;
      const bool right_nearer = box_distance(nodes_[left], p) > box_distance(nodes_[right], p);
      stack.push_back(right_nearer ? left : right);
      stack.push_back(right_nearer ? right : left);
    }
    return best;
  }

  /// Distance from p to triangle t.
  Real distance_to(const Vec3& p, std::uint32_t t) const {
    return (p - detail::closest_point_on_triangle(p, triangles_[t])).norm();
  }

 private:
  struct Node {
    Vec3 lo, hi;
    std::uint32_t first = 0;  ///< leaf: first slot; inner: left child
    std::uint32_t count = 0;  ///< leaf: triangles
    std::uint32_t right = 0;  ///< inner: right child; 0 for a leaf
  };

  static Real box_distance(const Node& node, const Vec3& p) {
    return (node.lo - p).cwiseMax(p - node.hi).cwiseMax(0).norm();
  }

  std::uint32_t build(std::uint32_t begin, std::uint32_t end) {
    const auto index = static_cast<std::uint32_t>(nodes_.size());
    nodes_.emplace_back();
    Vec3 lo = Vec3::Constant(std::numeric_limits<Real>::infinity()), hi = -lo;
    Vec3 c_lo = lo, c_hi = hi;
    for (std::uint32_t k = begin; k < end; ++k) {
      for (const Vec3& v : triangles_[order_[k]]) {
        lo = lo.cwiseMin(v);
        hi = hi.cwiseMax(v);
      }
      const Vec3 c = centroid(order_[k]);
      c_lo = c_lo.cwiseMin(c);
      c_hi = c_hi.cwiseMax(c);
    }
    nodes_[index].lo = lo;
    nodes_[index].hi = hi;
    if (end - begin <= 4) {
      nodes_[index].first = begin;
      nodes_[index].count = end - begin;
      return index;
    }
    int axis = 0;
    (c_hi - c_lo).maxCoeff(&axis);
    const std::uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                     [&](std::uint32_t x, std::uint32_t y) {
                       const Real cx = centroid(x)[axis], cy = centroid(y)[axis];
                       return cx < cy || (cx == cy && x < y);
                     });
    const std::uint32_t left = build(begin, mid);
    const std::uint32_t right = build(mid, end);
    nodes_[index].first = left;
    nodes_[index].right = right;
    return index;
  }

  const Vec3& centroid(std::uint32_t t) const { return centroids_[t]; }

  std::vector<detail::TriangleVertices> triangles_;
  std::vector<Vec3> centroids_;
  std::vector<std::uint32_t> order_;
  std::vector<Node> nodes_;
};

/// How deep one part ("part") reaches into the other ("other"): for the
/// regions of the part's surface inside the other, the largest distance of
/// a vertex to the other's surface; and the deepest point of the part's
/// edges that cross the other's surface (edge_reach). Everything is taken in
/// A's frame, B's vertices mapped by the same Transform::apply as the
/// collision query.
///
/// Why this way: the part's surface is cut into regions by the intersection
/// curves, which run through the intersecting triangle pairs. Walking the
/// part's mesh along edges that do not cross the other's surface never
/// leaves a region, so one exact point-in-solid test decides a whole region,
/// and only vertices really inside are measured (a part overhanging an edge,
/// or a pin hanging free in a hole, adds nothing). Regions are labelled once
/// per call and shared by every patch that touches them. This relies on the
/// pairs being all intersecting pairs: a region whose deepest vertex is not
/// inside after all (missing pairs let a walk cross the surface) counts 0.
class InsideReach {
 public:
  /// `resolution`: how close to the deepest point of an edge the search goes.
  InsideReach(const Mesh& part, const VertexTriangles& around, const Transform& X_AP,
              const Mesh& other, const Transform& X_AO,
              std::vector<std::pair<std::uint32_t, std::uint32_t>> crossings, Real resolution)
      : part_(part),
        around_(around),
        X_AP_(X_AP),
        other_(other),
        X_AO_(X_AO),
        crossings_(std::move(crossings)),
        resolution_(resolution) {
    std::sort(crossings_.begin(), crossings_.end());
  }

  /// The deepest reach of the inside regions that the part's triangles
  /// `seeds` (a patch's) touch; nullopt when the other is open (it has no
  /// inside).
  std::optional<Real> reach(const std::vector<std::uint32_t>& seeds) {
    if (!locator_) locator_.emplace(other_, X_AO_);
    if (!locator_->closed()) return std::nullopt;
    std::vector<std::uint32_t> start;
    for (const std::uint32_t t : seeds) {
      for (const std::uint32_t v : part_.triangles[t]) start.push_back(v);
    }
    std::sort(start.begin(), start.end());
    start.erase(std::unique(start.begin(), start.end()), start.end());
    Real deepest = 0;
    for (const std::uint32_t v : start) {
      if (!label_.contains(v)) label_group(v, start);
      deepest = std::max(deepest, regions_[label_.at(v)]);
    }
    return edge_reach(seeds, deepest);
  }

 private:
  Vec3 vertex(std::uint32_t v) const { return X_AP_.apply(part_.vertices[v]); }
  detail::TriangleVertices other_triangle(std::uint32_t t) const {
    const TriangleIndices& f = other_.triangles[t];
    return {X_AO_.apply(other_.vertices[f[0]]), X_AO_.apply(other_.vertices[f[1]]),
            X_AO_.apply(other_.vertices[f[2]])};
  }

  /// Calls visit(t) for each of the other's triangles that meets a part
  /// triangle at the edge (v, w): the only ones the edge can cross. Stops when
  /// visit returns true; returns whether it did.
  template <typename Visit>
  bool for_each_crossing(std::uint32_t v, std::uint32_t w, Visit visit) const {
    for (std::uint32_t k = around_.offsets[v]; k < around_.offsets[v + 1]; ++k) {
      const std::uint32_t t = around_.triangles[k];
      const TriangleIndices& f = part_.triangles[t];
      if (f[0] != w && f[1] != w && f[2] != w) continue;
      auto it = std::lower_bound(crossings_.begin(), crossings_.end(), std::pair{t, 0u});
      for (; it != crossings_.end() && it->first == t; ++it) {
        if (visit(it->second)) return true;
      }
    }
    return false;
  }

  /// Does the edge (v, w) of the part cross the other's surface?
  bool cut(std::uint32_t v, std::uint32_t w) const {
    const Vec3 pv = vertex(v), pw = vertex(w);
    return for_each_crossing(
        v, w, [&](std::uint32_t t) { return segment_meets_triangle(pv, pw, other_triangle(t)); });
  }

  const TriangleDistanceTree& tree() {
    if (!tree_) {
      std::vector<detail::TriangleVertices> triangles;
      triangles.reserve(other_.triangles.size());
      for (std::uint32_t t = 0; t < other_.triangles.size(); ++t) {
        triangles.push_back(other_triangle(t));
      }
      tree_.emplace(std::move(triangles));
    }
    return *tree_;
  }

  /// Where along the edge (v, w) it meets the other's surface: the
  /// fractions of the way from v at which it meets a triangle whose plane it
  /// does not lie in, sorted; empty when it crosses no triangle from one side
  /// strictly to the other (an edge that only touches the surface has no
  /// stretch inside that the vertex regions do not measure).
  std::vector<Real> edge_crossings(std::uint32_t v, std::uint32_t w) const {
    const Vec3 pv = vertex(v), pw = vertex(w);
    std::vector<Real> at;
    bool proper = false;
    for_each_crossing(v, w, [&](std::uint32_t t) {
      const detail::TriangleVertices tri = other_triangle(t);
      const int sv = orient3d(tri[0], tri[1], tri[2], pv);
      const int sw = orient3d(tri[0], tri[1], tri[2], pw);
      if (sv * sw > 0 || (sv == 0 && sw == 0)) return false;
      const int o0 = orient3d(pv, pw, tri[0], tri[1]);
      const int o1 = orient3d(pv, pw, tri[1], tri[2]);
      const int o2 = orient3d(pv, pw, tri[2], tri[0]);
      const bool meets = (o0 >= 0 && o1 >= 0 && o2 >= 0) || (o0 <= 0 && o1 <= 0 && o2 <= 0);
      if (!meets) return false;
      proper = proper || sv * sw < 0;
      const Vec3 n = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
      const Real dv = n.dot(pv - tri[0]), dw = n.dot(pw - tri[0]);
      if (dv != dw) at.push_back(std::clamp(dv / (dv - dw), Real{0}, Real{1}));
      return false;
    });
    if (!proper) return {};
    std::sort(at.begin(), at.end());
    at.erase(std::unique(at.begin(), at.end()), at.end());
    return at;
  }

  /// The deepest point inside the other of the edges of the part's
  /// triangles `seeds` that cross its surface, where deeper than `known`;
  /// `known` otherwise.
  ///
  /// Why: two parts can cross with no vertex of either inside the other (a
  /// rod through a plate, both ends out), and then the vertex regions
  /// measure nothing. But where two surfaces cross, an edge of one crosses
  /// a face of the other, so some edge has a stretch inside.
  ///
  /// Each such edge is cut at its crossings with the other's surface into
  /// stretches that lie wholly on one side. The deepest point of a stretch
  /// is found by branch and bound on the distance to the other's surface
  /// (1-Lipschitz along the edge, and for each triangle convex, so a piece
  /// is no deeper than the farther of its ends from the triangle nearest
  /// either end), best piece first over all the edges, to within the
  /// resolution (or a thousandth of the depth) and at most kEdgeProbes
  /// distance queries a call beyond the stretches' ends; a stretch is located (one exact
  /// point-in-solid test) only when it could beat the deepest point so far.
  /// The deepest point found is located again, as the vertex regions' is.
  Real edge_reach(const std::vector<std::uint32_t>& seeds, Real known) {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
    for (const std::uint32_t t : seeds) {
      const TriangleIndices& f = part_.triangles[t];
      for (int k = 0; k < 3; ++k) edges.push_back(std::minmax(f[k], f[(k + 1) % 3]));
    }
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());

    struct Stretch {
      Vec3 mid;
      PointLocation side = PointLocation::kOnSurface;
      bool located = false;
    };
    struct Piece {
      Real bound;  ///< no point of the piece is deeper
      Vec3 p0, p1;
      TriangleDistanceTree::Nearest n0, n1;
      std::size_t stretch;
      bool operator<(const Piece& other) const { return bound < other.bound; }
    };
    const TriangleDistanceTree* distances = nullptr;
    std::size_t probes = 0;
    const auto probe = [&](const Vec3& p) {
      ++probes;
      return distances->nearest(p);
    };
    const auto piece = [&](const Vec3& p0, const Vec3& p1, const TriangleDistanceTree::Nearest& n0,
                           const TriangleDistanceTree::Nearest& n1, std::size_t stretch) {
      const Real lipschitz = (n0.distance + n1.distance + (p1 - p0).norm()) / 2;
      const Real by_n0 = std::max(n0.distance, distances->distance_to(p1, n0.triangle));
      const Real by_n1 = std::max(distances->distance_to(p0, n1.triangle), n1.distance);
      return Piece{std::min({lipschitz, by_n0, by_n1}), p0, p1, n0, n1, stretch};
    };

    std::vector<Stretch> stretches;
    std::vector<Piece> heap;
    for (const auto& [v, w] : edges) {
      std::vector<Real> at = edge_crossings(v, w);
      if (at.empty()) continue;
      if (!distances) distances = &tree();
      const Vec3 pv = vertex(v), pw = vertex(w);
      at.insert(at.begin(), 0);
      at.push_back(1);
      TriangleDistanceTree::Nearest n0 = probe(pv);
      for (std::size_t i = 0; i + 1 < at.size(); ++i) {
        const Vec3 p0 = pv + at[i] * (pw - pv);
        const Vec3 p1 = at[i + 1] == 1 ? pw : Vec3(pv + at[i + 1] * (pw - pv));
        const TriangleDistanceTree::Nearest n1 = probe(p1);
        if (at[i + 1] > at[i]) {
          stretches.push_back({(p0 + p1) / 2});
          heap.push_back(piece(p0, p1, n0, n1, stretches.size() - 1));
        }
        n0 = n1;
      }
    }
    std::make_heap(heap.begin(), heap.end());
    probes =
        0;  // the budget is the search's: the stretches' ends above are measured whatever it is
    Real deepest = known;
    Vec3 deepest_point = Vec3::Zero();
    while (!heap.empty() && probes < kEdgeProbes) {
      std::pop_heap(heap.begin(), heap.end());
      const Piece p = heap.back();
      heap.pop_back();
      if (p.bound <= deepest + std::max(resolution_, 1e-3 * deepest)) break;
      Stretch& stretch = stretches[p.stretch];
      if (!stretch.located) {
        if (!locator_) locator_.emplace(other_, X_AO_);
        stretch.side = locator_->locate(stretch.mid);
        stretch.located = true;
      }
      if (stretch.side != PointLocation::kInside) continue;
      const Vec3 mid = (p.p0 + p.p1) / 2;
      const TriangleDistanceTree::Nearest n = probe(mid);
      if (n.distance > deepest) {
        deepest = n.distance;
        deepest_point = mid;
      }
      for (const Piece& half :
           {piece(p.p0, mid, p.n0, n, p.stretch), piece(mid, p.p1, n, p.n1, p.stretch)}) {
        heap.push_back(half);
        std::push_heap(heap.begin(), heap.end());
      }
    }
    if (deepest > known && locator_->locate(deepest_point) != PointLocation::kInside) return known;
    return deepest;
  }

  /// The vertices reachable from `from` along uncut edges that had no label,
  /// with `within` (sorted) only through its vertices; labelled `region`.
  std::vector<std::uint32_t> walk(std::vector<std::uint32_t> from, std::uint32_t region,
                                  const std::vector<std::uint32_t>* within) {
    // `from` may be labelled already (a group walked again without `within`).
    std::vector<std::uint32_t> members;
    for (const std::uint32_t v : from) {
      if (label_.emplace(v, region).second) members.push_back(v);
    }
    std::vector<std::uint32_t> stack = std::move(from);
    while (!stack.empty()) {
      const std::uint32_t v = stack.back();
      stack.pop_back();
      for (std::uint32_t k = around_.offsets[v]; k < around_.offsets[v + 1]; ++k) {
        for (const std::uint32_t w : part_.triangles[around_.triangles[k]]) {
          if (label_.contains(w)) continue;
          if (within && !std::binary_search(within->begin(), within->end(), w)) continue;
          if (cut(v, w)) continue;
          label_.emplace(w, region);
          members.push_back(w);
          stack.push_back(w);
        }
      }
    }
    return members;
  }

  /// Labels the group of patch vertices around `start` (joined along uncut
  /// edges among `start_set`), decides it with one point-in-solid test, and,
  /// when it is inside, walks and measures its whole region. An outside
  /// group is not walked further: the rest of the part may be large.
  void label_group(std::uint32_t start, const std::vector<std::uint32_t>& start_set) {
    const auto region = static_cast<std::uint32_t>(regions_.size());
    regions_.push_back(0);
    std::vector<std::uint32_t> group = walk({start}, region, &start_set);
    if (locator_->locate(vertex(start)) == PointLocation::kOutside) return;
    // Inside: the rest of the region, then its deepest vertex.
    for (const std::uint32_t v : walk(group, region, nullptr)) group.push_back(v);
    Real reach = 0;
    std::uint32_t deepest_vertex = start;
    for (const std::uint32_t v : group) {
      const Real d = tree().nearest(vertex(v)).distance;
      if (d > reach) {
        reach = d;
        deepest_vertex = v;
      }
    }
    // A consistency check that costs one more test: a walk that crossed
    // the surface through a pair missing from the input measured outside.
    if (locator_->locate(vertex(deepest_vertex)) == PointLocation::kOutside) reach = 0;
    regions_[region] = reach;
  }

  const Mesh& part_;
  const VertexTriangles& around_;
  const Transform& X_AP_;
  const Mesh& other_;
  const Transform& X_AO_;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> crossings_;  ///< (part tri, other tri)
  Real resolution_;
  std::optional<PointLocator> locator_;       ///< the other's, in A's frame, on first need
  std::optional<TriangleDistanceTree> tree_;  ///< the other's triangles, on first need
  std::unordered_map<std::uint32_t, std::uint32_t> label_;  ///< vertex -> region
  std::vector<Real> regions_;                               ///< reach of each region
};

Vec3 normalized_or(const Vec3& v, Real total_weight, const Vec3& fallback) {
  const Real n = v.norm();
  return n > 1e-9 * total_weight && n > 0 ? Vec3(v / n) : fallback;
}

/// Patch of the pieces `members` (indices into `pieces`).
ContactPatch make_patch(const std::vector<PairPiece>& pieces,
                        const std::vector<std::size_t>& members,
                        std::span<const TrianglePair> pairs, InsideReach* b_in_a,
                        InsideReach* a_in_b, const ContactRequest& request) {
  ContactPatch patch;
  Real area = 0;
  Real length = 0;
  Vec3 area_point = Vec3::Zero();
  Vec3 area_normal = Vec3::Zero();
  Vec3 length_point = Vec3::Zero();
  Vec3 length_normal = Vec3::Zero();
  Vec3 mean_point = Vec3::Zero();
  Vec3 centre_a = Vec3::Zero();
  Vec3 centre_b = Vec3::Zero();
  for (std::size_t m : members) {
    const detail::TrianglePiece& p = pieces[m].piece;
    patch.pairs.push_back(pairs[m]);
    mean_point += p.centroid;
    for (int i = 0; i < 3; ++i) {
      centre_a += pieces[m].t_a[i];
      centre_b += pieces[m].t_b[i];
    }
    if (p.coplanar && p.opposed && p.area > 0) {
      area += p.area;
      area_point += p.area * p.centroid;
      area_normal += p.area * p.n_a;
    } else if (!p.coplanar || p.area == 0) {
      // Flush faces (coplanar, same normal) carry no direction of their own.
      const Real w = p.share * p.length;
      length += w;
      length_point += w * p.centroid;
      length_normal += w * p.normal;
    }
  }
  std::sort(patch.pairs.begin(), patch.pairs.end());
  const Real count = static_cast<Real>(members.size());
  mean_point /= count;

  // Last resort for the normal: from the centre of A's patch triangles to B's.
  const Vec3 first = pieces[members.front()].piece.normal;
  const Vec3 fallback = normalized_or(centre_b - centre_a, 0, first);
  patch.length = length;
  if (area > 0) {
    patch.kind = ContactKind::kFace;
    patch.area = area;
    patch.point = area_point / area;
    patch.normal = normalized_or(area_normal, area, fallback);
  } else if (length > 0) {
    patch.kind = ContactKind::kCurve;
    patch.point = length_point / length;
    patch.normal = normalized_or(length_normal, length, fallback);
  } else {
    patch.kind = ContactKind::kPoint;
    patch.point = mean_point;
    Vec3 sum = Vec3::Zero();
    for (std::size_t m : members) sum += pieces[m].piece.normal;
    patch.normal = normalized_or(sum, count, fallback);
  }

  if (b_in_a == nullptr || a_in_b == nullptr) {  // depth not asked for
    return patch;
  }
  // Depth: how deep B reaches into A and A into B, the larger. Into a
  // closed part: the deepest vertex of the other inside it, in a region
  // connected to the patch, or deeper point of a crossing edge
  // (InsideReach), measured to its surface; this sees the caps of curved
  // overlaps, whose deepest vertices cross nothing, and parts that cross
  // with no vertex inside. Into
  // an open part (no inside): the deepest vertex of a patch triangle behind
  // its patch face (projecting onto the face), over the pairs whose face
  // turns towards the patch normal: exact for flat faces pushed into flat
  // faces, but blind to caps and, through a thin wall, to the far side.
  std::vector<std::uint32_t> triangles_a, triangles_b;
  for (std::size_t m : members) {
    triangles_a.push_back(pairs[m].a);
    triangles_b.push_back(pairs[m].b);
  }
  for (auto* list : {&triangles_a, &triangles_b}) {
    std::sort(list->begin(), list->end());
    list->erase(std::unique(list->begin(), list->end()), list->end());
  }
  const auto behind_faces = [&](bool b_behind_a) {
    Real depth = 0;
    for (std::size_t m : members) {
      const PairPiece& pp = pieces[m];
      if (b_behind_a && pp.piece.n_a.dot(patch.normal) >= kFacingCosine) {
        depth = std::max(depth, depth_behind(pp.t_a, pp.piece.n_a, pp.t_b));
      }
      if (!b_behind_a && -pp.piece.n_b.dot(patch.normal) >= kFacingCosine) {
        depth = std::max(depth, depth_behind(pp.t_b, pp.piece.n_b, pp.t_a));
      }
    }
    return depth;
  };
  const std::optional<Real> b_into_a = b_in_a->reach(triangles_b);
  const std::optional<Real> a_into_b = a_in_b->reach(triangles_a);
  patch.depth = std::max(b_into_a ? *b_into_a : behind_faces(true),
                         a_into_b ? *a_into_b : behind_faces(false));
  patch.penetrating = patch.depth > request.touching_tolerance;
  return patch;
}

}  // namespace

std::string_view contact_kind_name(ContactKind kind) {
  switch (kind) {
    case ContactKind::kFace:
      return "face";
    case ContactKind::kCurve:
      return "curve";
    case ContactKind::kPoint:
      return "point";
  }
  return "point";
}

std::vector<ContactPatch> compute_contacts(const Mesh& a, const Mesh& b, const Transform& X_AB,
                                           std::span<const TrianglePair> pairs_in,
                                           const ContactRequest& request) {
  std::vector<TrianglePair> pairs(pairs_in.begin(), pairs_in.end());
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  if (pairs.empty()) return {};

  // Each pair's triangles in A's frame (B's vertices mapped by the same
  // Transform::apply as the collision query) and its piece.
  std::vector<PairPiece> pieces(pairs.size());
  Real scale = 1;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const TriangleIndices& fa = a.triangles.at(pairs[i].a);
    const TriangleIndices& fb = b.triangles.at(pairs[i].b);
    for (int k = 0; k < 3; ++k) {
      pieces[i].t_a[k] = a.vertices[fa[k]];
      pieces[i].t_b[k] = X_AB.apply(b.vertices[fb[k]]);
      scale = std::max(
          {scale, pieces[i].t_a[k].cwiseAbs().maxCoeff(), pieces[i].t_b[k].cwiseAbs().maxCoeff()});
    }
  }
  const Real coplanar_tolerance = std::max(request.coplanar_tolerance, 1e-12 * scale);
  const Real merge = std::max(request.merge_distance, 1e-9 * scale);
  for (PairPiece& p : pieces)
    p.piece = detail::intersect_triangles(p.t_a, p.t_b, coplanar_tolerance);
  // The surfaces' neighbourhoods, for the coplanar search and the depth.
  const bool walks = request.nearly_coplanar_pairs || request.estimate_depth;
  const VertexTriangles around_a = walks ? VertexTriangles(a) : VertexTriangles();
  const VertexTriangles around_b = walks ? VertexTriangles(b) : VertexTriangles();
  if (request.nearly_coplanar_pairs) {
    add_nearly_coplanar_pairs(a, b, X_AB, coplanar_tolerance, around_a, around_b, pairs, pieces);
  }
  for (PairPiece& p : pieces) {
    p.lo = p.hi = p.piece.points.front();
    for (const Vec3& x : p.piece.points) {
      p.lo = p.lo.cwiseMin(x);
      p.hi = p.hi.cwiseMax(x);
    }
    p.lo.array() -= merge;
    p.hi.array() += merge;
  }

  // Join pieces that meet: sweep the widened bounds along x, then the piece distance.
  std::vector<std::size_t> order(pieces.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) {
    return pieces[i].lo.x() < pieces[j].lo.x() || (pieces[i].lo.x() == pieces[j].lo.x() && i < j);
  });
  DisjointSets sets(pieces.size());
  for (std::size_t oi = 0; oi < order.size(); ++oi) {
    const PairPiece& p = pieces[order[oi]];
    for (std::size_t oj = oi + 1; oj < order.size() && pieces[order[oj]].lo.x() <= p.hi.x(); ++oj) {
      const PairPiece& q = pieces[order[oj]];
      if (q.lo.y() > p.hi.y() || q.hi.y() < p.lo.y() || q.lo.z() > p.hi.z() ||
          q.hi.z() < p.lo.z()) {
        continue;
      }
      if (sets.find(order[oi]) == sets.find(order[oj])) continue;
      if (detail::piece_distance(p.piece, q.piece) <= merge) sets.join(order[oi], order[oj]);
    }
  }

  // Members of each patch in pair order; patches in order of their first pair.
  std::vector<std::vector<std::size_t>> groups;
  std::vector<std::size_t> group_of(pieces.size(), 0);
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    const std::size_t root = sets.find(i);
    if (root == i) {
      group_of[i] = groups.size();
      groups.emplace_back();
    }
    groups[group_of[root]].push_back(i);
  }
  std::vector<ContactPatch> patches;
  patches.reserve(groups.size());
  std::vector<std::pair<std::uint32_t, std::uint32_t>> b_crossing_a, a_crossing_b;
  for (const TrianglePair& p : pairs) {
    b_crossing_a.emplace_back(p.b, p.a);
    a_crossing_b.emplace_back(p.a, p.b);
  }
  const Transform identity;
  std::optional<InsideReach> b_in_a, a_in_b;
  if (request.estimate_depth) {
    const Real resolution = request.touching_tolerance / 10;
    b_in_a.emplace(b, around_b, X_AB, a, identity, std::move(b_crossing_a), resolution);
    a_in_b.emplace(a, around_a, identity, b, X_AB, std::move(a_crossing_b), resolution);
  }
  for (const std::vector<std::size_t>& g : groups) {
    patches.push_back(make_patch(pieces, g, pairs, b_in_a ? &*b_in_a : nullptr,
                                 a_in_b ? &*a_in_b : nullptr, request));
  }
  std::sort(patches.begin(), patches.end(), [](const ContactPatch& x, const ContactPatch& y) {
    return x.pairs.front() < y.pairs.front();
  });
  return patches;
}

std::vector<ContactPatch> compute_contacts(const CollisionModel& a, const CollisionModel& b,
                                           const Transform& X_AB, const ContactRequest& request) {
  const CollideResult hits = a.collide(b, X_AB, {.all_pairs = true, .front = request.front});
  return compute_contacts(a.mesh(), b.mesh(), X_AB, hits.pairs, request);
}

}  // namespace dovetail::collision
