#include "dovetail/collision/containment.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <numbers>
#include <tuple>
#include <vector>

#include "core/disjoint_sets.h"
#include "core/predicates_inline.h"

namespace dovetail::collision {

namespace {

/// The triangles' bounding boxes and their union: a ray skips the triangles
/// whose box it misses (PointLocator builds them once for many points).
struct TriangleBoxes {
  std::vector<Vec3> lo, hi;
  Vec3 all_lo, all_hi;
  Real magnitude = 0;  ///< the largest |coordinate|
};

/// A directed edge of a triangle, between welded vertices.
struct Edge {
  std::uint32_t from;
  std::uint32_t to;
  std::uint32_t triangle;
  friend auto operator<=>(const Edge&, const Edge&) = default;
};

std::vector<Edge> directed_edges(const Mesh& mesh) {
  const std::vector<std::uint32_t> id = welded_ids(mesh.vertices);
  std::vector<Edge> edges;
  edges.reserve(3 * mesh.triangles.size());
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    const TriangleIndices& f = mesh.triangles[t];
    for (int k = 0; k < 3; ++k) edges.push_back({id[f[k]], id[f[(k + 1) % 3]], t});
  }
  std::sort(edges.begin(), edges.end());
  return edges;
}

/// Connected surface components (shells) of a mesh: triangles joined through
/// shared edges. Returns the shell of each triangle and the shell count.
std::pair<std::vector<std::uint32_t>, std::size_t> shells(const Mesh& mesh) {
  detail::DisjointSets sets(mesh.triangles.size());
  std::vector<Edge> edges = directed_edges(mesh);
  for (Edge& e : edges) {
    if (e.from > e.to) std::swap(e.from, e.to);
  }
  std::sort(edges.begin(), edges.end());
  for (std::size_t k = 1; k < edges.size(); ++k) {
    if (edges[k].from == edges[k - 1].from && edges[k].to == edges[k - 1].to) {
      sets.join(edges[k].triangle, edges[k - 1].triangle);
    }
  }
  std::vector<std::uint32_t> shell(mesh.triangles.size());
  std::vector<std::uint32_t> number(mesh.triangles.size(), UINT32_MAX);
  std::size_t count = 0;
  for (std::uint32_t t = 0; t < shell.size(); ++t) {
    const std::size_t r = sets.find(t);
    if (number[r] == UINT32_MAX) number[r] = static_cast<std::uint32_t>(count++);
    shell[t] = number[r];
  }
  return {std::move(shell), count};
}

/// Signed crossings per shell (the winding number of the segment's start
/// about it), or a verdict that needs no count.
struct RayOutcome {
  enum { kCounted, kOnSurface, kDegenerate } status = kCounted;
  /// Per shell: crossings from the back of a triangle to its front, less
  /// those from the front to its back.
  std::vector<int> winding;
};

bool same_closed_side(int e1, int e2, int e3) {
  return (e1 >= 0 && e2 >= 0 && e3 >= 0) || (e1 <= 0 && e2 <= 0 && e3 <= 0);
}

/// Whether segment p -> p + d may meet the box [lo, hi]: a slab test on the
/// box widened by `margin`, far above the rounding of the test, so that it
/// never rejects a box the segment meets.
bool segment_may_meet(const Vec3& p, const Vec3& d, const Vec3& lo, const Vec3& hi, Real margin) {
  Real t0 = 0, t1 = 1;
  for (int k = 0; k < 3; ++k) {
    const Real a = lo[k] - margin - p[k], b = hi[k] + margin - p[k];
    if (d[k] == 0) {
      if (a > 0 || b < 0) return false;
      continue;
    }
    Real u = a / d[k], v = b / d[k];
    if (u > v) std::swap(u, v);
    t0 = std::max(t0, u);
    t1 = std::min(t1, v);
    if (t0 > t1) return false;
  }
  return true;
}

/// Crossings of segment p -> q (q outside the mesh's bounds) with every
/// triangle, decided by exact signs. Degenerate when the segment meets an
/// edge or vertex, or lies in a triangle's plane. With `boxes`, the
/// triangles whose box the segment misses are skipped: they add no crossing
/// and cannot hold p, so only the choice of direction can change (a
/// segment in the plane of a far triangle is no longer degenerate), never
/// the location.
RayOutcome cast(const std::vector<Vec3>& vertices, const std::vector<TriangleIndices>& triangles,
                const std::vector<std::uint32_t>& shell, std::size_t shell_count, const Vec3& p,
                const Vec3& q, const TriangleBoxes* boxes) {
  RayOutcome out;
  out.winding.assign(shell_count, 0);
  const Vec3 d = q - p;
  const Real margin =
      boxes ? 1e-9 * (boxes->magnitude + p.cwiseAbs().maxCoeff() + d.cwiseAbs().maxCoeff()) +
                  std::numeric_limits<Real>::min()
            : 0;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    if (boxes && !segment_may_meet(p, d, boxes->lo[t], boxes->hi[t], margin)) continue;
    const Vec3& a = vertices[triangles[t][0]];
    const Vec3& b = vertices[triangles[t][1]];
    const Vec3& c = vertices[triangles[t][2]];
    const int sp = detail::orient3d_filtered(a, b, c, p);
    const int sq = detail::orient3d_filtered(a, b, c, q);
    if (sp == 0 && sq == 0) return {RayOutcome::kDegenerate, {}};
    if (sp == sq || sq == 0) continue;  // q, outside the bounds, is in no triangle
    const int e1 = detail::orient3d_filtered(p, q, a, b);
    const int e2 = detail::orient3d_filtered(p, q, b, c);
    const int e3 = detail::orient3d_filtered(p, q, c, a);
    if (sp == 0) {
      // p on the plane: on the surface when the line through p meets the closed triangle.
      if (same_closed_side(e1, e2, e3)) return {RayOutcome::kOnSurface, {}};
      continue;
    }
    if (!same_closed_side(e1, e2, e3)) continue;
    if (e1 == 0 || e2 == 0 || e3 == 0) return {RayOutcome::kDegenerate, {}};
    // Leaving through the triangle's back side or entering through it.
    out.winding[shell[t]] += sp < 0 ? 1 : -1;
  }
  return out;
}

/// A fixed sequence of directions in general position (no component zero,
/// none along a coordinate plane or diagonal), the same on every platform.
Vec3 ray_direction(int k) {
  const Real golden = std::numbers::phi - 1;
  const Real u = std::fmod(0.1234 + k * golden, 1.0);
  const Real v = std::fmod(0.3719 + k * 0.7548776662466927, 1.0);
  const Real z = 0.2 + 0.6 * u;
  const Real angle = 2 * std::numbers::pi * (0.05 + 0.9 * v);
  return Vec3(std::cos(angle) + 0.017, std::sin(angle) + 0.031, z);
}

/// Generalized winding number (sum of solid angles / 4 pi), only used when
/// every one of the fixed ray directions is degenerate.
Real winding_number(const std::vector<Vec3>& vertices,
                    const std::vector<TriangleIndices>& triangles,
                    const std::vector<std::uint32_t>& shell, std::size_t s, const Vec3& p) {
  Real sum = 0;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    if (shell[t] != s) continue;
    const Vec3 a = vertices[triangles[t][0]] - p;
    const Vec3 b = vertices[triangles[t][1]] - p;
    const Vec3 c = vertices[triangles[t][2]] - p;
    const Real la = a.norm(), lb = b.norm(), lc = c.norm();
    const Real num = a.dot(b.cross(c));
    const Real den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    sum += 2 * std::atan2(num, den);
  }
  return sum / (4 * std::numbers::pi);
}

/// Location of p against the surface (vertices, triangles), overall and per shell.
struct Located {
  PointLocation location = PointLocation::kOutside;
  bool in_some_shell = false;
};

Located locate(const std::vector<Vec3>& vertices, const std::vector<TriangleIndices>& triangles,
               const std::vector<std::uint32_t>& shell, std::size_t shell_count, const Vec3& p,
               const TriangleBoxes* boxes = nullptr) {
  Vec3 lo, hi;
  if (boxes) {
    lo = boxes->all_lo;
    hi = boxes->all_hi;
  } else {
    lo = hi = vertices[triangles[0][0]];
    for (const TriangleIndices& f : triangles) {
      for (std::uint32_t i : f) {
        lo = lo.cwiseMin(vertices[i]);
        hi = hi.cwiseMax(vertices[i]);
      }
    }
  }
  const Real reach = 4 * ((hi - lo).norm() + (p - 0.5 * (lo + hi)).norm()) + 1;
  constexpr int kDirections = 64;
  for (int k = 0; k < kDirections; ++k) {
    const Vec3 q = p + reach * ray_direction(k).normalized();
    const RayOutcome r = cast(vertices, triangles, shell, shell_count, p, q, boxes);
    if (r.status == RayOutcome::kOnSurface) return {PointLocation::kOnSurface, true};
    if (r.status == RayOutcome::kDegenerate) continue;
    // Inside where the surfaces wind around p: one body or more (bodies
    // that touch or overlap, a face written twice); a cavity's shell winds
    // the other way and cancels its housing's.
    long total = 0;
    bool any = false;
    for (const int w : r.winding) {
      total += w;
      any = any || w != 0;
    }
    return {total != 0 ? PointLocation::kInside : PointLocation::kOutside, any};
  }
  Located out;
  long total = 0;
  for (std::size_t s = 0; s < shell_count; ++s) {
    const long w = std::lround(winding_number(vertices, triangles, shell, s, p));
    total += w;
    out.in_some_shell = out.in_some_shell || w != 0;
  }
  out.location = total != 0 ? PointLocation::kInside : PointLocation::kOutside;
  return out;
}

/// Is point p (in the mesh's frame) in the solid, and in some shell, of `mesh` with `vertices`?
Located locate_in(const Mesh& mesh, const std::vector<Vec3>& vertices, const Vec3& p) {
  const auto [shell, count] = shells(mesh);
  return locate(vertices, mesh.triangles, shell, count, p);
}

/// One vertex of each shell of `part` (the first vertex of the shell's
/// first triangle): with the surfaces apart, a shell lies wholly on one side
/// of the other part's surface, so its vertex speaks for it.
std::vector<std::uint32_t> shell_vertices(const Mesh& part) {
  const auto [shell, count] = shells(part);
  std::vector<std::uint32_t> vertex(count, UINT32_MAX);
  for (std::size_t t = 0; t < shell.size(); ++t) {
    if (vertex[shell[t]] == UINT32_MAX) vertex[shell[t]] = part.triangles[t][0];
  }
  return vertex;
}

/// Whether every shell of the part whose vertices are `part_vertices` (in
/// `solid`'s frame) lies in the solid of `solid`, and whether every one lies
/// inside some shell of it (in its solid or a cavity it encloses).
std::pair<Inside, Inside> shells_inside(const Mesh& solid, const std::vector<Vec3>& solid_vertices,
                                        const Mesh& part, const std::vector<Vec3>& part_vertices) {
  const auto [shell, count] = shells(solid);
  bool all_inside = true, all_enclosed = true;
  for (const std::uint32_t v : shell_vertices(part)) {
    const Located l = locate(solid_vertices, solid.triangles, shell, count, part_vertices[v]);
    all_inside = all_inside && l.location == PointLocation::kInside;
    all_enclosed = all_enclosed && l.location != PointLocation::kOnSurface && l.in_some_shell;
  }
  return {all_inside ? Inside::kYes : Inside::kNo, all_enclosed ? Inside::kYes : Inside::kNo};
}

}  // namespace

bool is_closed(const Mesh& mesh) {
  if (mesh.triangles.empty()) return false;
  // Closed: every directed edge is used as often as its reverse.
  const std::vector<Edge> edges = directed_edges(mesh);  // sorted by (from, to)
  const auto uses = [&](std::uint32_t from, std::uint32_t to) {
    const auto [first, last] = std::equal_range(
        edges.begin(), edges.end(), Edge{from, to, 0}, [](const Edge& x, const Edge& y) {
          return std::tie(x.from, x.to) < std::tie(y.from, y.to);
        });
    return last - first;
  };
  for (std::size_t k = 0; k < edges.size();) {
    const Edge& e = edges[k];
    const auto n = uses(e.from, e.to);
    // An edge of a triangle with two welded corners has no direction to cancel.
    if (e.from != e.to && uses(e.to, e.from) != n) return false;
    k += static_cast<std::size_t>(n);
  }
  return true;
}

SurfaceEdges surface_edges(const Mesh& mesh) {
  // Each edge by its lower vertex first, with +1 for a use in that direction
  // and -1 for the other: a closed surface uses every edge as often each way.
  std::vector<std::tuple<std::uint32_t, std::uint32_t, int>> uses;
  uses.reserve(3 * mesh.triangles.size());
  for (const Edge& e : directed_edges(mesh)) {
    // An edge of a triangle with two welded corners has no direction to cancel.
    if (e.from == e.to) continue;
    if (e.from < e.to) {
      uses.emplace_back(e.from, e.to, 1);
    } else {
      uses.emplace_back(e.to, e.from, -1);
    }
  }
  std::sort(uses.begin(), uses.end());
  SurfaceEdges counts;
  for (std::size_t k = 0; k < uses.size();) {
    std::size_t n = 0;
    int balance = 0;
    std::size_t j = k;
    for (; j < uses.size() && std::get<0>(uses[j]) == std::get<0>(uses[k]) &&
           std::get<1>(uses[j]) == std::get<1>(uses[k]);
         ++j) {
      ++n;
      balance += std::get<2>(uses[j]);
    }
    // An odd count cannot balance, so it is a hole whatever the winding.
    if (n % 2 == 1) {
      ++counts.open;
    } else if (balance != 0) {
      ++counts.misoriented;
    }
    k = j;
  }
  return counts;
}

PointLocation locate_point(const Mesh& mesh, const Vec3& p_M) {
  if (mesh.triangles.empty()) return PointLocation::kOutside;
  return locate_in(mesh, mesh.vertices, p_M).location;
}

bool point_inside(const Mesh& mesh, const Vec3& p_M) {
  return locate_point(mesh, p_M) != PointLocation::kOutside;
}

struct PointLocator::Boxes : TriangleBoxes {};

PointLocator::PointLocator(const Mesh& mesh, const Transform& X_FM)
    : mesh_(mesh), closed_(is_closed(mesh)) {
  vertices_F_.reserve(mesh.vertices.size());
  for (const Vec3& v : mesh.vertices) vertices_F_.push_back(X_FM.apply(v));
  // Inside or outside is the parity over all triangles; which shell a
  // crossing belongs to matters only for "enclosed by a shell", which a
  // location does not report, so every triangle counts as one shell.
  shell_.assign(mesh.triangles.size(), 0);
  shell_count_ = 1;
  // The triangles' boxes, for the rays of many points to skip most triangles.
  auto boxes = std::make_shared<Boxes>();
  boxes->lo.reserve(mesh.triangles.size());
  boxes->hi.reserve(mesh.triangles.size());
  boxes->all_lo = Vec3::Constant(std::numeric_limits<Real>::infinity());
  boxes->all_hi = -boxes->all_lo;
  for (const TriangleIndices& f : mesh.triangles) {
    const Vec3 &a = vertices_F_[f[0]], &b = vertices_F_[f[1]], &c = vertices_F_[f[2]];
    boxes->lo.push_back(a.cwiseMin(b).cwiseMin(c));
    boxes->hi.push_back(a.cwiseMax(b).cwiseMax(c));
    boxes->all_lo = boxes->all_lo.cwiseMin(boxes->lo.back());
    boxes->all_hi = boxes->all_hi.cwiseMax(boxes->hi.back());
  }
  boxes->magnitude =
      std::max(boxes->all_lo.cwiseAbs().maxCoeff(), boxes->all_hi.cwiseAbs().maxCoeff());
  boxes_ = std::move(boxes);
}

PointLocation PointLocator::locate(const Vec3& p_F) const {
  if (mesh_.triangles.empty()) return PointLocation::kOutside;
  return dovetail::collision::locate(vertices_F_, mesh_.triangles, shell_, shell_count_, p_F,
                                     boxes_.get())
      .location;
}

ContainmentResult contains(const CollisionModel& outer, const CollisionModel& inner,
                           const Transform& X_outer_inner) {
  ContainmentResult result;
  const Mesh& mo = outer.mesh();
  const Mesh& mi = inner.mesh();
  const bool outer_closed = is_closed(mo);
  const bool inner_closed = is_closed(mi);
  result.surfaces_intersect = outer.collide(inner, X_outer_inner).colliding;
  if (result.surfaces_intersect) {
    if (outer_closed) result.inner_in_outer = result.inner_enclosed_by_outer = Inside::kNo;
    if (inner_closed) result.outer_in_inner = result.outer_enclosed_by_inner = Inside::kNo;
    return result;
  }
  // Disjoint surfaces: one vertex of each shell decides for that shell, and a
  // part is inside only when all its shells are. Both parts are taken in
  // outer's frame, inner's vertices mapped by the same Transform::apply as
  // the collision query, so the points are those it tested.
  std::vector<Vec3> inner_in_outer_frame(mi.vertices.size());
  for (std::size_t i = 0; i < mi.vertices.size(); ++i) {
    inner_in_outer_frame[i] = X_outer_inner.apply(mi.vertices[i]);
  }
  if (outer_closed) {
    std::tie(result.inner_in_outer, result.inner_enclosed_by_outer) =
        shells_inside(mo, mo.vertices, mi, inner_in_outer_frame);
  }
  if (inner_closed) {
    std::tie(result.outer_in_inner, result.outer_enclosed_by_inner) =
        shells_inside(mi, inner_in_outer_frame, mo, mo.vertices);
  }
  return result;
}

ContainmentResult contains(const Mesh& outer, const Mesh& inner, const Transform& X_outer_inner) {
  // Models over the caller's meshes for this call only: an empty owner, no copy.
  const auto model_outer = build_model(
      Method::kAabb, std::shared_ptr<const Mesh>(std::shared_ptr<const Mesh>(), &outer));
  const auto model_inner = build_model(
      Method::kAabb, std::shared_ptr<const Mesh>(std::shared_ptr<const Mesh>(), &inner));
  return contains(*model_outer, *model_inner, X_outer_inner);
}

}  // namespace dovetail::collision
