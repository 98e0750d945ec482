#include "dovetail/collision/contacts.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <unordered_set>

#include "tri_intersection.h"

namespace dovetail::collision {

namespace {

/// Union-find over piece indices, smaller root kept (so a patch's root is its first pair).
class DisjointSets {
 public:
  explicit DisjointSets(std::size_t n) : parent_(n) {
    std::iota(parent_.begin(), parent_.end(), std::size_t{0});
  }
  std::size_t find(std::size_t i) {
    while (parent_[i] != i) {
      parent_[i] = parent_[parent_[i]];
      i = parent_[i];
    }
    return i;
  }
  void join(std::size_t i, std::size_t j) {
    i = find(i);
    j = find(j);
    if (i != j) parent_[std::max(i, j)] = std::min(i, j);
  }

 private:
  std::vector<std::size_t> parent_;
};

/// One pair with its triangles in A's frame and its piece of intersection.
struct PairPiece {
  detail::TriangleVertices t_a;
  detail::TriangleVertices t_b;
  detail::TrianglePiece piece;
  Vec3 lo;  ///< piece bounds, widened by the merge distance
  Vec3 hi;
};

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

/// Triangles around each vertex, in compressed rows.
struct VertexTriangles {
  std::vector<std::uint32_t> offsets;
  std::vector<std::uint32_t> triangles;

  explicit VertexTriangles(const Mesh& mesh) : offsets(mesh.vertices.size() + 1, 0) {
    for (const TriangleIndices& f : mesh.triangles) {
      for (std::uint32_t v : f) ++offsets[v + 1];
    }
    std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
    triangles.resize(offsets.back());
    std::vector<std::uint32_t> fill(offsets.begin(), offsets.end() - 1);
    for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
      for (std::uint32_t v : mesh.triangles[t]) triangles[fill[v]++] = t;
    }
  }

  /// Calls visit(t) for every triangle sharing a vertex with `f` (f's own included).
  template <typename Visit>
  void around(const TriangleIndices& f, Visit&& visit) const {
    for (std::uint32_t v : f) {
      for (std::uint32_t k = offsets[v]; k < offsets[v + 1]; ++k) visit(triangles[k]);
    }
  }
};

/// Quick test before the piece: every vertex of each triangle within `tolerance` of the other's
/// plane.
bool nearly_coplanar(const detail::TriangleVertices& t_a, const detail::TriangleVertices& t_b,
                     Real tolerance) {
  const Vec3 n_a = (t_a[1] - t_a[0]).cross(t_a[2] - t_a[0]).normalized();
  const Vec3 n_b = (t_b[1] - t_b[0]).cross(t_b[2] - t_b[0]).normalized();
  for (int i = 0; i < 3; ++i) {
    if (std::abs((t_b[i] - t_a[0]).dot(n_a)) > tolerance) return false;
    if (std::abs((t_a[i] - t_b[0]).dot(n_b)) > tolerance) return false;
  }
  return true;
}

/// Adds the pairs of faces that lie on each other within the coplanar
/// tolerance but that the exact test separates by a rounding-size gap
/// (faces of a rotated part resting on another): starting next to the
/// reported pairs, pairs one triangle step apart are tried, and every pair
/// found with an overlap of positive area spreads the search further.
void add_nearly_coplanar_pairs(const Mesh& a, const Mesh& b, const Transform& X_AB, Real tolerance,
                               std::vector<TrianglePair>& pairs, std::vector<PairPiece>& pieces) {
  const VertexTriangles around_a(a);
  const VertexTriangles around_b(b);
  const auto key = [](std::uint32_t ta, std::uint32_t tb) {
    return (static_cast<std::uint64_t>(ta) << 32) | tb;
  };
  std::unordered_set<std::uint64_t> seen;
  for (const TrianglePair& p : pairs) seen.insert(key(p.a, p.b));
  std::vector<TrianglePair> queue;
  const auto spread = [&](const TrianglePair& p) {
    around_a.around(a.triangles[p.a], [&](std::uint32_t t) { queue.push_back({t, p.b}); });
    around_b.around(b.triangles[p.b], [&](std::uint32_t t) { queue.push_back({p.a, t}); });
  };
  for (std::size_t i = 0; i < pairs.size(); ++i) spread(pairs[i]);
  while (!queue.empty()) {
    const TrianglePair p = queue.back();
    queue.pop_back();
    if (!seen.insert(key(p.a, p.b)).second) continue;
    PairPiece candidate;
    for (int k = 0; k < 3; ++k) {
      candidate.t_a[k] = a.vertices[a.triangles[p.a][k]];
      candidate.t_b[k] = X_AB.apply(b.vertices[b.triangles[p.b][k]]);
    }
    if (!nearly_coplanar(candidate.t_a, candidate.t_b, tolerance)) continue;
    candidate.piece = detail::intersect_triangles(candidate.t_a, candidate.t_b, tolerance);
    if (candidate.piece.area <= 0) continue;
    pairs.push_back(p);
    pieces.push_back(std::move(candidate));
    spread(p);
  }
}

Vec3 normalized_or(const Vec3& v, Real total_weight, const Vec3& fallback) {
  const Real n = v.norm();
  return n > 1e-9 * total_weight && n > 0 ? Vec3(v / n) : fallback;
}

/// Patch of the pieces `members` (indices into `pieces`).
ContactPatch make_patch(const std::vector<PairPiece>& pieces,
                        const std::vector<std::size_t>& members,
                        std::span<const TrianglePair> pairs, const ContactRequest& request) {
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

  // Depth: the deepest vertex of one triangle of a pair behind the other's
  // face (inside the other part, projecting onto the face), over the pairs
  // whose face turns towards the patch normal.
  patch.depth = 0;
  for (std::size_t m : members) {
    const PairPiece& pp = pieces[m];
    if (pp.piece.n_a.dot(patch.normal) >= kFacingCosine) {
      patch.depth = std::max(patch.depth, depth_behind(pp.t_a, pp.piece.n_a, pp.t_b));
    }
    if (-pp.piece.n_b.dot(patch.normal) >= kFacingCosine) {
      patch.depth = std::max(patch.depth, depth_behind(pp.t_b, pp.piece.n_b, pp.t_a));
    }
  }
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
  add_nearly_coplanar_pairs(a, b, X_AB, coplanar_tolerance, pairs, pieces);
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
  for (const std::vector<std::size_t>& g : groups) {
    patches.push_back(make_patch(pieces, g, pairs, request));
  }
  std::sort(patches.begin(), patches.end(), [](const ContactPatch& x, const ContactPatch& y) {
    return x.pairs.front() < y.pairs.front();
  });
  return patches;
}

std::vector<ContactPatch> compute_contacts(const CollisionModel& a, const CollisionModel& b,
                                           const Transform& X_AB, const ContactRequest& request) {
  const CollideResult hits = a.collide(b, X_AB, {.all_pairs = true});
  return compute_contacts(a.mesh(), b.mesh(), X_AB, hits.pairs, request);
}

}  // namespace dovetail::collision
