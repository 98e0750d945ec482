#include "dovetail/collision/collision_world.h"

#include <algorithm>
#include <array>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>

#include "core/vertex_triangles.h"
#include "dovetail/collision/containment.h"
#include "dovetail/collision/convex.h"
#include "dovetail/collision/distance.h"
#include "dovetail/collision/task_system.h"
#include "dovetail/collision/tri_tri.h"
#include "polygon/hierarchy_common.h"
#include "world/rotated_bounds.h"

namespace dovetail::collision {

namespace {

/// What parts with the same mesh share: built once, on first need.
struct Shape {
  std::shared_ptr<const Mesh> mesh;
  std::shared_ptr<const CollisionModel> model;  ///< polygon level, built for the first exact pair
  /// The cross-check's polygon level (WorldSettings::cross_check), on first need.
  std::shared_ptr<const CollisionModel> check_model;
  /// Distance hierarchy, built for the first exact distance query.
  std::shared_ptr<const DistanceModel> distance_model;
  /// Convex level and tight world boxes of moving parts: built when a pair's
  /// plan first needs it (Impl::defers_convex_level), not before.
  std::shared_ptr<const ConvexHull> hull;
  /// A small hull's vertices by coordinate (every x, then every y, then
  /// every z), for its world boxes; empty for a large hull.
  std::vector<Real> small_hull;
  bool hull_failed = false;  ///< flat part: no hull, conservative boxes
  /// Closed and on its hull (surface_on_hull): the hull is the part. Decided
  /// with the hull, when a tolerance asks for it.
  std::optional<bool> convex;
  Vec3 local_min, local_max;  ///< bounds in the part's frame
  Real max_abs = 0;
  /// Triangles around each vertex. Built with the model in pairs mode; used
  /// to follow a moving contact from one triangle to the next.
  detail::VertexTriangles around;
};

struct Part {
  PartId id;
  std::shared_ptr<Shape> shape;
  Transform X_WP;
  bool movable = true;
  bool alive = false;
  bool in_broadphase = false;
  bool dirty = true;
  LevelOfDetail level = LevelOfDetail::kExact;
  std::string name;
  std::array<std::uint32_t, 6>
      extremal{};  ///< hull vertices extremal along +-x, +-y, +-z last step
};

/// What the last steps learned about a pair (temporal coherence). Only the
/// work depends on it, never a verdict.
struct PairCache {
  SeparatingPlaneCache plane;
  GjkCache gjk;
  /// First-hit mode: the triangle pair that intersected last step. Parts in
  /// contact usually still touch there, which then decides the pair at once.
  TrianglePair witness;
  bool has_witness = false;
  /// First-hit mode: the subtree pair around the last hit, searched next
  /// when the witness and its neighbours no longer intersect.
  TraversalHint hint;
  /// The box pairs the last query found apart (PairPlan::front).
  SeparationFront front;
};

/// A pair's plan as kept: a PairPlan whose reason is an index into the
/// world's list of distinct reasons (a crowded scene plans a hundred
/// thousand pairs with a handful of sentences).
struct StoredPlan {
  PartPair pair;
  LevelOfDetail level = LevelOfDetail::kExact;
  bool convex_level = false;
  std::optional<Method> method{};
  bool front = false;
  Real max_size = 0;
  std::uint32_t reason = 0;
};

/// Steps a pair may go untested before its cache is freed, by a pass every
/// so many steps.
constexpr std::uint64_t kForgetSteps = 1024;

/// Per-pair state kept across steps: the plan for as long as both parts
/// exist (plans() reports it), the cache while the pair is being tested. A
/// crowded scene meets ever more pairs; their caches (about 1 kB each with a
/// separation front) are freed once they have gone kForgetSteps steps
/// untested, so only the plans (about 100 bytes a pair) grow with the pairs
/// met.
struct PairState {
  StoredPlan plan;
  bool planned = false;
  std::uint64_t plan_version = 0;    ///< plans_version right after the plan was made
  std::unique_ptr<PairCache> cache;  ///< null until tested, and once forgotten
  std::uint64_t tested_at = 0;       ///< `steps` at its last test
  /// A planned pair whose separating-plane test waits for its hulls
  /// (Impl::defers_convex_level): the work the polygon level has spent on
  /// answers of "apart" (volume and triangle tests), and the work building
  /// the missing hulls is reckoned to cost.
  bool convex_deferred = false;
  std::uint64_t apart_work = 0;
  std::uint64_t hull_work = 0;
};

void sort_by_pair(std::vector<PairPlan>& plans) {
  std::sort(plans.begin(), plans.end(),
            [](const PairPlan& x, const PairPlan& y) { return x.pair < y.pair; });
}

std::uint64_t pair_key(std::uint32_t a, std::uint32_t b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(a) << 32) | b;
}

/// X_AB = X_WA^-1 X_WB.
Transform relative(const Transform& X_WA, const Transform& X_WB) {
  Transform X;
  X.R = X_WA.R.transpose() * X_WB.R;
  X.t = X_WA.R.transpose() * (X_WB.t - X_WA.t);
  return X;
}

/// The work of one candidate pair, filled in by whichever thread evaluates it.
struct PairWork {
  std::uint32_t a = 0, b = 0;
  LevelOfDetail level = LevelOfDetail::kExact;
  PairState* state = nullptr;  ///< the pair's caches and its plan
  Transform X_AB;              ///< B in A's frame, once the convex level has it
  // Outputs.
  bool colliding = false;
  bool convex_tested = false;
  bool convex_separated = false;
  bool cached_plane = false;
  bool polygon = false;
  bool by_witness = false;     ///< decided by last step's contact (Impl::witness_holds)
  bool search_capped = false;  ///< the separating plane or GJK stopped at its iteration cap
  CollideResult result;
};

}  // namespace

struct CollisionWorld::Impl {
  WorldSettings settings;
  std::unique_ptr<TaskSystem> tasks;
  std::unique_ptr<Broadphase> broadphase;
  std::vector<Part> parts;
  std::vector<std::uint32_t> free_slots;  ///< removed slots, reused smallest first
  std::map<const Mesh*, std::shared_ptr<Shape>> shapes;
  std::unordered_map<std::uint64_t, bool> interest;
  std::unordered_map<std::uint64_t, LevelOfDetail> levels;
  std::unordered_map<std::uint64_t, PairState> pair_states;
  /// The distinct reasons of the plans made (StoredPlan::reason), and their
  /// indices; node-based, so the pointers stay valid.
  std::vector<const std::string*> reasons;
  std::unordered_map<std::string, std::uint32_t> reason_ids;
  std::vector<ProxyPair> candidates;
  std::vector<PairWork> work;
  StepResult result;
  std::uint64_t steps = 0;  ///< step() calls so far, for the captures' context
  std::uint64_t plans_version = 0;
  /// (plans_version after it, pair key) of every plan made, in order: what
  /// plans_since() reads instead of every pair's state.
  std::vector<std::pair<std::uint64_t, std::uint64_t>> plan_log;

  Part& part(PartId id) {
    if (id.index >= parts.size() || !parts[id.index].alive || parts[id.index].id != id) {
      throw std::invalid_argument("collision world: unknown or removed part");
    }
    return parts[id.index];
  }

  std::shared_ptr<Shape> shape_for(const std::shared_ptr<const Mesh>& mesh) {
    const auto known = shapes.find(mesh.get());
    if (known != shapes.end()) return known->second;
    // Checked here, on the caller's thread, rather than when a worker first
    // builds the mesh's hierarchy.
    check_mesh(*mesh);
    auto shape = std::make_shared<Shape>();
    shape->mesh = mesh;
    const Bounds bounds = mesh_bounds(*mesh);
    shape->local_min = bounds.min;
    shape->local_max = bounds.max;
    shape->max_abs = detail::max_abs_coordinate(*mesh);
    shapes.emplace(mesh.get(), shape);
    return shape;
  }

  void ensure_hull(Shape& shape) {
    if (shape.hull || shape.hull_failed) return;
    try {
      shape.hull = std::make_shared<const ConvexHull>(
          compute_convex_hull(shape.mesh->vertices, shape.mesh->source));
      const std::vector<Vec3>& v = shape.hull->vertices;
      if (v.size() <= kSmallHull) {
        shape.small_hull.resize(3 * v.size());
        for (std::size_t i = 0; i < v.size(); ++i) {
          for (int k = 0; k < 3; ++k) shape.small_hull[k * v.size() + i] = v[i][k];
        }
      }
    } catch (const std::invalid_argument&) {
      shape.hull_failed = true;  // a flat part: conservative boxes, no convex level
    }
  }

  void ensure_distance_model(Shape& shape) {
    if (!shape.distance_model) shape.distance_model = build_distance_model(shape.mesh);
  }

  void ensure_model(Shape& shape) {
    if (shape.model) return;
    shape.model = build_model(polygon_method(), shape.mesh);
    if (settings.contacts == ContactDetail::kPairs)
      shape.around = detail::VertexTriangles(*shape.mesh);
  }

  Method polygon_method() const { return settings.method.value_or(Method::kObb); }

  /// Hulls of at most this many vertices get their world boxes from all
  /// their vertices, in one pass with six independent bounds, not from six
  /// walks to the extremal vertices, which wait on one comparison after
  /// another: with 30-vertex hulls the 1,000-polytope benchmark ran 1.2
  /// times as fast (docs/engine.md).
  static constexpr std::size_t kSmallHull = 64;

  /// The part's world box: for a small hull the bounds of its vertices,
  /// rotated (each coordinate as one row of R times the vertex) and then
  /// moved; for a larger one extremal hull vertices found by walking from last
  /// step's; without a hull (none built yet, or a flat part), the box of the
  /// transformed vertices for a fixed part (it moves seldom; the same box the
  /// hull would give) and the transformed local box for a moving one; widened
  /// by a margin far above rounding so the box holds the part as every later
  /// stage computes it.
  Aabb world_box(Part& p) {
    const Shape& shape = *p.shape;
    const Transform& X = p.X_WP;
    Aabb box;
    if (!shape.hull && !p.movable) {
      box.min = Vec3::Constant(std::numeric_limits<Real>::infinity());
      box.max = -box.min;
      for (const Vec3& v : shape.mesh->vertices) {
        const Vec3 v_W = X.apply(v);
        box.min = box.min.cwiseMin(v_W);
        box.max = box.max.cwiseMax(v_W);
      }
    } else if (!shape.small_hull.empty() && X.R.allFinite()) {
      const std::size_t n = shape.hull->vertices.size();
      const Real* x = shape.small_hull.data();
      const Real* y = x + n;
      const Real* z = y + n;
      const auto [lo, hi] = detail::rotated_bounds(X.R, x, y, z, n);
      box.max = hi + X.t;
      box.min = lo + X.t;
    } else if (shape.hull) {
      for (int k = 0; k < 3; ++k) {
        const Vec3 d_P = X.R.row(k).transpose();  // world axis k in the part's frame
        p.extremal[2 * k] = shape.hull->support(d_P, p.extremal[2 * k]);
        p.extremal[2 * k + 1] = shape.hull->support(-d_P, p.extremal[2 * k + 1]);
        box.max[k] = X.apply(shape.hull->vertices[p.extremal[2 * k]])[k];
        box.min[k] = X.apply(shape.hull->vertices[p.extremal[2 * k + 1]])[k];
      }
    } else {
      const Vec3 centre = X.apply((shape.local_min + shape.local_max) * 0.5);
      const Vec3 half = X.R.cwiseAbs() * ((shape.local_max - shape.local_min) * 0.5);
      box.min = centre - half;
      box.max = centre + half;
    }
    const Real margin = 0x1.0p-36 * (X.t.cwiseAbs().sum() + 3 * shape.max_abs);
    box.min.array() -= margin;
    box.max.array() += margin;
    return box;
  }

  bool interested(const Part& a, const Part& b) const {
    // Most scenes set no pair's interest: no hashing for the box pairs of
    // fixed parts, which a packed assembly reports every step.
    if (!interest.empty()) {
      const auto it = interest.find(pair_key(a.id.index, b.id.index));
      if (it != interest.end()) return it->second;
    }
    return a.movable || b.movable;
  }

  LevelOfDetail level_of(const Part& a, const Part& b) const {
    const auto it = levels.find(pair_key(a.id.index, b.id.index));
    if (it != levels.end()) return it->second;
    return std::min(a.level, b.level);
  }

  /// Whether the shape is convex (surface_on_hull and closed); needs its hull.
  static bool convex(Shape& shape) {
    if (!shape.convex) {
      // The surface test first: it stops at the first triangle off the hull.
      shape.convex = shape.hull &&
                     surface_on_hull(*shape.hull, shape.mesh->vertices, shape.mesh->triangles) &&
                     is_closed(*shape.mesh);
    }
    return *shape.convex;
  }

  /// Frees the caches of the pairs not tested for kForgetSteps steps.
  void forget_idle_caches() {
    for (auto& [key, state] : pair_states) {
      if (state.cache && state.tested_at + kForgetSteps <= steps) state.cache.reset();
    }
  }

  /// Plans a pair on its first test (serially: it may build the two hulls).
  void make_plan(const Part& a, const Part& b, PairState& state) {
    state.planned = true;
    state.plan_version = ++plans_version;
    plan_log.emplace_back(plans_version, pair_key(a.id.index, b.id.index));
    std::uint64_t deferred_hull_work = 0;
    PairPlan plan = plan_for(a, b, deferred_hull_work);
    state.convex_deferred = deferred_hull_work > 0;
    state.hull_work = deferred_hull_work;
    state.apart_work = 0;
    state.plan = {.pair = plan.pair,
                  .level = plan.level,
                  .convex_level = plan.convex_level,
                  .method = plan.method,
                  .front = plan.front,
                  .max_size = plan.max_size,
                  .reason = intern_reason(std::move(plan.reason))};
  }

  std::uint32_t intern_reason(std::string reason) {
    const auto [it, added] =
        reason_ids.emplace(std::move(reason), static_cast<std::uint32_t>(reasons.size()));
    if (added) reasons.push_back(&it->first);
    return it->second;
  }

  PairPlan to_plan(const StoredPlan& p) const {
    return {.pair = p.pair,
            .level = p.level,
            .convex_level = p.convex_level,
            .method = p.method,
            .front = p.front,
            .max_size = p.max_size,
            .reason = *reasons[p.reason]};
  }

  /// Work, in volume and triangle tests of the polygon level, that building a
  /// hull of n points is reckoned to cost: measured, a hull costs 0.7 to 5 µs
  /// a point (the exact incremental hull of a capsule, qhull's on CAD parts,
  /// the first build in a run) and a test about 50 ns (docs/pipeline.md).
  static constexpr std::uint64_t kHullWorkPerPoint = 64;

  /// The reckoned work of building the hulls of a and b not built yet.
  static std::uint64_t missing_hull_work(const Part& a, const Part& b) {
    std::uint64_t work = 0;
    const auto add = [&](const Shape& shape) {
      if (!shape.hull && !shape.hull_failed)
        work += kHullWorkPerPoint * shape.mesh->vertices.size();
    };
    add(*a.shape);
    if (b.shape != a.shape) add(*b.shape);
    return work;
  }

  /// Whether the pair of a and b, planned at level `asked`, waits for its
  /// convex level: in an exact world that plans its pairs itself, a
  /// separating-plane test pays only where it separates pairs the polygon
  /// level would otherwise spend work on; until the answers "apart" have cost
  /// as much as the missing hulls, they are not built (ski rental: at most
  /// twice the better of the two choices). A world given a method keeps the
  /// former behaviour (hulls at once), as do tolerances and the hull level,
  /// which decide by the hulls, and a pair with a part known to be flat (it
  /// has no convex level). A deferred pair is decided in one piece at any
  /// number of threads, never split (evaluate_split, which keeps no
  /// separation front, does other work), so that the work it counts, and
  /// with it the step its test turns on, is the same however many threads.
  bool defers_convex_level(const Part& a, const Part& b, LevelOfDetail asked) const {
    return !settings.method && settings.tolerance == 0 && asked == LevelOfDetail::kExact &&
           settings.convex_level && !a.shape->hull_failed && !b.shape->hull_failed;
  }

  /// Counts the work of a deferred pair's answer of "apart" at the polygon
  /// level; true once the answers have paid for the pair's missing hulls
  /// (or those were built meanwhile, for other pairs).
  bool apart_work_paid(const PairWork& w) {
    PairState& state = *w.state;
    if (!state.convex_deferred || !w.polygon || w.colliding) return false;
    state.apart_work += w.result.stats.volume_tests + w.result.stats.triangle_tests +
                        w.result.stats.triangle_volume_tests;
    state.hull_work = std::min(state.hull_work, missing_hull_work(parts[w.a], parts[w.b]));
    return state.apart_work >= state.hull_work;
  }

  /// Builds a deferred pair's hulls (serially), turns its separating-plane
  /// test on and plans it again (plans_since() has it).
  void upgrade_deferred_plan(const PairWork& w) {
    PairState& state = *w.state;
    Part& a = parts[w.a];
    Part& b = parts[w.b];
    const bool paid = state.hull_work > 0;
    ensure_hull(*a.shape);
    ensure_hull(*b.shape);
    state.convex_deferred = false;
    state.plan.convex_level = a.shape->hull && b.shape->hull;
    const std::string& old = *reasons[state.plan.reason];
    std::string why = old.substr(0, old.find(kDeferredReason));
    if (!state.plan.convex_level) {
      why += "; a part is flat (no hull), so no convex level";
    } else if (paid) {
      why +=
          ", after the separating-plane test, turned on once the answers 'apart' had cost as "
          "much work as building the hulls";
    } else {
      why +=
          ", after the separating-plane test, turned on once the hulls had been built for "
          "other pairs";
    }
    state.plan.reason = intern_reason(std::move(why));
    state.plan_version = ++plans_version;
    plan_log.emplace_back(plans_version, pair_key(a.id.index, b.id.index));
  }

  /// How a deferred pair's reason ends (upgrade_deferred_plan replaces it).
  static constexpr std::string_view kDeferredReason =
      "; the separating-plane test once the answers 'apart' have cost as much work as building "
      "the hulls it needs";

  /// The plan of a pair of parts a and b; sets deferred_hull_work when the
  /// pair's separating-plane test waits for its hulls (defers_convex_level).
  PairPlan plan_for(const Part& a, const Part& b, std::uint64_t& deferred_hull_work) {
    PairPlan plan{.pair = {a.id, b.id}};
    const LevelOfDetail asked = level_of(a, b);
    if (asked == LevelOfDetail::kBox) {
      plan.level = LevelOfDetail::kBox;
      plan.reason = "the scene asks for the box level: boxes that overlap are in contact";
      return plan;
    }
    const std::uint64_t hull_work = missing_hull_work(a, b);
    const bool defer = defers_convex_level(a, b, asked) && hull_work > 0;
    if (!defer) {
      ensure_hull(*a.shape);
      ensure_hull(*b.shape);
    }
    const bool hulls = a.shape->hull && b.shape->hull;
    if (asked == LevelOfDetail::kHull && hulls) {
      plan.level = LevelOfDetail::kHull;
      plan.convex_level = true;
      plan.reason = "the scene asks for the hull level: GJK on the convex hulls";
      return plan;
    }
    // GJK's touching band is kGjkContactTolerance of the pair's scale; a
    // tolerance far above it is kept by the hull level of convex parts.
    const Real scale = hulls ? a.shape->hull->extent + b.shape->hull->extent : 0;
    if (settings.tolerance > 0 && hulls && settings.tolerance >= 1e-6 * scale && convex(*a.shape) &&
        convex(*b.shape)) {
      plan.level = LevelOfDetail::kHull;
      plan.convex_level = true;
      plan.reason =
          "both parts are convex (closed, every triangle on the hull): the hulls are the parts, "
          "and GJK on them decides contact far within the tolerance";
      return plan;
    }
    plan.level = LevelOfDetail::kExact;
    plan.convex_level = hulls && settings.convex_level;
    if (defer) deferred_hull_work = hull_work;
    plan.method = polygon_method();
    plan.front = !settings.method;
    const bool cuts = *plan.method == Method::kObb || *plan.method == Method::kAabb;
    plan.max_size = cuts ? settings.tolerance : 0;
    std::string why;
    if (asked == LevelOfDetail::kHull)
      why = "the scene asks for the hull level, but a part is flat (no hull): ";
    else if (!hulls && !defer)
      why = "a part is flat (no hull), so no convex level: ";
    why += settings.method ? "the polygon level on the hierarchy the world was given (" +
                                 std::string(method_name(*plan.method)) + ")"
                           : std::string(
                                 "the polygon level on OBB trees, the fastest exact hierarchy "
                                 "measured, keeping the box pairs found apart from step to step");
    if (plan.convex_level) why += ", after the separating-plane test";
    if (defer) why += kDeferredReason;
    if (settings.tolerance > 0) {
      why += cuts ? "; a part is not convex, so its hull would not keep the tolerance: box pairs "
                    "smaller than the tolerance count as contact"
                  : "; a part is not convex, and this hierarchy has no tolerance cut: exact";
    }
    plan.reason = std::move(why);
    return plan;
  }

  /// Decides one pair up to the polygon level by its plan; returns whether
  /// the polygon level must still decide it.
  bool evaluate_coarse(PairWork& w) {
    const Part& a = parts[w.a];
    const Part& b = parts[w.b];
    const StoredPlan& plan = w.state->plan;
    PairCache& cache = *w.state->cache;
    if (plan.level == LevelOfDetail::kBox) {
      w.colliding = true;
      return false;
    }
    w.X_AB = relative(a.X_WP, b.X_WP);
    const Transform& X_AB = w.X_AB;
    const bool polygon_level = plan.level == LevelOfDetail::kExact || !plan.convex_level;
    if (polygon_level && witness_holds(w, X_AB)) return false;
    if (plan.convex_level) {
      const SeparatingPlaneResult separation =
          separating_plane_test(*a.shape->hull, *b.shape->hull, X_AB, cache.plane);
      w.convex_tested = true;
      w.cached_plane = separation.cache_hit;
      w.search_capped = separation.gave_up && !separation.overlap &&
                        separation.iterations >= SeparatingPlaneSettings{}.max_iterations;
      if (separation.separated) {
        w.convex_separated = true;
        return false;
      }
      if (plan.level == LevelOfDetail::kHull) {
        const GjkResult g = gjk(*a.shape->hull, *b.shape->hull, X_AB, &cache.gjk);
        w.colliding = g.intersecting;
        w.search_capped = w.search_capped || g.hit_iteration_cap;
        return false;
      }
    }
    w.polygon = true;
    return true;
  }

  /// All intersecting triangle pairs, or only whether there is one.
  CollideRequest polygon_request() const {
    return {.all_pairs = settings.contacts == ContactDetail::kTriangles};
  }

  /// The start of a first-hit pair's polygon level, before its hulls'
  /// test: a pair in contact at the last step is most often still in
  /// contact at or next to the same triangles, and a hit there decides it
  /// (colliding, at the polygon level) without the hulls' test, which could
  /// not have separated it. Returns whether it did; a miss leaves its
  /// work in w.result's statistics for evaluate_polygon to add.
  bool witness_holds(PairWork& w, const Transform& X_AB) {
    PairCache& cache = *w.state->cache;
    if (polygon_request().all_pairs || !cache.has_witness) return false;
    w.result = CollideResult{};
    const PairTriangles pair{*parts[w.a].shape, *parts[w.b].shape, X_AB, w.result.stats};
    const bool hit = follow_witness(pair, cache.witness) || search_witness(pair, cache.witness);
    if (hit) w.result.pairs = {cache.witness};
    w.result.colliding = hit;
    w.polygon = w.by_witness = w.colliding = hit;
    return hit;
  }

  /// The polygon level of one pair, in one piece, after witness_holds.
  void evaluate_polygon(PairWork& w) {
    const Part& a = parts[w.a];
    const Part& b = parts[w.b];
    const Transform& X_AB = w.X_AB;
    PairCache& cache = *w.state->cache;
    CollideRequest request = polygon_request();
    request.max_size = w.state->plan.max_size;
    const CollideStats witness_work = w.result.stats;
    CollideRequest hinted = request;
    if (!request.all_pairs) hinted.hint = &cache.hint;
    if (w.state->plan.front) hinted.front = &cache.front;
    w.result = a.shape->model->collide(*b.shape->model, X_AB, hinted);
    w.result.stats.triangle_tests += witness_work.triangle_tests;
    w.result.stats.triangle_volume_tests += witness_work.triangle_volume_tests;
    w.colliding = w.result.colliding;
    // A hit of the tolerance cut has no triangle pair to follow.
    cache.has_witness = !request.all_pairs && w.colliding && !w.result.pairs.empty();
    if (cache.has_witness) cache.witness = w.result.pairs.front();
  }

  /// A triangle's corners and their bounding box.
  struct Corners {
    Corners(const Vec3& p, const Vec3& q, const Vec3& r)
        : v{p, q, r}, lo(p.cwiseMin(q).cwiseMin(r)), hi(p.cwiseMax(q).cwiseMax(r)) {}
    bool box_meets(const Corners& o) const {
      return detail::aligned_boxes_meet(lo, hi, o.lo, o.hi);
    }
    std::array<Vec3, 3> v;
    Vec3 lo, hi;
  };

  /// A pair's triangles as the searches for its contact read them: A's as
  /// they are, B's mapped into A's frame by Transform::apply, as the
  /// hierarchies map them. As in the hierarchies' leaves, a pair whose
  /// bounding boxes (of the very coordinates the exact test reads) are
  /// apart is rejected before the exact test, which alone counts in
  /// stats.triangle_tests.
  struct PairTriangles {
    const Shape& a;
    const Shape& b;
    const Transform& X_AB;
    CollideStats& stats;

    Corners in_a(std::uint32_t t) const {
      const TriangleIndices& f = a.mesh->triangles[t];
      return {a.mesh->vertices[f[0]], a.mesh->vertices[f[1]], a.mesh->vertices[f[2]]};
    }
    Corners in_b(std::uint32_t t) const {
      const TriangleIndices& f = b.mesh->triangles[t];
      return {X_AB.apply(b.mesh->vertices[f[0]]), X_AB.apply(b.mesh->vertices[f[1]]),
              X_AB.apply(b.mesh->vertices[f[2]])};
    }
    bool meet(const Corners& p, const Corners& q) const {
      if (!p.box_meets(q)) return false;
      ++stats.triangle_tests;
      return triangles_intersect(p.v[0], p.v[1], p.v[2], q.v[0], q.v[1], q.v[2]);
    }
  };

  /// Follows last step's contact: the witness pair itself, then each of its
  /// triangles against the triangles around the other's vertices (the
  /// contact usually moves to a neighbour), each neighbour once, in the order
  /// of the vertices. On success `witness` is the pair found. A hit is a
  /// proof; a miss proves nothing and the caller searches on.
  static bool follow_witness(const PairTriangles& pair, TrianglePair& witness) {
    const TrianglePair last = witness;
    const Corners last_a = pair.in_a(last.a);
    const Corners last_b = pair.in_b(last.b);  // once for all of A's candidates
    if (pair.meet(last_a, last_b)) return true;
    bool found = false;
    around_once(pair.a, last.a, [&](std::uint32_t t) {
      found = pair.meet(pair.in_a(t), last_b);
      if (found) witness = {t, last.b};
      return found;
    });
    if (found) return true;
    around_once(pair.b, last.b, [&](std::uint32_t t) {
      found = pair.meet(last_a, pair.in_b(t));
      if (found) witness = {last.a, t};
      return found;
    });
    return found;
  }

  /// Parts with fewer triangles are not searched by search_witness: their
  /// hierarchies are about six levels deep or less, and a traversal from
  /// the roots costs about what the two searches cost (docs/engine.md, "A
  /// fifth round").
  static constexpr std::size_t kSearchedMesh = 64;

  /// After follow_witness: each triangle of the lost witness searched for
  /// against the other part's whole hierarchy (CollisionModel::
  /// search_triangle), the larger triangle first. A part often moves by
  /// more than a ring of the other's triangles in a step, and a large
  /// triangle that crossed the other part's surface most often still does,
  /// elsewhere. B's triangle is searched in A's frame, in which its corners
  /// are the exact test's own; A's is searched in B's frame, and what that
  /// search visits is tested in A's frame like every other pair. The margin
  /// covers the rounding of the boxes and of the move into B's frame
  /// (relative 2^-40, as the hierarchies' own margin) many times over. A hit
  /// is a proof; a miss proves nothing and the caller traverses.
  static bool search_witness(const PairTriangles& pair, TrianglePair& witness) {
    if (pair.a.mesh->triangles.size() < kSearchedMesh ||
        pair.b.mesh->triangles.size() < kSearchedMesh) {
      return false;
    }
    const Transform& X_AB = pair.X_AB;
    const Real margin = 0x1.0p-36 * (pair.a.max_abs + pair.b.max_abs + X_AB.t.cwiseAbs().sum());
    const TrianglePair last = witness;
    const Corners last_a = pair.in_a(last.a);
    const Corners last_b = pair.in_b(last.b);
    const auto b_in_a = [&] {
      return pair.a.model->search_triangle(
          last_b.v, margin,
          [&](std::uint32_t t) {
            if (!pair.meet(pair.in_a(t), last_b)) return false;
            witness = {t, last.b};
            return true;
          },
          pair.stats);
    };
    const auto a_in_b = [&] {
      const Transform X_BA = X_AB.inverse();
      const std::array<Vec3, 3> moved{X_BA.apply(last_a.v[0]), X_BA.apply(last_a.v[1]),
                                      X_BA.apply(last_a.v[2])};
      return pair.b.model->search_triangle(
          moved, margin,
          [&](std::uint32_t t) {
            if (!pair.meet(last_a, pair.in_b(t))) return false;
            witness = {last.a, t};
            return true;
          },
          pair.stats);
    };
    const bool a_larger = (last_a.hi - last_a.lo).sum() > (last_b.hi - last_b.lo).sum();
    return a_larger ? a_in_b() || b_in_a() : b_in_a() || a_in_b();
  }

  /// Calls visit(t) for every triangle other than `f` that shares a vertex
  /// with it, once each, around f's first vertex, then its second, then its
  /// third, until visit returns true.
  template <typename Visit>
  static void around_once(const Shape& shape, std::uint32_t f, Visit&& visit) {
    const Mesh& mesh = *shape.mesh;
    const TriangleIndices& corners = mesh.triangles[f];
    for (int i = 0; i < 3; ++i) {
      const std::uint32_t v = corners[i];
      for (std::uint32_t k = shape.around.offsets[v]; k < shape.around.offsets[v + 1]; ++k) {
        const std::uint32_t t = shape.around.triangles[k];
        if (t == f) continue;
        // Met already around an earlier corner?
        const TriangleIndices& tt = mesh.triangles[t];
        const auto has = [&](std::uint32_t u) { return tt[0] == u || tt[1] == u || tt[2] == u; };
        if ((i > 0 && has(corners[0])) || (i > 1 && has(corners[1]))) continue;
        if (visit(t)) return;
      }
    }
  }

  /// The polygon level of heavy pairs, each divided into parts, all parts of
  /// all pairs in one parallel loop (fine grain, balanced across pairs).
  void evaluate_split(const std::vector<std::size_t>& heavy_pairs) {
    std::vector<std::unique_ptr<SplitQuery>> queries(heavy_pairs.size());
    tasks->parallel_for(heavy_pairs.size(), 1, [&](std::size_t begin, std::size_t end) {
      for (std::size_t q = begin; q < end; ++q) {
        const PairWork& w = work[heavy_pairs[q]];
        queries[q] =
            parts[w.a].shape->model->split(*parts[w.b].shape->model, w.X_AB, polygon_request());
      }
    });
    std::vector<std::pair<std::uint32_t, std::uint32_t>> jobs;  // (query, part)
    for (std::size_t q = 0; q < queries.size(); ++q) {
      for (std::size_t i = 0; i < queries[q]->parts(); ++i) {
        jobs.emplace_back(static_cast<std::uint32_t>(q), static_cast<std::uint32_t>(i));
      }
    }
    tasks->parallel_for(jobs.size(), 1, [&](std::size_t begin, std::size_t end) {
      for (std::size_t j = begin; j < end; ++j) queries[jobs[j].first]->run(jobs[j].second);
    });
    for (std::size_t q = 0; q < queries.size(); ++q) {
      PairWork& w = work[heavy_pairs[q]];
      w.result = queries[q]->result();
      w.colliding = w.result.colliding;
    }
  }

  /// A pair worth splitting over the threads: both parts large.
  bool heavy(const PairWork& w) const {
    constexpr std::size_t kHeavyProduct = std::size_t{1} << 20;
    return parts[w.a].shape->mesh->triangle_count() * parts[w.b].shape->mesh->triangle_count() >=
           kHeavyProduct;
  }

  /// Distance of parts a and b, computed with the smaller index as A (the
  /// orientation of the pair's caches, as in step()) and returned in the
  /// caller's order.
  PartDistance distance(PartId id_a, PartId id_b, const PartDistanceRequest& request) {
    if (id_a == id_b) throw std::invalid_argument("collision world: distance of a part to itself");
    Part& first = part(id_a);
    Part& second = part(id_b);
    const bool swapped = id_b.index < id_a.index;
    Part& a = swapped ? second : first;
    Part& b = swapped ? first : second;
    const LevelOfDetail level = request.level ? *request.level : level_of(a, b);
    ensure_hull(*a.shape);
    ensure_hull(*b.shape);
    const bool hulls = a.shape->hull && b.shape->hull;
    const Transform X_AB = relative(a.X_WP, b.X_WP);
    PartDistance r;
    if (level != LevelOfDetail::kExact && hulls) {
      PairState& state = pair_states[pair_key(a.id.index, b.id.index)];
      if (!state.cache) state.cache = std::make_unique<PairCache>();
      state.tested_at = steps;
      GjkCache& warm = state.cache->gjk;
      r.warm_started = request.warm_start && warm.valid;
      GjkCache cold;
      GjkCache& cache = request.warm_start ? warm : cold;
      const GjkResult g = gjk(*a.shape->hull, *b.shape->hull, X_AB, &cache);
      if (!request.warm_start) warm = cold;
      r.level = LevelOfDetail::kHull;
      r.distance = g.distance;
      r.intersecting = g.intersecting;
      r.p_W = a.X_WP.apply(g.closest_a);
      r.q_W = a.X_WP.apply(g.closest_b);
      r.feature_a = g.feature_a;
      r.feature_b = g.feature_b;
      r.gjk_iterations = g.iterations;
    } else {
      ensure_distance_model(*a.shape);
      ensure_distance_model(*b.shape);
      const DistanceResult d = collision::distance(*a.shape->distance_model,
                                                   *b.shape->distance_model, X_AB, request.exact);
      r.level = LevelOfDetail::kExact;
      r.distance = d.distance;
      r.intersecting = d.distance == 0;
      r.p_W = a.X_WP.apply(d.p_A);
      r.q_W = a.X_WP.apply(d.q_A);
      r.triangle_a = d.triangle_a;
      r.triangle_b = d.triangle_b;
      r.stats = d.stats;
    }
    if (swapped) {
      std::swap(r.p_W, r.q_W);
      std::swap(r.feature_a, r.feature_b);
      std::swap(r.triangle_a, r.triangle_b);
    }
    return r;
  }

  bool within(PartId id_a, PartId id_b, Real eps, const PartDistanceRequest& request) {
    if (!(eps >= 0)) throw std::invalid_argument("collision world: tolerance must be >= 0");
    if (id_a == id_b) throw std::invalid_argument("collision world: distance of a part to itself");
    Part& first = part(id_a);
    Part& second = part(id_b);
    Part& a = id_b.index < id_a.index ? second : first;
    Part& b = id_b.index < id_a.index ? first : second;
    const LevelOfDetail level = request.level ? *request.level : level_of(a, b);
    ensure_hull(*a.shape);
    ensure_hull(*b.shape);
    if (level != LevelOfDetail::kExact && a.shape->hull && b.shape->hull) {
      const PartDistance d = distance(a.id, b.id, request);
      return d.intersecting || d.distance <= eps;
    }
    ensure_distance_model(*a.shape);
    ensure_distance_model(*b.shape);
    return within_tolerance(*a.shape->distance_model, *b.shape->distance_model,
                            relative(a.X_WP, b.X_WP), eps)
        .within;
  }

  void prepare() {
    std::vector<Shape*> shapes_in_use;
    std::unordered_map<const Shape*, std::size_t> index;
    for (const Part& p : parts) {
      if (p.alive && index.emplace(p.shape.get(), shapes_in_use.size()).second) {
        shapes_in_use.push_back(p.shape.get());
      }
    }
    // Distinct shapes are independent: each task builds one shape's data.
    const auto build = [&](const std::vector<Shape*>& todo, auto&& what) {
      tasks->parallel_for(todo.size(), 1, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) what(*todo[i]);
      });
    };
    build(shapes_in_use, [&](Shape& shape) { ensure_hull(shape); });

    // Models for every part that step() could take to the polygon level: a
    // part at the exact level, a part of a pair set to the exact level, and,
    // when some part is flat (no hull, so its pairs are decided exactly),
    // every part, since any may meet that one.
    std::vector<char> needs_model(shapes_in_use.size(), 0);
    bool any_flat = false;
    for (const Part& p : parts) {
      if (!p.alive) continue;
      any_flat = any_flat || p.shape->hull_failed;
      if (p.level == LevelOfDetail::kExact) needs_model[index.at(p.shape.get())] = 1;
    }
    for (const auto& [key, level] : levels) {
      if (level != LevelOfDetail::kExact) continue;
      for (const std::uint64_t i : {key >> 32, key & 0xffffffffu}) {
        const Part& p = parts[i];
        if (p.alive) needs_model[index.at(p.shape.get())] = 1;
      }
    }
    std::vector<Shape*> todo;
    for (std::size_t i = 0; i < shapes_in_use.size(); ++i) {
      if (needs_model[i] || any_flat) todo.push_back(shapes_in_use[i]);
    }
    build(todo, [&](Shape& shape) { ensure_model(shape); });
  }

  /// Failure capture after the pairs are decided, serially and in pair
  /// order (so the files do not depend on the threads): capped searches,
  /// poses that are not finite, and the cross-check's disagreements.
  void capture_suspects() {
    for (const PairWork& w : work) {
      const Part& a = parts[w.a];
      const Part& b = parts[w.b];
      const Transform X_AB = relative(a.X_WP, b.X_WP);
      const auto record = [&](CaptureKind kind, std::string what) {
        settings.capture->record(
            {.kind = kind,
             .what = std::move(what),
             .context = "step " + std::to_string(steps) + ": '" + a.name + "' and '" + b.name + "'",
             .a = a.shape->mesh,
             .b = b.shape->mesh,
             .X_AB = X_AB});
      };
      const bool finite = a.X_WP.R.allFinite() && a.X_WP.t.allFinite() && b.X_WP.R.allFinite() &&
                          b.X_WP.t.allFinite();
      if (!finite) {
        record(CaptureKind::kNonFinite, "a part's pose is not finite");
        continue;
      }
      if (w.search_capped) {
        record(CaptureKind::kIterationCap,
               w.level == LevelOfDetail::kHull
                   ? "GJK or the separating-plane search stopped at its cap"
                   : "the separating-plane search stopped at its cap");
      }
      if (!settings.cross_check || w.level != LevelOfDetail::kExact) continue;
      if (!w.polygon && !w.convex_separated) continue;
      for (Shape* shape : {a.shape.get(), b.shape.get()}) {
        if (!shape->check_model)
          shape->check_model = build_model(*settings.cross_check, shape->mesh);
      }
      const bool check = a.shape->check_model->collide(*b.shape->check_model, X_AB).colliding;
      if (check == w.colliding) continue;
      const std::string verdict = w.colliding ? "intersecting" : "separate";
      const std::string other = check ? "intersecting" : "separate";
      record(CaptureKind::kMethodsDisagree,
             (w.polygon ? std::string(method_name(polygon_method())) + " says " + verdict
                        : std::string("the convex level separated the hulls")) +
                 ", " + std::string(method_name(*settings.cross_check)) + " says " + other);
    }
  }

  /// The polygon-level hierarchies of the pairs that reached that level,
  /// built once per mesh, the meshes spread over the threads.
  void build_models_for_polygon_pairs() {
    std::vector<Shape*> todo;
    for (const PairWork& w : work) {
      if (!w.polygon) continue;
      for (Shape* shape : {parts[w.a].shape.get(), parts[w.b].shape.get()}) {
        if (!shape->model && std::find(todo.begin(), todo.end(), shape) == todo.end())
          todo.push_back(shape);
      }
    }
    tasks->parallel_for(todo.size(), 1, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) ensure_model(*todo[i]);
    });
  }

  const StepResult& step() {
    StepResult next;
    // 1. World boxes of new and moved parts; broad phase.
    for (Part& p : parts) {
      if (!p.alive) continue;
      if (p.dirty || !p.in_broadphase) {
        const Aabb box = world_box(p);
        if (p.in_broadphase)
          broadphase->move(p.id.index, box);
        else
          broadphase->add(p.id.index, box);
        p.in_broadphase = true;
        p.dirty = false;
      }
      ++next.stats.parts;
    }
    broadphase->pairs(candidates);
    next.stats.box_pairs = candidates.size();

    // 2. Pairs of interest and their plans (serially: planning a pair may
    //    build its hulls).
    work.clear();
    for (const ProxyPair& c : candidates) {
      const Part& a = parts[c.a];
      const Part& b = parts[c.b];
      if (!interested(a, b)) continue;
      PairWork w;
      w.a = c.a;
      w.b = c.b;
      w.state = &pair_states[pair_key(c.a, c.b)];
      if (!w.state->planned) make_plan(a, b, *w.state);
      if (!w.state->cache) w.state->cache = std::make_unique<PairCache>();
      w.state->tested_at = steps;
      w.level = w.state->plan.level;
      work.push_back(std::move(w));
    }
    next.stats.tested_pairs = work.size();

    // 3. The box and convex levels in parallel over pairs; then the
    //    hierarchies the polygon level needs and has not built yet (one task
    //    per mesh); then the polygon level in parallel over pairs (coarse
    //    grain), with heavy pairs each split over the threads (fine grain).
    //    Either way each pair's result is the same.
    tasks->parallel_for(work.size(), 16, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) evaluate_coarse(work[i]);
    });
    build_models_for_polygon_pairs();
    // First-hit queries are not split: a divided query may do different work
    // than an undivided one, and the counters must not depend on the threads.
    const bool split_heavy =
        tasks->thread_count() > 1 && settings.contacts == ContactDetail::kTriangles;
    std::vector<std::size_t> polygon_pairs, heavy_pairs;
    for (std::size_t i = 0; i < work.size(); ++i) {
      if (!work[i].polygon || work[i].by_witness) continue;
      const bool split = split_heavy && heavy(work[i]) && !work[i].state->convex_deferred;
      (split ? heavy_pairs : polygon_pairs).push_back(i);
    }
    tasks->parallel_for(polygon_pairs.size(), 1, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) evaluate_polygon(work[polygon_pairs[i]]);
    });
    if (!heavy_pairs.empty()) evaluate_split(heavy_pairs);

    if (settings.capture) capture_suspects();
    ++steps;
    if (steps % kForgetSteps == 0) forget_idle_caches();

    // 4. Gather in pair order: contacts sorted by (a, b, triangle_a, triangle_b).
    for (const PairWork& w : work) {
      if (apart_work_paid(w)) upgrade_deferred_plan(w);
      StepStats& s = next.stats;
      s.convex_tests += w.convex_tested;
      s.convex_separated += w.convex_separated;
      s.cached_planes += w.cached_plane;
      s.polygon_pairs += w.polygon;
      s.polygon.volume_tests += w.result.stats.volume_tests;
      s.polygon.triangle_tests += w.result.stats.triangle_tests;
      s.polygon.triangle_volume_tests += w.result.stats.triangle_volume_tests;
      if (!w.colliding) continue;
      const PartPair pair{parts[w.a].id, parts[w.b].id};
      next.colliding.push_back(pair);
      if (w.polygon && settings.contacts == ContactDetail::kTriangles) {
        for (const TrianglePair& t : w.result.pairs)
          next.contacts.push_back({pair.a, pair.b, t.a, t.b});
      } else {
        next.contacts.push_back({pair.a, pair.b, kNoTriangle, kNoTriangle});
      }
    }
    next.stats.colliding_pairs = next.colliding.size();

    // 5. Changes since the last step.
    std::set_difference(next.colliding.begin(), next.colliding.end(), result.colliding.begin(),
                        result.colliding.end(), std::back_inserter(next.began));
    std::set_difference(result.colliding.begin(), result.colliding.end(), next.colliding.begin(),
                        next.colliding.end(), std::back_inserter(next.ended));
    result = std::move(next);
    return result;
  }
};

CollisionWorld::CollisionWorld(const WorldSettings& settings) : impl_(std::make_unique<Impl>()) {
  impl_->settings = settings;
  impl_->tasks = make_task_system(settings.threads);
  impl_->broadphase = make_broadphase(settings.broadphase);
}

CollisionWorld::~CollisionWorld() = default;

PartId CollisionWorld::add_part(const PartDef& def) {
  if (!def.mesh)
    throw std::invalid_argument("collision world: part '" + def.name + "' has no mesh");
  Impl& w = *impl_;
  std::shared_ptr<Shape> shape = w.shape_for(def.mesh);  // may refuse the mesh
  std::uint32_t index;
  if (!w.free_slots.empty()) {
    const auto smallest = std::min_element(w.free_slots.begin(), w.free_slots.end());
    index = *smallest;
    w.free_slots.erase(smallest);
  } else {
    index = static_cast<std::uint32_t>(w.parts.size());
    w.parts.emplace_back();
  }
  Part& p = w.parts[index];
  const std::uint32_t generation = p.id.generation + (p.id.valid() ? 1 : 0);
  p = Part{};
  p.id = {index, generation};
  p.shape = std::move(shape);
  p.X_WP = def.X_WP;
  p.movable = def.movable;
  p.level = def.level;
  p.name = def.name;
  p.alive = true;
  // Pairs of fixed parts are of no interest unless a pair is set to be.
  w.broadphase->set_fixed(index, !def.movable);
  return p.id;
}

void CollisionWorld::remove_part(PartId id) {
  Impl& w = *impl_;
  Part& p = w.part(id);
  if (p.in_broadphase) w.broadphase->remove(id.index);
  p.alive = false;
  p.in_broadphase = false;
  p.shape.reset();
  w.free_slots.push_back(id.index);
  // Forget every per-pair setting and cache of the slot (order does not matter).
  auto involves = [&](std::uint64_t key) {
    return (key >> 32) == id.index || (key & 0xffffffffu) == id.index;
  };
  std::erase_if(w.pair_states, [&](const auto& kv) { return involves(kv.first); });
  ++w.plans_version;
  std::erase_if(w.interest, [&](const auto& kv) { return involves(kv.first); });
  std::erase_if(w.levels, [&](const auto& kv) { return involves(kv.first); });
}

void CollisionWorld::set_pose(PartId id, const Transform& X_WP) {
  Part& p = impl_->part(id);
  p.X_WP = X_WP;
  p.dirty = true;
}

const Transform& CollisionWorld::pose(PartId id) const { return impl_->part(id).X_WP; }
const std::string& CollisionWorld::name(PartId id) const { return impl_->part(id).name; }

std::size_t CollisionWorld::part_count() const {
  return static_cast<std::size_t>(std::count_if(impl_->parts.begin(), impl_->parts.end(),
                                                [](const Part& p) { return p.alive; }));
}

void CollisionWorld::set_interest(PartId a, PartId b, bool interested) {
  impl_->part(a);
  impl_->part(b);
  impl_->interest[pair_key(a.index, b.index)] = interested;
  if (interested) {
    // The broad phase must report the pair, even of two fixed parts.
    impl_->broadphase->set_fixed(a.index, false);
    impl_->broadphase->set_fixed(b.index, false);
  }
}

void CollisionWorld::set_pair_level(PartId a, PartId b, LevelOfDetail level) {
  impl_->part(a);
  impl_->part(b);
  impl_->levels[pair_key(a.index, b.index)] = level;
  // Planned again at the next test, with the new level.
  const auto it = impl_->pair_states.find(pair_key(a.index, b.index));
  if (it != impl_->pair_states.end() && it->second.planned) {
    it->second.planned = false;
    ++impl_->plans_version;
  }
}

std::vector<PairPlan> CollisionWorld::plans() const {
  std::vector<PairPlan> out;
  for (const auto& [key, state] : impl_->pair_states) {
    if (state.planned) out.push_back(impl_->to_plan(state.plan));
  }
  sort_by_pair(out);
  return out;
}

std::vector<PairPlan> CollisionWorld::plans_since(std::uint64_t version) const {
  const auto& log = impl_->plan_log;
  auto entry = std::upper_bound(log.begin(), log.end(), version,
                                [](std::uint64_t v, const auto& e) { return v < e.first; });
  std::vector<PairPlan> out;
  for (; entry != log.end(); ++entry) {
    const auto it = impl_->pair_states.find(entry->second);
    // Skipped: pairs forgotten since, and plans made again later in the log.
    if (it != impl_->pair_states.end() && it->second.planned &&
        it->second.plan_version == entry->first) {
      out.push_back(impl_->to_plan(it->second.plan));
    }
  }
  sort_by_pair(out);
  return out;
}

std::uint64_t CollisionWorld::plans_version() const { return impl_->plans_version; }

std::string_view level_name(LevelOfDetail level) {
  switch (level) {
    case LevelOfDetail::kBox:
      return "box";
    case LevelOfDetail::kHull:
      return "hull";
    case LevelOfDetail::kExact:
      return "exact";
  }
  return "exact";
}

PartDistance CollisionWorld::distance(PartId a, PartId b, const PartDistanceRequest& request) {
  return impl_->distance(a, b, request);
}

bool CollisionWorld::within(PartId a, PartId b, Real eps, const PartDistanceRequest& request) {
  return impl_->within(a, b, eps, request);
}

void CollisionWorld::prepare() { impl_->prepare(); }

const StepResult& CollisionWorld::step() { return impl_->step(); }
const StepResult& CollisionWorld::last_step() const { return impl_->result; }

std::size_t CollisionWorld::model_bytes() const {
  std::size_t bytes = 0;
  for (const auto& [mesh, shape] : impl_->shapes) {
    if (shape->model) bytes += shape->model->info().bytes;
    if (shape->distance_model) bytes += shape->distance_model->info().bytes;
    if (shape->hull) {
      bytes += shape->hull->vertices.size() * sizeof(Vec3) +
               shape->hull->faces.size() * sizeof(TriangleIndices) +
               (shape->hull->neighbors.size() + shape->hull->neighbor_offsets.size()) *
                   sizeof(std::uint32_t);
    }
  }
  return bytes;
}

}  // namespace dovetail::collision
