/// \file convex_hull.cpp
/// Convex hulls through reentrant qhull, made exact: qhull's triangulated hull
/// is accepted only when exact orient3d proves it closed, consistently
/// oriented, free of zero-area faces, and holding every input point on or
/// below every face; otherwise an exact incremental hull is built from qhull's
/// vertices and every point outside it is added. Small point sets skip qhull
/// and go straight to the exact incremental hull (docs/convex.md).

#include <libqhull_r/qhull_ra.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "convex/convex_internal.h"
#include "core/expansion.h"
#include "core/predicates_inline.h"
#include "dovetail/collision/convex.h"
#include "dovetail/collision/predicates.h"

namespace dovetail::collision {

namespace detail {

int dot_difference_sign(const Vec3& d, const Vec3& u, const Vec3& v) {
  Real h[13];
  int m = 0;
  for (int i = 0; i < 3; ++i) {
    // Exact products d_i u_i and d_i v_i as value plus error term.
    const Real pu = d[i] * u[i];
    const Real eu = std::fma(d[i], u[i], -pu);
    const Real pv = d[i] * v[i];
    const Real ev = std::fma(d[i], v[i], -pv);
    m = grow_expansion(h, m, pu);
    m = grow_expansion(h, m, eu);
    m = grow_expansion(h, m, -pv);
    m = grow_expansion(h, m, -ev);
  }
  const Real top = h[m - 1];
  return (top > 0) - (top < 0);
}

}  // namespace detail

std::uint32_t ConvexHull::support(const Vec3& d, std::uint32_t start) const {
  return detail::hull_support(*this, d, start);
}

namespace {

using Triangles = std::vector<TriangleIndices>;

/// The points the triangles use, ascending, each once.
std::vector<std::uint32_t> vertex_ids(const Triangles& triangles) {
  std::vector<std::uint32_t> ids;
  ids.reserve(3 * triangles.size());
  for (const TriangleIndices& t : triangles) ids.insert(ids.end(), t.begin(), t.end());
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return ids;
}

/// An inconsistency inside the exact hull (a bug, never expected).
struct HullInternalError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

[[noreturn]] void fail(const std::string& source, const std::string& what) {
  throw std::invalid_argument(source + ": convex hull: " + what);
}

/// Indices of four affinely independent points (decided exactly), or false.
bool find_simplex(std::span<const Vec3> p, std::array<std::uint32_t, 4>& s) {
  const std::uint32_t n = static_cast<std::uint32_t>(p.size());
  s[0] = 0;
  std::uint32_t i = 1;
  while (i < n && p[i] == p[0]) ++i;
  if (i == n) return false;
  s[1] = i;
  for (i = 1; i < n && is_degenerate_triangle(p[s[0]], p[s[1]], p[i]);) ++i;
  if (i == n) return false;
  s[2] = i;
  for (i = 1; i < n && orient3d(p[s[0]], p[s[1]], p[s[2]], p[i]) == 0;) ++i;
  if (i == n) return false;
  s[3] = i;
  return true;
}

/// Owns one reentrant qhull run and its error stream; frees both.
class QhullRun {
 public:
  QhullRun() : qh_(std::make_unique<qhT>()) {
    err_ = open_memstream(&err_text_, &err_size_);
    qh_zero(qh_.get(), err_);
  }
  QhullRun(const QhullRun&) = delete;
  QhullRun& operator=(const QhullRun&) = delete;
  ~QhullRun() {
    qh_freeqhull(qh_.get(), !qh_ALL);
    int curlong = 0, totlong = 0;
    qh_memfreeshort(qh_.get(), &curlong, &totlong);
    if (err_) std::fclose(err_);
    std::free(err_text_);
  }

  qhT* qh() { return qh_.get(); }
  FILE* err() { return err_; }

  /// First line of qhull's error output that names an error, else the first line.
  std::string message() {
    if (!err_) return "qhull failed";
    std::fflush(err_);
    const std::string text(err_text_ ? err_text_ : "", err_size_);
    std::string first;
    std::size_t pos = 0;
    while (pos < text.size()) {
      std::size_t end = text.find('\n', pos);
      if (end == std::string::npos) end = text.size();
      const std::string line = text.substr(pos, end - pos);
      if (first.empty() && !line.empty()) first = line;
      if (line.find("error") != std::string::npos) return line;
      pos = end + 1;
    }
    return first.empty() ? "qhull failed" : first;
  }

 private:
  std::unique_ptr<qhT> qh_;
  FILE* err_ = nullptr;
  char* err_text_ = nullptr;
  std::size_t err_size_ = 0;
};

/// qhull's triangulated hull ('Qt') as outward triangles over input indices.
Triangles run_qhull(std::span<const Vec3> points, const std::string& source) {
  std::vector<coordT> coords(points.size() * 3);
  for (std::size_t i = 0; i < points.size(); ++i) {
    coords[3 * i] = points[i].x();
    coords[3 * i + 1] = points[i].y();
    coords[3 * i + 2] = points[i].z();
  }
  QhullRun run;
  if (!run.err()) fail(source, "cannot open qhull's error stream");
  char command[] = "qhull Qt";
  qhT* qh = run.qh();
  const int code = qh_new_qhull(qh, 3, static_cast<int>(points.size()), coords.data(), False,
                                command, nullptr, run.err());
  if (code != 0) fail(source, "qhull error: " + run.message());

  Triangles triangles;
  triangles.reserve(static_cast<std::size_t>(qh->num_facets));
  facetT* facet;
  vertexT *vertex, **vertexp;
  FORALLfacets {
    std::uint32_t ids[3];
    int count = 0;
    FOREACHvertex_(facet->vertices) {
      if (count < 3) ids[count] = static_cast<std::uint32_t>(qh_pointid(qh, vertex->point));
      ++count;
    }
    if (count != 3) fail(source, "qhull returned a non-triangular facet");
    // Orient along qhull's outward facet normal; the exact check confirms.
    const Vec3& a = points[ids[0]];
    const Vec3 n = (points[ids[1]] - a).cross(points[ids[2]] - a);
    const Vec3 outward(facet->normal[0], facet->normal[1], facet->normal[2]);
    if (n.dot(outward) < 0) std::swap(ids[1], ids[2]);
    triangles.push_back({ids[0], ids[1], ids[2]});
  }
  for (const TriangleIndices& t : triangles) {
    for (std::uint32_t id : t) {
      if (id >= points.size()) fail(source, "qhull returned an unknown point");
    }
  }
  return triangles;
}

/// Face adjacency of the triangles as a closed, consistently oriented
/// surface of genus 0 without zero-area faces: across[f][k] is the face on
/// the other side of edge v[k] -> v[k + 1]. False when they are not one.
bool closed_surface(std::span<const Vec3> points, const Triangles& triangles,
                    std::vector<std::array<std::uint32_t, 3>>& across) {
  if (triangles.size() < 4) return false;
  struct Edge {
    std::uint32_t u, v, face, k;
  };
  std::vector<Edge> edges;
  edges.reserve(triangles.size() * 3);
  for (std::uint32_t f = 0; f < triangles.size(); ++f) {
    const TriangleIndices& t = triangles[f];
    if (is_degenerate_triangle(points[t[0]], points[t[1]], points[t[2]])) return false;
    for (std::uint32_t k = 0; k < 3; ++k) edges.push_back({t[k], t[(k + 1) % 3], f, k});
  }
  auto less = [](const Edge& x, const Edge& y) { return x.u != y.u ? x.u < y.u : x.v < y.v; };
  std::sort(edges.begin(), edges.end(), less);
  across.assign(triangles.size(), {0, 0, 0});
  for (std::size_t i = 0; i < edges.size(); ++i) {
    if (i + 1 < edges.size() && edges[i].u == edges[i + 1].u && edges[i].v == edges[i + 1].v) {
      return false;
    }
    const Edge reverse{edges[i].v, edges[i].u, 0, 0};
    const auto it = std::lower_bound(edges.begin(), edges.end(), reverse, less);
    if (it == edges.end() || it->u != reverse.u || it->v != reverse.v) return false;
    across[edges[i].face][edges[i].k] = it->face;
  }
  const auto vertex_count = static_cast<long long>(vertex_ids(triangles).size());
  const auto face_count = static_cast<long long>(triangles.size());
  return vertex_count - face_count * 3 / 2 + face_count == 2;
}

/// Solid angle of triangle (a, b, c) seen from the origin (Van Oosterom and
/// Strackee), for a triangle known to face away from the origin (its exact
/// determinant is positive, so a rounded numerator below zero is read as
/// zero). False when the triangle is so nearly edge-on that the rounded
/// formula cannot be trusted to a small fraction of pi.
bool solid_angle(const Vec3& a, const Vec3& b, const Vec3& c, Real& angle) {
  const Real la = a.norm(), lb = b.norm(), lc = c.norm();
  const Real numerator = a.dot(b.cross(c));
  const Real denominator = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
  if (!(std::hypot(numerator, denominator) >= 1e-3 * la * lb * lc)) return false;
  angle = 2 * std::atan2(numerator > 0 ? numerator : 0.0, denominator);
  return true;
}

/// Proves that a closed surface of genus 0 bounds a convex polytope, with `c`
/// strictly inside: (1) c lies strictly below every face (exact); (2) every
/// edge is convex: the far vertex of the face across it is not above the
/// face's plane (exact); (3) the faces, projected centrally from c, cover the
/// sphere once (their solid angles, all positive by (1), sum to 4 pi times
/// an integer degree, which floating point tells apart: each rounded angle
/// is accurate to about 1e-12 once the face is not nearly edge-on, and
/// nearly edge-on faces make the proof fail, not pass). By (1) and (3) the
/// projection is one-to-one, so the surface is embedded and star-shaped
/// about c; a closed embedded surface that is convex at every edge is
/// locally convex everywhere (a simple cone with convex edges is convex) and
/// therefore bounds a convex set (Tietze-Nakajima).
bool proves_convex(std::span<const Vec3> points, const Triangles& triangles,
                   const std::vector<std::array<std::uint32_t, 3>>& across, Vec3& c) {
  Vec3 sum = Vec3::Zero();
  std::size_t count = 0;
  for (const TriangleIndices& t : triangles) {
    for (std::uint32_t i : t) sum += points[i];
    count += 3;
  }
  c = sum / static_cast<Real>(count);
  Real angles = 0;
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    const TriangleIndices& t = triangles[f];
    const Vec3 &a = points[t[0]], &b = points[t[1]], &d = points[t[2]];
    if (orient3d(a, b, d, c) >= 0) return false;
    for (int k = 0; k < 3; ++k) {
      const TriangleIndices& g = triangles[across[f][k]];
      const std::uint32_t u = t[k], v = t[(k + 1) % 3];
      const std::uint32_t far =
          g[0] != u && g[0] != v ? g[0] : (g[1] != u && g[1] != v ? g[1] : g[2]);
      if (orient3d(a, b, d, points[far]) > 0) return false;
    }
    Real angle = 0;
    if (!solid_angle(a - c, b - c, d - c, angle)) return false;
    angles += angle;
  }
  constexpr Real kFourPi = 12.566370614359172;
  return std::abs(angles - kFourPi) < 0.5 * kFourPi;
}

/// Finds, for a point p, the face whose cone from c contains p, so that one
/// exact orient3d decides whether p is inside a convex polytope: the cones
/// are binned by direction on the six faces of a cube map (a face whose
/// vertex directions share a cube face lies inside that face's pyramid and
/// its gnomonic projection is the triangle of the projected vertices; other
/// faces go to a list searched for every point). Binning only proposes
/// candidates; membership in a cone is decided exactly, and a point no
/// candidate's cone holds falls back to testing every face.
class ConeLocator {
 public:
  ConeLocator(std::span<const Vec3> points, const Triangles& triangles, const Vec3& c)
      : p_(points), t_(triangles), c_(c) {
    grid_ = std::max(1, static_cast<int>(std::sqrt(static_cast<Real>(triangles.size()) / 12)));
    cells_.assign(6 * static_cast<std::size_t>(grid_) * grid_, {});
    for (std::uint32_t f = 0; f < triangles.size(); ++f) {
      int face[3];
      Real u[3], v[3];
      for (int k = 0; k < 3; ++k) project(points[triangles[f][k]] - c, face[k], u[k], v[k]);
      if (face[0] != face[1] || face[0] != face[2]) {
        everywhere_.push_back(f);
        continue;
      }
      constexpr Real kSlack = 1e-9;
      const int i0 = cell_of(std::min({u[0], u[1], u[2]}) - kSlack);
      const int i1 = cell_of(std::max({u[0], u[1], u[2]}) + kSlack);
      const int j0 = cell_of(std::min({v[0], v[1], v[2]}) - kSlack);
      const int j1 = cell_of(std::max({v[0], v[1], v[2]}) + kSlack);
      for (int i = i0; i <= i1; ++i) {
        for (int j = j0; j <= j1; ++j) cells_[index(face[0], i, j)].push_back(f);
      }
    }
  }

  /// True when p lies strictly outside the polytope (exact).
  bool outside(const Vec3& p) const {
    const Vec3 d = p - c_;
    if (d == Vec3::Zero()) return false;
    int face;
    Real u, v;
    project(d, face, u, v);
    for (std::uint32_t f : cells_[index(face, cell_of(u), cell_of(v))]) {
      if (in_cone(f, p)) return above(f, p);
    }
    for (std::uint32_t f : everywhere_) {
      if (in_cone(f, p)) return above(f, p);
    }
    for (std::uint32_t f = 0; f < t_.size(); ++f) {
      if (above(f, p)) return true;
    }
    return false;
  }

 private:
  static void project(const Vec3& d, int& face, Real& u, Real& v) {
    int k = 0;
    if (std::abs(d.y()) > std::abs(d[k])) k = 1;
    if (std::abs(d.z()) > std::abs(d[k])) k = 2;
    face = 2 * k + (d[k] < 0);
    const Real scale = 1 / std::abs(d[k]);
    u = d[(k + 1) % 3] * scale;
    v = d[(k + 2) % 3] * scale;
  }
  int cell_of(Real x) const {
    const Real cell = std::floor((x + 1) * 0.5 * grid_);
    return static_cast<int>(std::clamp(cell, Real{0}, static_cast<Real>(grid_ - 1)));
  }
  std::size_t index(int face, int i, int j) const {
    return (static_cast<std::size_t>(face) * grid_ + i) * grid_ + j;
  }
  bool in_cone(std::uint32_t f, const Vec3& p) const {
    const TriangleIndices& t = t_[f];
    return orient3d(c_, p_[t[0]], p_[t[1]], p) >= 0 && orient3d(c_, p_[t[1]], p_[t[2]], p) >= 0 &&
           orient3d(c_, p_[t[2]], p_[t[0]], p) >= 0;
  }
  bool above(std::uint32_t f, const Vec3& p) const {
    const TriangleIndices& t = t_[f];
    return orient3d(p_[t[0]], p_[t[1]], p_[t[2]], p) > 0;
  }

  std::span<const Vec3> p_;
  const Triangles& t_;
  Vec3 c_;
  int grid_ = 1;
  std::vector<std::vector<std::uint32_t>> cells_;
  std::vector<std::uint32_t> everywhere_;
};

/// Indices of the input points strictly above some face (exact), ascending,
/// when the triangles are proven to bound a convex polytope; nullopt-like
/// `proven = false` otherwise.
std::vector<std::uint32_t> points_outside(std::span<const Vec3> points, const Triangles& triangles,
                                          bool& proven) {
  std::vector<std::array<std::uint32_t, 3>> across;
  Vec3 c;
  proven = closed_surface(points, triangles, across) && proves_convex(points, triangles, across, c);
  std::vector<std::uint32_t> outside;
  if (!proven) return outside;
  // Vertices lie on the boundary of the proven polytope; test the others.
  std::vector<char> vertex(points.size(), 0);
  for (const TriangleIndices& t : triangles) {
    for (std::uint32_t i : t) vertex[i] = 1;
  }
  const ConeLocator locator(points, triangles, c);
  for (std::uint32_t i = 0; i < points.size(); ++i) {
    if (!vertex[i] && locator.outside(points[i])) outside.push_back(i);
  }
  return outside;
}

/// Exact incremental (beneath-beyond) hull: every decision is an exact
/// orient3d sign; a point on the plane of a face does not see it, so faces
/// stay triangles and coplanar neighbours are allowed.
class ExactHull {
 public:
  ExactHull(std::span<const Vec3> points, const std::array<std::uint32_t, 4>& s)
      : p_(points), start_of_(points.size(), kNone), stamp_of_(points.size(), 0) {
    std::uint32_t i0 = s[0], i1 = s[1], i2 = s[2], i3 = s[3];
    // Orient the tetrahedron so that (i0, i1, i2) has i3 below it.
    if (orient3d(p_[i0], p_[i1], p_[i2], p_[i3]) > 0) std::swap(i1, i2);
    const std::uint32_t f0 = add_face(i0, i1, i2), f1 = add_face(i0, i3, i1),
                        f2 = add_face(i1, i3, i2), f3 = add_face(i2, i3, i0);
    faces_[f0].nb = {f1, f2, f3};
    faces_[f1].nb = {f3, f2, f0};
    faces_[f2].nb = {f1, f3, f0};
    faces_[f3].nb = {f2, f1, f0};
  }

  /// Adds point i; no change when it lies inside or on the hull.
  void insert(std::uint32_t i) {
    const Vec3& q = p_[i];
    // Find one face that sees q: walk from the newest face towards faces q
    // is farther above (rounded), else try every face.
    std::uint32_t seed = kNone;
    std::uint32_t at = last_;
    Real height = plane_height(at, q);
    for (std::size_t steps = 0; steps < faces_.size(); ++steps) {
      if (sees(at, q)) {
        seed = at;
        break;
      }
      std::uint32_t best = kNone;
      for (std::uint32_t g : faces_[at].nb) {
        const Real h = plane_height(g, q);
        if (h > height) {
          height = h;
          best = g;
        }
      }
      if (best == kNone) break;
      at = best;
    }
    for (std::uint32_t g = 0; g < faces_.size() && seed == kNone; ++g) {
      if (faces_[g].alive && sees(g, q)) seed = g;
    }
    if (seed == kNone) return;
    // Grow the visible region across edges.
    ++visit_;
    visible_.clear();
    visible_.push_back(seed);
    mark(seed, 1);
    for (std::size_t k = 0; k < visible_.size(); ++k) {
      for (std::uint32_t g : faces_[visible_[k]].nb) {
        if (state(g) != 0) continue;
        const bool v = sees(g, q);
        mark(g, v ? 1 : 2);
        if (v) visible_.push_back(g);
      }
    }
    // One new face per horizon edge, joined to the face beyond it.
    ++horizon_stamp_;
    created_.clear();
    for (std::uint32_t f : visible_) {
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t g = faces_[f].nb[k];
        if (state(g) == 1) continue;
        const std::uint32_t u = faces_[f].v[k], w = faces_[f].v[(k + 1) % 3];
        const std::uint32_t nf = add_face(u, w, i);
        faces_[nf].nb[0] = g;
        for (std::uint32_t& back : faces_[g].nb) {
          if (back == f) back = nf;
        }
        if (stamp_of_[u] == horizon_stamp_) throw HullInternalError("horizon not simple");
        stamp_of_[u] = horizon_stamp_;
        start_of_[u] = nf;
        created_.push_back(nf);
      }
    }
    // Join the new faces around the new vertex: (u, w, i) meets (w, x, i) along (w, i).
    for (std::uint32_t nf : created_) {
      const std::uint32_t w = faces_[nf].v[1];
      if (stamp_of_[w] != horizon_stamp_) throw HullInternalError("horizon not closed");
      const std::uint32_t next = start_of_[w];
      faces_[nf].nb[1] = next;
      faces_[next].nb[2] = nf;
    }
    for (std::uint32_t v : visible_) faces_[v].alive = false;
    last_ = created_.front();
  }

  Triangles triangles() const {
    Triangles out;
    for (const Face& f : faces_) {
      if (f.alive) out.push_back(f.v);
    }
    return out;
  }

 private:
  static constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

  struct Face {
    TriangleIndices v;                  ///< outward, counter-clockwise
    std::array<std::uint32_t, 3> nb{};  ///< nb[k]: face across edge v[k] -> v[k + 1]
    bool alive = true;
    std::uint64_t visit = 0;
    int state = 0;  ///< during one insertion: 1 visible, 2 not visible
  };

  std::uint32_t add_face(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    Face f;
    f.v = {a, b, c};
    faces_.push_back(f);
    return static_cast<std::uint32_t>(faces_.size() - 1);
  }
  /// Rounded distance of q above the plane of face f.
  Real plane_height(std::uint32_t f, const Vec3& q) const {
    const TriangleIndices& t = faces_[f].v;
    const Vec3 n = (p_[t[1]] - p_[t[0]]).cross(p_[t[2]] - p_[t[0]]);
    const Real above = n.dot(q - p_[t[0]]);
    const Real length = n.norm();
    if (length == 0) {
      // A sliver whose rounded normal vanishes: the IEEE quotient, spelt out
      // (the walk only uses it to choose a direction; sees() decides).
      constexpr Real kInf = std::numeric_limits<Real>::infinity();
      return above > 0 ? kInf : above < 0 ? -kInf : std::numeric_limits<Real>::quiet_NaN();
    }
    return above / length;
  }
  bool sees(std::uint32_t f, const Vec3& q) const {
    const TriangleIndices& t = faces_[f].v;
    return orient3d(p_[t[0]], p_[t[1]], p_[t[2]], q) > 0;
  }
  int state(std::uint32_t f) const { return faces_[f].visit == visit_ ? faces_[f].state : 0; }
  void mark(std::uint32_t f, int s) {
    faces_[f].visit = visit_;
    faces_[f].state = s;
  }

  std::span<const Vec3> p_;
  std::vector<Face> faces_;
  std::vector<std::uint32_t> visible_, created_;
  std::vector<std::uint32_t> start_of_;
  std::vector<std::uint64_t> stamp_of_;
  std::uint64_t visit_ = 0, horizon_stamp_ = 0;
  std::uint32_t last_ = 0;  ///< a live face near the last insertion
};

/// Indices of the points strictly above some face, by testing every pair
/// (exact; used only when the convexity proof cannot be made).
std::vector<std::uint32_t> points_outside_by_scan(std::span<const Vec3> points,
                                                  const Triangles& triangles) {
  std::vector<std::uint32_t> outside;
  for (std::uint32_t i = 0; i < points.size(); ++i) {
    for (const TriangleIndices& t : triangles) {
      if (orient3d(points[t[0]], points[t[1]], points[t[2]], points[i]) > 0) {
        outside.push_back(i);
        break;
      }
    }
  }
  return outside;
}

/// Exact hull: qhull's vertices first, then every point still outside, until
/// none is.
Triangles exact_hull(std::span<const Vec3> points, const Triangles& candidate,
                     const std::array<std::uint32_t, 4>& simplex) {
  ExactHull hull(points, simplex);
  for (std::uint32_t i : vertex_ids(candidate)) hull.insert(i);
  Triangles triangles = hull.triangles();
  for (;;) {
    bool proven = false;
    std::vector<std::uint32_t> outside = points_outside(points, triangles, proven);
    if (!proven) outside = points_outside_by_scan(points, triangles);
    if (outside.empty()) return triangles;
    for (std::uint32_t i : outside) hull.insert(i);
    triangles = hull.triangles();
  }
}

/// Whether every corner of triangle u lies in the plane of triangle t (exact).
bool coplanar(std::span<const Vec3> p, const TriangleIndices& t, const TriangleIndices& u) {
  for (const std::uint32_t k : u) {
    if (orient3d(p[t[0]], p[t[1]], p[t[2]], p[k]) != 0) return false;
  }
  return true;
}

/// The vertices of an exact hull's triangles that are corners of the
/// polytope, ascending. A corner has three or more facets, so the triangles
/// around it lie in three or more planes; a vertex that lies inside an edge
/// of the polytope has two, inside a facet one (decided exactly).
std::vector<std::uint32_t> corners(std::span<const Vec3> p, const Triangles& triangles) {
  std::vector<std::vector<std::uint32_t>> around(p.size());
  for (std::uint32_t f = 0; f < triangles.size(); ++f) {
    for (const std::uint32_t v : triangles[f]) around[v].push_back(f);
  }
  std::vector<std::uint32_t> out;
  for (std::uint32_t v = 0; v < p.size(); ++v) {
    std::vector<std::uint32_t> planes;  // one triangle per plane met so far
    for (const std::uint32_t f : around[v]) {
      const bool known = std::any_of(planes.begin(), planes.end(), [&](std::uint32_t g) {
        return coplanar(p, triangles[g], triangles[f]);
      });
      if (!known) planes.push_back(f);
      if (planes.size() == 3) break;
    }
    if (planes.size() == 3) out.push_back(v);
  }
  return out;
}

/// The hull's width: over its faces, the least largest depth of a vertex
/// below the face's plane (rounded; used only against kThinnest). A sliver
/// face, whose rounded normal may point anywhere (its sine of the angle
/// between its edges under 1e-6), is passed over: its neighbours, in nearly
/// the same plane, measure the width there, and a flat set's two large
/// faces always do.
Real width(std::span<const Vec3> p, const Triangles& triangles) {
  const std::vector<std::uint32_t> vertices = vertex_ids(triangles);
  Real least = std::numeric_limits<Real>::infinity();
  for (const TriangleIndices& t : triangles) {
    const Vec3 u = p[t[1]] - p[t[0]], v = p[t[2]] - p[t[0]];
    const Vec3 n = u.cross(v);
    const Real length = n.norm();
    if (!(length > 1e-6 * u.norm() * v.norm())) continue;  // a sliver: no width of its own
    Real deepest = 0;
    for (const std::uint32_t k : vertices) deepest = std::max(deepest, -n.dot(p[k] - p[t[0]]));
    least = std::min(least, deepest / length);
  }
  return least;
}

/// Point sets thinner than this fraction of their size are flat parts.
constexpr Real kThinnest = 1e-14;

/// Whether the hull's width is below `fraction` of its bounding box's
/// diagonal. Measured on the points moved to the box's centre and scaled by
/// a power of two to a diagonal near 1, so that neither underflow (a set of
/// size 1e-200) nor overflow (1e200) decides.
bool thinner_than(Real fraction, std::span<const Vec3> points, const Triangles& triangles) {
  Vec3 lo = points[0], hi = points[0];
  for (const Vec3& q : points) {
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  const Vec3 half = hi / 2 - lo / 2;  // halves: no overflow near 1e308
  int exponent = 0;
  std::frexp(half.maxCoeff(), &exponent);
  const Vec3 centre = lo / 2 + hi / 2;
  std::vector<Vec3> scaled(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3 d = points[i] - centre;
    scaled[i] = Vec3(std::ldexp(d.x(), -exponent), std::ldexp(d.y(), -exponent),
                     std::ldexp(d.z(), -exponent));
  }
  // The scaled box's diagonal: twice its half, scaled as the points are.
  const Real diagonal = 2 * std::ldexp(half.norm(), -exponent);
  return width(scaled, triangles) < fraction * diagonal;
}

/// The exact incremental hull of every point, without qhull: for small point
/// sets, where starting qhull costs more than the whole hull (docs/convex.md).
/// Points go in farthest from the seed tetrahedron's centre first, so that
/// the polytope's corners mostly come before the points on its edges and
/// facets; a beneath-beyond hull keeps such a point as a vertex when it came
/// first, so the hull is built a second time from the corners alone.
Triangles direct_hull(std::span<const Vec3> points, const std::array<std::uint32_t, 4>& simplex) {
  const auto build = [](std::span<const Vec3> p, const std::array<std::uint32_t, 4>& s) {
    ExactHull hull(p, s);
    const Vec3 c = (p[s[0]] + p[s[1]] + p[s[2]] + p[s[3]]) / 4;
    std::vector<std::pair<Real, std::uint32_t>> order(p.size());
    for (std::uint32_t i = 0; i < p.size(); ++i) order[i] = {-(p[i] - c).squaredNorm(), i};
    std::sort(order.begin(), order.end());
    for (const auto& [far, i] : order) hull.insert(i);
    return hull.triangles();
  };
  const Triangles first = build(points, simplex);
  const std::vector<std::uint32_t> keep = corners(points, first);
  if (keep.size() == vertex_ids(first).size()) return first;
  // Corners of a polytope are in convex position: the second hull has each
  // of them as a vertex and nothing else.
  std::vector<Vec3> corner_points;
  for (const std::uint32_t i : keep) corner_points.push_back(points[i]);
  std::array<std::uint32_t, 4> s;
  if (!find_simplex(corner_points, s)) throw HullInternalError("corners are flat");
  Triangles second = build(corner_points, s);
  for (TriangleIndices& t : second) {
    for (std::uint32_t& i : t) i = keep[i];
  }
  return second;
}

/// Compacts the vertices, builds the adjacency and the bounds.
ConvexHull finish(std::span<const Vec3> points, const Triangles& triangles) {
  ConvexHull hull;
  std::vector<std::uint32_t> index(points.size(), std::numeric_limits<std::uint32_t>::max());
  for (std::uint32_t i : vertex_ids(triangles)) {
    index[i] = static_cast<std::uint32_t>(hull.vertices.size());
    hull.vertices.push_back(points[i]);
  }
  hull.faces.reserve(triangles.size());
  for (const TriangleIndices& t : triangles)
    hull.faces.push_back({index[t[0]], index[t[1]], index[t[2]]});

  // Each directed edge u -> v of a face gives v as a neighbour of u; the
  // surface is closed, so every undirected edge is listed once per end.
  const std::size_t n = hull.vertices.size();
  hull.neighbor_offsets.assign(n + 1, 0);
  for (const TriangleIndices& f : hull.faces) {
    for (std::uint32_t v : f) ++hull.neighbor_offsets[v + 1];
  }
  for (std::size_t i = 0; i < n; ++i) hull.neighbor_offsets[i + 1] += hull.neighbor_offsets[i];
  hull.neighbors.resize(hull.neighbor_offsets[n]);
  std::vector<std::uint32_t> fill(hull.neighbor_offsets.begin(), hull.neighbor_offsets.end() - 1);
  for (const TriangleIndices& f : hull.faces) {
    for (int k = 0; k < 3; ++k) hull.neighbors[fill[f[k]]++] = f[(k + 1) % 3];
  }
  for (std::size_t i = 0; i < n; ++i) {
    std::sort(hull.neighbors.begin() + hull.neighbor_offsets[i],
              hull.neighbors.begin() + hull.neighbor_offsets[i + 1]);
  }

  Vec3 sum = Vec3::Zero();
  for (const Vec3& v : hull.vertices) sum += v;
  hull.center = sum / static_cast<Real>(n);
  for (const Vec3& v : hull.vertices) {
    hull.radius = std::max(hull.radius, (v - hull.center).norm());
    hull.extent = std::max(hull.extent, v.cwiseAbs().maxCoeff());
  }
  return hull;
}

}  // namespace

namespace detail {

ConvexHull build_convex_hull(std::span<const Vec3> points, const std::string& source,
                             HullBuildStats* stats, HullPath path) {
  // Validate the input.
  if (points.empty()) fail(source, "no points");
  if (points.size() > static_cast<std::size_t>(std::numeric_limits<int>::max()) / 3) {
    fail(source, "too many points");
  }
  for (const Vec3& p : points) {
    if (!p.allFinite()) fail(source, "non-finite coordinate");
  }
  std::array<std::uint32_t, 4> simplex;
  if (!find_simplex(points, simplex)) {
    fail(source, "fewer than 4 affinely independent points (flat or degenerate part)");
  }
  if (path == HullPath::kAuto) {
    path = points.size() <= kDirectHullPoints ? HullPath::kDirect : HullPath::kQhull;
  }
  if (stats) stats->direct = path == HullPath::kDirect;
  if (path == HullPath::kDirect) {
    Triangles triangles;
    try {
      triangles = direct_hull(points, simplex);
    } catch (const HullInternalError& e) {
      fail(source, std::string("internal error: ") + e.what());
    }
    // qhull refuses a set thinner than about 1e-14 of its size; so does this
    // path, so that whether a part is flat does not depend on its size.
    if (thinner_than(kThinnest, points, triangles)) {
      fail(source, "thinner than 1e-14 of its size (flat or degenerate part)");
    }
    return finish(points, triangles);
  }
  // qhull's triangulated hull, accepted when exactly right.
  const Triangles candidate = run_qhull(points, source);
  bool proven = false;
  const bool exact =
      path != HullPath::kRebuild && points_outside(points, candidate, proven).empty() && proven;
  if (stats) {
    stats->qhull_vertices = vertex_ids(candidate).size();
    stats->rebuilt_exactly = !exact;
  }
  if (exact) return finish(points, candidate);
  // Otherwise the exact rebuild from qhull's vertices.
  try {
    return finish(points, exact_hull(points, candidate, simplex));
  } catch (const HullInternalError& e) {
    fail(source, std::string("internal error: ") + e.what());
  }
}

bool is_exact_hull(std::span<const Vec3> points, const std::vector<TriangleIndices>& triangles) {
  bool proven = false;
  return points_outside(points, triangles, proven).empty() && proven;
}

}  // namespace detail

bool surface_on_hull(const ConvexHull& hull, std::span<const Vec3> points,
                     std::span<const TriangleIndices> triangles) {
  // The hull vertex at each point's exact position, if any.
  std::map<std::array<Real, 3>, std::uint32_t> at;
  for (std::uint32_t i = 0; i < hull.vertices.size(); ++i) {
    const Vec3& v = hull.vertices[i];
    at.emplace(std::array<Real, 3>{v.x(), v.y(), v.z()}, i);
  }
  // Signs of orient3d(a, b, c, .) over some hull vertices: supporting when
  // they never take both signs; a plane no vertex leaves is degenerate.
  const auto supports = [&](const Vec3& a, const Vec3& b, const Vec3& c, auto&& vertices) {
    bool above = false, below = false;
    for (const std::uint32_t v : vertices) {
      const Real o = orient3d(a, b, c, hull.vertices[v]);
      above = above || o > 0;
      below = below || o < 0;
      if (above && below) return false;
    }
    return above || below;
  };
  std::vector<std::uint32_t> every(hull.vertices.size());
  for (std::uint32_t i = 0; i < every.size(); ++i) every[i] = i;
  for (const TriangleIndices& t : triangles) {
    const Vec3& a = points[t[0]];
    const Vec3& b = points[t[1]];
    const Vec3& c = points[t[2]];
    std::span<const std::uint32_t> check = every;
    for (const std::uint32_t corner : t) {
      const Vec3& p = points[corner];
      const auto it = at.find({p.x(), p.y(), p.z()});
      if (it == at.end()) continue;
      const std::uint32_t h = it->second;
      check =
          std::span<const std::uint32_t>(hull.neighbors.data() + hull.neighbor_offsets[h],
                                         hull.neighbor_offsets[h + 1] - hull.neighbor_offsets[h]);
      break;
    }
    if (!supports(a, b, c, check)) return false;
  }
  return true;
}

ConvexHull compute_convex_hull(std::span<const Vec3> points, const std::string& source) {
  return detail::build_convex_hull(points, source, nullptr, detail::HullPath::kAuto);
}

}  // namespace dovetail::collision
