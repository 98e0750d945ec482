#include "dovetail/interaction/sliding.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

#include "dovetail/collision/contacts.h"
#include "dovetail/collision/tri_tri.h"
#include "dovetail/engine/scene.h"

namespace dovetail::interaction {

namespace {

constexpr Real kDegree = std::numbers::pi / 180;

/// X rotated by w about the point c (world) and moved by v.
Transform moved(const Transform& X, const Vec3& c, const Vec3& v, const Vec3& w) {
  const Mat3 R = rotation_from_vector(w);
  Transform out;
  out.R = R * X.R;
  out.t = c + v + R * (X.t - c);
  return out;
}

using Triangle = std::array<Vec3, 3>;

/// The bodies that move in a step: the sliding part (body 0) and the parts
/// attached to it (body i is attachment i - 1), rigidly together.
std::uint32_t index(std::size_t body) { return static_cast<std::uint32_t>(body); }
std::size_t body_count(const SlideRequest& request) { return 1 + request.attached.size(); }
const std::shared_ptr<const collision::CollisionModel>& body_model(const SlideRequest& request,
                                                                   std::size_t body) {
  return body == 0 ? request.part : request.attached[body - 1].model;
}
/// Body `body`'s pose in the world when the sliding part is at X_WP.
Transform body_pose(const SlideRequest& request, std::size_t body, const Transform& X_WP) {
  return body == 0 ? X_WP : engine::compose(X_WP, request.attached[body - 1].X_PA);
}

/// Where a pose of the part collides: the first intersecting triangle pair
/// that an obstacle's query found (the obstacle's triangle, the body's).
struct Hit {
  std::size_t obstacle = 0;  ///< index into the request's obstacles
  std::size_t body = 0;      ///< which of the moving bodies
  collision::TrianglePair pair;
};

/// Most triangle pairs of one patch whose closest points are measured.
constexpr std::size_t kPairsPerPatch = 64;

/// The contacts of one moving body met between its last free pose and the
/// colliding one. The contact patches of the colliding pose X_WB_hit say
/// where the body meets each obstacle and how (their kind: face, curve,
/// point); for each patch's triangle pairs, the closest points of the two
/// triangles at the free pose X_WB_free, a hair's breadth away, give a
/// contact point and the normal from the obstacle's triangle toward the
/// body's: the face normal for a vertex or an edge on a face, the common
/// perpendicular for two edges. A patch keeps its distinct normals (1 degree
/// apart), each at the point of its pair.
void contacts_of_body(const SlideRequest& request, std::size_t body, const Transform& X_WB_free,
                      const Transform& X_WB_hit, std::vector<SlideContact>& out, int& queries) {
  const std::shared_ptr<const collision::CollisionModel>& model = body_model(request, body);
  const collision::Mesh& body_mesh = model->mesh();
  for (const SlideObstacle& o : request.obstacles) {
    const Transform X_OB = engine::compose(o.X_WO.inverse(), X_WB_hit);
    ++queries;
    const std::vector<collision::ContactPatch> patches = collision::compute_contacts(
        *o.model, *model, X_OB,
        {.estimate_depth = false,
         .nearly_coplanar_pairs = false,
         .front = request.fronts ? &request.fronts->of(o.model, model) : nullptr});
    const collision::Mesh& obstacle_mesh = o.model->mesh();
    for (const collision::ContactPatch& patch : patches) {
      const std::size_t first = out.size();
      const std::size_t count = std::min(patch.pairs.size(), kPairsPerPatch);
      for (std::size_t i = 0; i < count; ++i) {
        // Evenly over the patch when it has more pairs than are measured.
        const collision::TrianglePair& pair = patch.pairs[i * patch.pairs.size() / count];
        Triangle ta, tb;
        for (int k = 0; k < 3; ++k) {
          ta[k] = o.X_WO.apply(obstacle_mesh.vertices[obstacle_mesh.triangles[pair.a][k]]);
          tb[k] = X_WB_free.apply(body_mesh.vertices[body_mesh.triangles[pair.b][k]]);
        }
        const collision::TrianglePairDistance d = collision::triangle_pair_distance(ta, tb);
        if (!(d.distance > 0)) continue;  // still touching at the free pose: no direction
        const Vec3 n_W = (d.q - d.p) / d.distance;
        bool seen = false;
        for (std::size_t j = first; j < out.size() && !seen; ++j)
          seen = out[j].n_W.dot(n_W) > 0.9998;
        if (!seen) out.push_back({o.id, (d.p + d.q) / 2, n_W, patch.kind, 0, index(body)});
      }
      if (out.size() == first) {
        out.push_back({o.id, o.X_WO.apply(patch.point), (o.X_WO.R * patch.normal).normalized(),
                       patch.kind, 0, index(body)});
      }
    }
  }
}

/// contacts_of_body for each moving body, the sliding part moving from X_WP_free to X_WP_hit.
void contacts_at(const SlideRequest& request, const Transform& X_WP_free, const Transform& X_WP_hit,
                 std::vector<SlideContact>& out, int& queries) {
  for (std::size_t body = 0; body < body_count(request); ++body) {
    contacts_of_body(request, body, body_pose(request, body, X_WP_free),
                     body_pose(request, body, X_WP_hit), out, queries);
  }
}

/// The contact of one colliding triangle pair, measured at the free pose X_WP_free as in
/// contacts_at; nothing when the pair still touches there.
std::optional<SlideContact> pair_contact(const SlideRequest& request, const Hit& hit,
                                         const Transform& X_WP_free) {
  const SlideObstacle& o = request.obstacles[hit.obstacle];
  const collision::Mesh& obstacle_mesh = o.model->mesh();
  const collision::Mesh& body_mesh = body_model(request, hit.body)->mesh();
  const Transform X_WB_free = body_pose(request, hit.body, X_WP_free);
  Triangle ta, tb;
  for (int k = 0; k < 3; ++k) {
    ta[k] = o.X_WO.apply(obstacle_mesh.vertices[obstacle_mesh.triangles[hit.pair.a][k]]);
    tb[k] = X_WB_free.apply(body_mesh.vertices[body_mesh.triangles[hit.pair.b][k]]);
  }
  const collision::TrianglePairDistance d = collision::triangle_pair_distance(ta, tb);
  if (!(d.distance > 0)) return std::nullopt;
  return SlideContact{
      o.id, (d.p + d.q) / 2, (d.q - d.p) / d.distance, collision::ContactKind::kPoint,
      0,    index(hit.body)};
}

/// The part at X_WP against every obstacle, exact first-hit queries: the
/// first hit, or nothing when the pose is collision-free. With `fronts`, each
/// query starts from the part's front for that obstacle.
std::optional<Hit> first_hit(const collision::CollisionModel& part, const Transform& X_WP,
                             std::span<const SlideObstacle> obstacles, int* queries,
                             const std::shared_ptr<const collision::CollisionModel>& part_shared,
                             SlideFronts* fronts) {
  for (std::size_t i = 0; i < obstacles.size(); ++i) {
    const SlideObstacle& o = obstacles[i];
    const Transform X_OP = engine::compose(o.X_WO.inverse(), X_WP);
    if (queries) ++*queries;
    collision::SeparationFront* front = fronts ? &fronts->of(o.model, part_shared) : nullptr;
    // The fixed order: the first hit, which guides the contact search, is
    // then the same with fronts and without.
    const collision::CollideResult r =
        o.model->collide(part, X_OP, {.front = front, .nearer_first = false});
    if (r.colliding) return Hit{.obstacle = i, .pair = r.pairs.front()};
  }
  return std::nullopt;
}

/// first_hit for each of the request's moving bodies in turn against its
/// obstacles, from its fronts, the sliding part at X_WP.
std::optional<Hit> first_hit(const SlideRequest& request, const Transform& X_WP, int& queries) {
  for (std::size_t body = 0; body < body_count(request); ++body) {
    const std::shared_ptr<const collision::CollisionModel>& model = body_model(request, body);
    std::optional<Hit> hit = first_hit(*model, body_pose(request, body, X_WP), request.obstacles,
                                       &queries, model, request.fronts);
    if (hit) {
      hit->body = body;
      return hit;
    }
  }
  return std::nullopt;
}

/// Whether the one triangle pair of `hit` intersects with the part at X_WP:
/// the leaf test of the first-hit query (the part's vertices mapped into the
/// obstacle's frame by the same Transform::apply), so a pair that intersects
/// here makes the query report the pose colliding.
bool pair_collides(const collision::CollisionModel& part, const Transform& X_WP,
                   const SlideObstacle& o, const collision::TrianglePair& pair) {
  const Transform X_OP = engine::compose(o.X_WO.inverse(), X_WP);
  const collision::Mesh& obstacle_mesh = o.model->mesh();
  const collision::Mesh& part_mesh = part.mesh();
  const collision::TriangleIndices& ta = obstacle_mesh.triangles[pair.a];
  const collision::TriangleIndices& tb = part_mesh.triangles[pair.b];
  return collision::triangles_intersect(
      obstacle_mesh.vertices[ta[0]], obstacle_mesh.vertices[ta[1]], obstacle_mesh.vertices[ta[2]],
      X_OP.apply(part_mesh.vertices[tb[0]]), X_OP.apply(part_mesh.vertices[tb[1]]),
      X_OP.apply(part_mesh.vertices[tb[2]]));
}

/// A move of the part: from X_WP by v and the turn w about the world point c.
struct Move {
  Transform X_WP;
  Vec3 c, v, w;
  /// The pose after the fraction s of the move.
  Transform at(Real s) const { return moved(X_WP, c, s * v, s * w); }
  /// How far the fraction s moves any point of a part of size L at most.
  Real reach(Real s, Real size) const { return s * (v.norm() + w.norm() * size); }
};

/// Fractions of a move: the part is collision-free after `free`, colliding after `hit`.
struct Bracket {
  Real free = 0;
  Real hit = 1;
  Hit pair_at_hit;  ///< a triangle pair that intersects after `hit`
};

/// The contact pose of a move whose end collides, by halving the bracket
/// with a first-hit query of the whole part each time, until it moves a
/// point less than the resolution or the query budget is spent.
Bracket bracket_halving(const SlideRequest& request, const Move& motion, Hit hit,
                        const SlidingSettings& settings, int& queries) {
  Bracket b{.pair_at_hit = hit};
  for (int i = 0; i < settings.bisection_steps &&
                  motion.reach(b.hit - b.free, request.size) > settings.resolution_m;
       ++i) {
    const Real mid = (b.free + b.hit) / 2;
    if (const std::optional<Hit> h = first_hit(request, motion.at(mid), queries)) {
      b.hit = mid;
      b.pair_at_hit = *h;
    } else {
      b.free = mid;
    }
  }
  return b;
}

/// The same bracket, guided by the triangle pair that collides: halve on
/// that pair alone (one exact triangle test a step) to where it starts to
/// touch, then ask the whole part there once. Collision-free: done, the pair
/// proves the other end collides. Colliding: the query's pair touches
/// earlier; go on with it. Each query thus moves the colliding end to an
/// earlier pair's contact, and a move that meets one new facet costs two
/// queries where halving with whole-part queries costs ten or more.
Bracket bracket_guided(const SlideRequest& request, const Move& motion, Hit hit,
                       const SlidingSettings& settings, int& queries) {
  Bracket b{.pair_at_hit = hit};
  for (int i = 0; i < settings.bisection_steps; ++i) {
    // Halve on the pair: it touches after b.hit and (the whole part being free there) not
    // after b.free.
    Real lo = b.free;
    while (motion.reach(b.hit - lo, request.size) > settings.resolution_m) {
      const Real mid = (lo + b.hit) / 2;
      if (mid <= lo || mid >= b.hit) break;  // no double left between them
      (pair_collides(*body_model(request, hit.body), body_pose(request, hit.body, motion.at(mid)),
                     request.obstacles[hit.obstacle], hit.pair)
           ? b.hit
           : lo) = mid;
    }
    if (lo == b.free) break;  // the pair touches within the resolution of the free end
    const std::optional<Hit> earlier = first_hit(request, motion.at(lo), queries);
    if (!earlier) {
      b.free = lo;
      break;
    }
    b.hit = lo;
    hit = *earlier;
  }
  b.pair_at_hit = hit;
  return b;
}

bool same_bits(const Transform& a, const Transform& b) { return a.R == b.R && a.t == b.t; }

/// Whether `proof` shows the request's starting pose collision-free: the same part model at
/// the same pose with the same attachments, and every obstacle's model at the same pose among
/// those it was proved against.
bool proves_free(const SlideProof* proof, const SlideRequest& request) {
  if (!proof || !proof->part || proof->part != request.part ||
      !same_bits(proof->X_WP, request.X_WP) ||
      !std::equal(proof->attached.begin(), proof->attached.end(), request.attached.begin(),
                  request.attached.end(), [](const SlideAttachment& a, const SlideAttachment& b) {
                    return a.model == b.model && same_bits(a.X_PA, b.X_PA);
                  })) {
    return false;
  }
  return std::all_of(request.obstacles.begin(), request.obstacles.end(),
                     [&](const SlideObstacle& o) {
                       return std::any_of(proof->obstacles.begin(), proof->obstacles.end(),
                                          [&](const SlideObstacle& p) {
                                            return p.model == o.model && same_bits(p.X_WO, o.X_WO);
                                          });
                     });
}

/// A part that starts touching obstacles, its surfaces meeting theirs but
/// nowhere deeper than the contacts' touching tolerance (placed face on face,
/// a held part resting where it was grasped), is moved out to the skin along
/// the contacts' normals by the least motion (project_motion from rest), so
/// that it can move on, and away from them. The pose off the contacts, with
/// the contacts met, once the exact test finds it free; nothing when the part
/// penetrates an obstacle or that pose still collides.
std::optional<Transform> off_touching(const SlideRequest& request, const SlidingSettings& settings,
                                      std::vector<SlideContact>& touching, int& queries) {
  const Vec3 c = request.X_WP.apply(request.p_PC);
  std::vector<Motion> constraints;
  for (std::size_t body = 0; body < body_count(request); ++body) {
    const Transform X_WB = body_pose(request, body, request.X_WP);
    for (const SlideObstacle& o : request.obstacles) {
      const Transform X_OB = engine::compose(o.X_WO.inverse(), X_WB);
      ++queries;
      for (const collision::ContactPatch& patch :
           collision::compute_contacts(*o.model, *body_model(request, body), X_OB)) {
        if (patch.penetrating) return std::nullopt;
        SlideContact k;
        k.obstacle = o.id;
        k.p_W = o.X_WO.apply(patch.point);
        k.n_W = o.X_WO.R * patch.normal;
        k.kind = patch.kind;
        k.body = index(body);
        Motion a;
        a << k.n_W, (k.p_W - c).cross(k.n_W);
        constraints.push_back(a);
        touching.push_back(k);
      }
    }
  }
  if (constraints.empty()) return std::nullopt;
  const std::vector<Real> clearance(constraints.size(), settings.skin_m);
  const std::optional<Motion> away = project_motion(Motion::Zero(), constraints, clearance,
                                                    settings.turn_stiffness * request.size);
  if (!away) return std::nullopt;
  const Transform X_WP = moved(request.X_WP, c, away->head<3>(), away->tail<3>());
  if (first_hit(request, X_WP, queries)) return std::nullopt;
  for (SlideContact& k : touching) {
    const Vec3 p = c + away->head<3>() + rotation_from_vector(away->tail<3>()) * (k.p_W - c);
    k.separation = k.n_W.dot(p - k.p_W);
    k.p_W = p;
  }
  return X_WP;
}

}  // namespace

// Goldfarb and Idnani's dual method: from the unconstrained minimum it adds the most
// violated constraint, walking along the M-shortest step (M = diag(1, 1, 1, L^2, L^2, L^2))
// that keeps the active constraints tight and dropping an active one whose multiplier would
// turn negative, until none is violated. Six unknowns: at most six active constraints, each
// step a solve of their Gram matrix at most 6 x 6.
std::optional<Motion> project_motion(const Motion& x_d, std::span<const Motion> a,
                                     std::span<const Real> b, Real length) {
  // Sized up to six on the stack: at most six constraints are active.
  using Active = Eigen::Matrix<Real, 6, Eigen::Dynamic, 0, 6, 6>;
  using Gram = Eigen::Matrix<Real, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;
  using Multipliers = Eigen::Matrix<Real, Eigen::Dynamic, 1, 0, 6, 1>;
  constexpr Real kInfinity = std::numeric_limits<Real>::infinity();
  // A constraint counts as met within this (metres), far below what sliding resolves.
  constexpr Real kSlack = 1e-15;
  Motion m_inv;  // the metric's inverse, diagonal
  m_inv << 1, 1, 1, 1 / (length * length), 1 / (length * length), 1 / (length * length);
  Motion x = x_d;
  std::vector<std::size_t> active;  // linearly independent, so at most six
  std::vector<Real> u;              // their multipliers, never negative
  const std::size_t budget = 8 * a.size() + 16;
  std::size_t steps = 0;
  while (true) {
    // The most violated constraint, the first of equals; none left: x is the projection.
    std::size_t p = a.size();
    Real worst = -kSlack;
    for (std::size_t i = 0; i < a.size(); ++i) {
      const Real s = a[i].dot(x) - b[i];
      if (s < worst) worst = s, p = i;
    }
    if (p == a.size()) return x;
    Real u_p = 0;
    while (true) {
      if (++steps > budget) return std::nullopt;  // not settled: not expected, but bounded
      // z: the M-shortest step raising a_p . x with the active constraints held tight;
      // r: how the active multipliers change along it.
      const auto k = static_cast<Eigen::Index>(active.size());
      Active N(6, k);
      for (Eigen::Index j = 0; j < k; ++j) N.col(j) = a[active[static_cast<std::size_t>(j)]];
      const Motion m_a = m_inv.cwiseProduct(a[p]);
      Multipliers r(k);
      Motion z = m_a;
      if (k > 0) {
        const Gram G = N.transpose() * m_inv.asDiagonal() * N;
        r = G.ldlt().solve(N.transpose() * m_a);
        z -= m_inv.asDiagonal() * (N * r);
      }
      // Full step: a_p's constraint becomes tight; none when a_p lies in the active span.
      const Real rise = a[p].dot(z);
      const bool dependent = !(rise > 1e-12 * a[p].dot(m_a));
      const Real full = dependent ? kInfinity : (b[p] - a[p].dot(x)) / rise;
      // Partial step: an active multiplier reaches zero first and that constraint is dropped.
      Real partial = kInfinity;
      std::size_t drop = active.size();
      for (Eigen::Index j = 0; j < k; ++j) {
        const auto i = static_cast<std::size_t>(j);
        if (r[j] > 0 && u[i] / r[j] < partial) partial = u[i] / r[j], drop = i;
      }
      const Real t = std::min(full, partial);
      if (t == kInfinity) return std::nullopt;  // a_p cannot be met with the others
      if (!dependent) x += t * z;
      for (Eigen::Index j = 0; j < k; ++j) u[static_cast<std::size_t>(j)] -= t * r[j];
      u_p += t;
      if (t == full) {
        active.push_back(p);
        u.push_back(u_p);
        break;
      }
      active.erase(active.begin() + static_cast<std::ptrdiff_t>(drop));
      u.erase(u.begin() + static_cast<std::ptrdiff_t>(drop));
    }
  }
}

Vec3 rotation_vector(const Mat3& R) {
  // Angle from the trace, axis from the skew part; near pi from the diagonal.
  const Real cos_angle = std::clamp((R.trace() - 1) / 2, Real{-1}, Real{1});
  const Vec3 skew(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  const Real sin_angle = skew.norm() / 2;
  const Real angle = std::atan2(sin_angle, cos_angle);
  if (angle < 1e-12) return skew / 2;
  if (angle < std::numbers::pi - 1e-6) return skew * (angle / (2 * sin_angle));
  Vec3 axis;
  const Mat3 B = (R + Mat3::Identity()) / 2;
  int k = 0;
  B.diagonal().maxCoeff(&k);
  axis = B.col(k) / std::sqrt(std::max(B(k, k), Real{0}));
  if (axis.dot(skew) < 0) axis = -axis;
  return axis.normalized() * angle;
}

Mat3 rotation_from_vector(const Vec3& w) {
  const Real angle = w.norm();
  if (angle == 0) return Mat3::Identity();
  const Vec3 k = w / angle;
  Mat3 K;
  K << 0, -k.z(), k.y(), k.z(), 0, -k.x(), -k.y(), k.x(), 0;
  return Mat3::Identity() + std::sin(angle) * K + (1 - std::cos(angle)) * (K * K);
}

bool collides(const collision::CollisionModel& part, const Transform& X_WP,
              std::span<const SlideObstacle> obstacles, int* queries) {
  return first_hit(part, X_WP, obstacles, queries, nullptr, nullptr).has_value();
}

SlideResult slide(const SlideRequest& request, const SlidingSettings& settings) {
  SlideResult result;
  result.X_WP = request.X_WP;
  auto centre = [&](const Transform& X) { return X.apply(request.p_PC); };
  auto measure_stretch = [&] {
    result.stretch_m = (centre(request.X_WP_target) - centre(result.X_WP)).norm();
    result.stretch_deg =
        rotation_vector(request.X_WP_target.R * result.X_WP.R.transpose()).norm() / kDegree;
  };
  measure_stretch();
  if (result.stretch_m > settings.band_limit_m || result.stretch_deg > settings.band_limit_deg) {
    result.status = SlideStatus::kOverstretched;
    return result;
  }
  std::vector<SlideContact> touching;
  if (!proves_free(request.start_proof, request) &&
      first_hit(request, result.X_WP, result.collision_queries)) {
    const std::optional<Transform> off =
        off_touching(request, settings, touching, result.collision_queries);
    if (!off) {
      result.status = SlideStatus::kBlocked;
      return result;
    }
    result.X_WP = *off;
  }
  auto add_contact = [&](const SlideContact& k) {
    for (const SlideContact& c : result.contacts) {
      if (c.obstacle == k.obstacle && (c.p_W - k.p_W).norm() < 1e-4 && c.n_W.dot(k.n_W) > 0.9998) {
        return false;
      }
    }
    result.contacts.push_back(k);
    if (result.contacts.size() > kMaxSlideContacts) result.contacts.erase(result.contacts.begin());
    return true;
  };
  for (const SlideContact& k : request.previous_contacts) add_contact(k);
  for (const SlideContact& k : touching) add_contact(k);

  // The contacts move with the part; those it moves away from expire.
  auto follow_contacts = [&](const Vec3& c, const Vec3& v, const Vec3& w) {
    const Mat3 R = rotation_from_vector(w);
    std::vector<SlideContact> kept;
    for (SlideContact k : result.contacts) {
      const Vec3 p = c + v + R * (k.p_W - c);
      k.separation += k.n_W.dot(p - k.p_W);
      k.p_W = p;
      if (k.separation <= kContactExpiry) kept.push_back(k);
    }
    result.contacts = std::move(kept);
  };

  int stalled = 0;
  result.status = SlideStatus::kReached;
  for (int sub = 0; sub < settings.substeps; ++sub) {
    ++result.substeps;
    // 4. The rest of the wanted motion, projected onto what the contacts allow.
    const Vec3 c = centre(result.X_WP);
    Motion wanted;
    wanted << centre(request.X_WP_target) - c,
        rotation_vector(request.X_WP_target.R * result.X_WP.R.transpose());
    if (wanted.head<3>().norm() + wanted.tail<3>().norm() * request.size < settings.rest_m) break;
    // Each contact: not into it, and back out to the skin where closer (so that sliding
    // along a curved or faceted surface has room for what the first order misses).
    std::vector<Motion> constraints;
    std::vector<Real> clearance;
    for (const SlideContact& k : result.contacts) {
      Motion a;
      a << k.n_W, (k.p_W - c).cross(k.n_W);
      constraints.push_back(a);
      clearance.push_back(std::max<Real>(0, settings.skin_m - k.separation));
    }
    // Contacts that ask to back out further than their common room allows (the part
    // wedged between them) still forbid moving into them.
    const Real metric = settings.turn_stiffness * request.size;
    std::optional<Motion> projected = project_motion(wanted, constraints, clearance, metric);
    if (!projected) {
      std::fill(clearance.begin(), clearance.end(), Real{0});
      projected = project_motion(wanted, constraints, clearance, metric);
    }
    const Motion allowed = projected.value_or(Motion::Zero());
    // 5. At rest: nothing left that the contacts allow.
    if (allowed.head<3>().norm() + allowed.tail<3>().norm() * request.size < settings.rest_m) {
      result.status = SlideStatus::kAtRest;
      break;
    }
    const Vec3 v = allowed.head<3>(), w = allowed.tail<3>();
    // 1. Try the move; where it collides, bisect toward the exact contact pose.
    const Move motion{result.X_WP, c, v, w};
    const std::optional<Hit> end_hit = first_hit(request, motion.at(1), result.collision_queries);
    if (!end_hit) {
      result.X_WP = motion.at(1);
      follow_contacts(c, v, w);
      result.status = result.contacts.empty() ? SlideStatus::kReached : SlideStatus::kSliding;
      stalled = 0;
      continue;
    }
    result.status = SlideStatus::kSliding;
    const Bracket bracket =
        settings.pair_guided
            ? bracket_guided(request, motion, *end_hit, settings, result.collision_queries)
            : bracket_halving(request, motion, *end_hit, settings, result.collision_queries);
    const Real free = bracket.free;
    result.X_WP = motion.at(free);
    follow_contacts(c, free * v, free * w);
    // 2, 3. The contacts of the colliding pose, their kinds and normals. A hit on a surface
    // the part already touches (the colliding pair's normal is a known contact's, the part
    // pivoting into it about that contact) adds the pair's point with that normal; only a new
    // direction asks for the contact patches.
    int added = 0;
    const std::optional<SlideContact> touch =
        settings.pair_guided ? pair_contact(request, bracket.pair_at_hit, result.X_WP)
                             : std::nullopt;
    const auto known = touch ? std::find_if(result.contacts.begin(), result.contacts.end(),
                                            [&](const SlideContact& k) {
                                              return k.obstacle == touch->obstacle &&
                                                     k.n_W.dot(touch->n_W) > 0.9998;
                                            })
                             : result.contacts.end();
    if (known != result.contacts.end()) {
      SlideContact k = *touch;
      k.kind = known->kind;
      added = add_contact(k) ? 1 : 0;
    }
    if (added == 0) {
      std::vector<SlideContact> met;
      contacts_at(request, result.X_WP, motion.at(bracket.hit), met, result.collision_queries);
      for (const SlideContact& k : met) added += add_contact(k) ? 1 : 0;
    }
    result.new_contacts += added;
    // Two moves in a row that got nowhere (under a thousandth of the way): at rest.
    stalled = free < 1e-3 ? stalled + 1 : 0;
    if (stalled >= 2) {
      result.status = SlideStatus::kAtRest;
      break;
    }
  }
  if (result.status == SlideStatus::kReached && !result.contacts.empty()) {
    result.status = SlideStatus::kSliding;
  }
  measure_stretch();
  // Every pose the step accepted was found free against all the obstacles.
  result.proof.part = request.part;
  result.proof.X_WP = result.X_WP;
  result.proof.attached.assign(request.attached.begin(), request.attached.end());
  result.proof.obstacles.assign(request.obstacles.begin(), request.obstacles.end());
  if (request.fronts) request.fronts->keep_only(request.obstacles, request.part, request.attached);
  return result;
}

collision::SeparationFront& SlideFronts::of(
    const std::shared_ptr<const collision::CollisionModel>& obstacle,
    const std::shared_ptr<const collision::CollisionModel>& part) {
  for (Kept& k : fronts_) {
    if (k.obstacle == obstacle && k.part == part) return k.front;
  }
  fronts_.push_back({obstacle, part, {}});
  return fronts_.back().front;
}

void SlideFronts::keep_only(std::span<const SlideObstacle> obstacles,
                            const std::shared_ptr<const collision::CollisionModel>& part,
                            std::span<const SlideAttachment> attached) {
  std::erase_if(fronts_, [&](const Kept& k) {
    return (k.part != part &&
            std::none_of(attached.begin(), attached.end(),
                         [&](const SlideAttachment& a) { return a.model == k.part; })) ||
           std::none_of(obstacles.begin(), obstacles.end(),
                        [&](const SlideObstacle& o) { return o.model == k.obstacle; });
  });
}

}  // namespace dovetail::interaction
