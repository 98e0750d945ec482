#pragma once
/// \file collision_world.h
/// The collision pipeline: many moving parts, pruned at the object level
/// (broad phase over world boxes), then by the convex level (a separating
/// plane cached per pair), then decided exactly at the polygon level, with
/// the pairs spread over worker threads; and distances between parts, on the
/// shared hulls (warm-started GJK) or meshes (distance hierarchies).
///
/// Why: this is what a frame of the simulation asks: "what touches what
/// now, and what changed since the last frame". Each stage is cheaper than
/// the next and prunes it; each pair is tested no more precisely than it
/// needs (its level of detail), pairs nobody is interested in are never
/// tested, and hierarchies and hulls are built once per mesh, only when a
/// pair first needs them, and shared by every part using that mesh.

#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dovetail/collision/broadphase.h"
#include "dovetail/collision/capture.h"
#include "dovetail/collision/collide.h"
#include "dovetail/collision/convex.h"
#include "dovetail/collision/distance.h"
#include "dovetail/collision/mesh.h"
#include "dovetail/collision/model.h"

namespace dovetail::collision {

/// Identifies a part of a CollisionWorld: slot index and generation, so an id
/// of a removed part is recognised as stale.
struct PartId {
  std::uint32_t index = std::numeric_limits<std::uint32_t>::max();
  std::uint32_t generation = 0;
  bool valid() const { return index != std::numeric_limits<std::uint32_t>::max(); }
  friend bool operator==(const PartId&, const PartId&) = default;
  friend auto operator<=>(const PartId&, const PartId&) = default;
};

/// How precisely a pair is decided.
enum class LevelOfDetail : std::uint8_t {
  kBox,    ///< world boxes overlap
  kHull,   ///< convex hulls intersect
  kExact,  ///< triangles intersect (the polygon level)
};

/// A part to add.
struct PartDef {
  std::shared_ptr<const Mesh> mesh;  ///< shared between instances of the same mesh
  Transform X_WP;                    ///< pose of the part in the world
  bool movable = true;               ///< pairs of two fixed parts are never tested
  /// The level this part needs; a pair uses the coarser of its two parts'
  /// levels unless set_pair_level overrides it.
  LevelOfDetail level = LevelOfDetail::kExact;
  std::string name{};
};

/// How much a step reports about each pair in contact.
enum class ContactDetail : std::uint8_t {
  /// Every intersecting triangle pair (contacts for sliding, highlighting).
  kTriangles,
  /// Only that the pair touches: the polygon level stops at the first
  /// intersecting triangle pair, much cheaper for parts pushed deep into each
  /// other; one contact per pair, with kNoTriangle.
  kPairs,
};

/// Pipeline settings.
struct WorldSettings {
  /// The polygon-level hierarchy of every pair. Unset (the default): the
  /// world plans each pair itself (PairPlan): the OBB tree, the fastest exact
  /// hierarchy measured, with a SeparationFront kept per pair across steps,
  /// and the separating-plane test once it pays. Given: that hierarchy, no
  /// front, and every pair's hulls built when it is planned.
  std::optional<Method> method{};
  /// The accuracy the world must keep, in the meshes' units. 0 (the default):
  /// exact, a pair is in contact exactly when its triangles intersect. A
  /// tolerance > 0: a pair may also be reported in contact when its parts are
  /// at most this far apart (solids: a part inside another is in contact);
  /// no contact is ever missed. Each pair then takes the cheapest level that
  /// keeps it (PairPlan): the hull level for two convex parts, a cut
  /// hierarchy (CollideRequest::max_size) for others.
  Real tolerance = 0;
  BroadphaseMethod broadphase = BroadphaseMethod::kSweepAndPrune;
  bool convex_level = true;  ///< separating-plane test before the polygon level
  int threads = 1;           ///< 1 = fully serial; 0 = one per hardware thread
  ContactDetail contacts = ContactDetail::kTriangles;
  /// Failure capture (capture.h): every suspect query of step() is written
  /// here with its inputs: a pair whose separating-plane search or GJK
  /// stopped at its iteration cap, a pair with a pose that is not finite, and,
  /// with `cross_check`, a pair the two methods disagree on. nullptr: off.
  /// Not owned; must outlive the world.
  CaptureSink* capture = nullptr;
  /// Decide every pair that step() takes to the exact level a second time
  /// with this polygon-level method, and every pair the convex level
  /// separated with `method` too; a disagreement is captured (needs
  /// `capture`). Off by default: it costs a second polygon-level query per pair.
  std::optional<Method> cross_check{};
};

/// Marks a contact found at the box or hull level, which has no triangles.
inline constexpr std::uint32_t kNoTriangle = std::numeric_limits<std::uint32_t>::max();

/// One contact: at the polygon level with ContactDetail::kTriangles an
/// intersecting triangle pair (indices into each part's Mesh::triangles);
/// otherwise one entry per pair with kNoTriangle. `a` has the smaller index.
struct Contact {
  PartId a;
  PartId b;
  std::uint32_t triangle_a = kNoTriangle;
  std::uint32_t triangle_b = kNoTriangle;
  friend bool operator==(const Contact&, const Contact&) = default;
};

/// A pair of parts, `a` with the smaller index.
struct PartPair {
  PartId a;
  PartId b;
  friend bool operator==(const PartPair&, const PartPair&) = default;
  friend auto operator<=>(const PartPair&, const PartPair&) = default;
};

/// How the world decides one pair, and why: made when the pair is first
/// tested (its boxes overlap and it is of interest), from the parts' levels
/// of detail, WorldSettings::tolerance and ::method, and the parts' shapes.
///
/// Why: a scene should be modelled no more precisely than it needs. A
/// large fixed part nobody comes near never gets a hull or a hierarchy; two
/// convex parts under a tolerance are decided on their hulls; everything
/// else at the polygon level, which keeps, per pair, what the last step
/// learned (the separating plane, the triangle pair in contact, the box
/// pairs found apart). An exact pair's separating-plane test, and the hulls
/// it needs, wait until the pair's answers of "apart" have cost the polygon
/// level as much counted work as building those hulls would; the pair is
/// then planned again (docs/pipeline.md, "The separating-plane test on
/// need"). Hulls built already (prepare(), or for another pair) cost
/// nothing: the test then runs at once.
struct PairPlan {
  PartPair pair;
  LevelOfDetail level = LevelOfDetail::kExact;  ///< the level that decides the pair
  bool convex_level = false;                    ///< the separating-plane test runs first
  std::optional<Method> method{};  ///< the polygon level's hierarchy (exact level only)
  bool front = false;              ///< a SeparationFront kept across steps
  Real max_size = 0;               ///< the polygon level's tolerance cut (0: exact)
  std::string reason{};            ///< one sentence: why this plan
  friend bool operator==(const PairPlan&, const PairPlan&) = default;
};

/// Command-line and report name of a level: box, hull, exact.
std::string_view level_name(LevelOfDetail level);

/// What one step did at each level.
struct StepStats {
  std::size_t parts = 0;
  /// Overlapping world boxes (broad phase), leaving out pairs of two fixed
  /// parts unless set_interest asked for such a pair.
  std::size_t box_pairs = 0;
  std::size_t tested_pairs = 0;      ///< of those, pairs of interest
  std::size_t convex_tests = 0;      ///< separating-plane tests
  std::size_t convex_separated = 0;  ///< pairs the convex level proved apart
  std::size_t cached_planes = 0;     ///< ... with last frame's plane
  std::size_t polygon_pairs = 0;     ///< pairs decided at the polygon level
  std::size_t colliding_pairs = 0;
  CollideStats polygon;  ///< volume and triangle tests
};

/// Result of a step: deterministic, the same bits for any thread count.
struct StepResult {
  std::vector<Contact> contacts;    ///< sorted by (a, b, triangle_a, triangle_b)
  std::vector<PartPair> colliding;  ///< sorted pairs in contact
  std::vector<PartPair> began;      ///< in contact now, not at the last step
  std::vector<PartPair> ended;      ///< in contact at the last step, not now
  StepStats stats;
};

/// What CollisionWorld::distance and within measure.
struct PartDistanceRequest {
  /// The level to measure at: kHull, GJK on the two parts' convex hulls (the
  /// hulls of the convex level, warm-started from the pair's cache); kExact,
  /// the triangle meshes (DistanceModel, distance.h). Unset: the pair's level
  /// of detail (PartDef::level, set_pair_level), with kBox measured at kHull.
  /// A part without a hull (flat) is always measured exactly. Ask for kHull
  /// when both parts are convex: their hulls are then the parts themselves.
  std::optional<LevelOfDetail> level{};
  /// Allowed error of the exact distance (0: the exact minimum).
  DistanceRequest exact{};
  /// Start GJK from the pair's cache (the last call's or step's simplex).
  /// False: a cold start; the cache is updated either way.
  bool warm_start = true;
};

/// Distance between two parts, in the order they were passed (a, then b).
struct PartDistance {
  /// Smallest distance at the level used; 0 when the pair intersects there.
  /// Hull level: the distance of the convex solids (0 also when one part is
  /// inside the other). Exact level: the distance of the two surfaces, as in
  /// distance.h (a part inside a closed housing is at its distance from the
  /// walls).
  Real distance = std::numeric_limits<Real>::infinity();
  bool intersecting = false;  ///< distance is 0 (hull level: within GJK's touching band)
  Vec3 p_W = Vec3::Zero();    ///< closest point on a, world frame
  Vec3 q_W = Vec3::Zero();    ///< closest point on b, world frame
  LevelOfDetail level = LevelOfDetail::kExact;  ///< how it was decided: kHull or kExact
  /// Hull level: the closest features of a's and b's hulls (GjkResult).
  HullFeature feature_a{};
  HullFeature feature_b{};
  int gjk_iterations = 0;     ///< hull level: GJK support-query pairs
  bool warm_started = false;  ///< hull level: GJK started from the pair's cache
  /// Exact level: the closest triangle pair (indices into each part's
  /// Mesh::triangles); kNoTriangle at hull level.
  std::uint32_t triangle_a = kNoTriangle;
  std::uint32_t triangle_b = kNoTriangle;
  CollideStats stats;  ///< exact level: volume and triangle pairs tested
};

/// A set of parts and the pipeline that finds their contacts.
class CollisionWorld {
 public:
  explicit CollisionWorld(const WorldSettings& settings = {});
  ~CollisionWorld();
  CollisionWorld(const CollisionWorld&) = delete;
  CollisionWorld& operator=(const CollisionWorld&) = delete;

  /// Adds a part; throws std::invalid_argument without a mesh, MeshError
  /// for a mesh with no triangles, a non-finite vertex or an index out of
  /// range (check_mesh; meshes from make_mesh have none of these).
  PartId add_part(const PartDef& def);
  /// Removes a part; its pairs end (reported by the next step).
  void remove_part(PartId id);
  /// Sets a part's pose for the next step.
  void set_pose(PartId id, const Transform& X_WP);
  const Transform& pose(PartId id) const;
  const std::string& name(PartId id) const;
  std::size_t part_count() const;

  /// Whether the pair is tested at all (default: yes unless both are fixed).
  void set_interest(PartId a, PartId b, bool interested);
  /// Level of detail for one pair, overriding the parts' levels.
  void set_pair_level(PartId a, PartId b, LevelOfDetail level);

  /// The plan of every pair tested so far and not removed, sorted by pair.
  std::vector<PairPlan> plans() const;
  /// The plans made after plans_version() was `version` and still current,
  /// sorted by pair: what is new since then, at a cost that grows with that,
  /// not with every pair planned so far.
  std::vector<PairPlan> plans_since(std::uint64_t version) const;
  /// Changes whenever plans() would give something new (a pair planned or
  /// forgotten): cheap to poll every step.
  std::uint64_t plans_version() const;

  /// Builds now, over the task system's threads, the hulls of all parts and
  /// the polygon-level hierarchies of all parts that can reach an exact pair
  /// (by their own level, a pair level, or a flat partner), instead of on
  /// first need during step(). Optional: results are the same either way; it
  /// keeps one-off set-up cost out of the stepping loop, and with every hull
  /// built each exact pair's separating-plane test runs from its first step
  /// (PairPlan). Parts added, or levels changed, afterwards are built on
  /// first need again.
  void prepare();

  /// Runs the pipeline on the current poses.
  const StepResult& step();
  const StepResult& last_step() const;

  /// Distance between parts a and b at their current poses (see
  /// PartDistanceRequest for the level). Hull level: GJK on the shared hulls,
  /// warm-started from a GjkCache kept per pair across calls and steps. Exact
  /// level: a query on DistanceModels built once per mesh on first need and
  /// shared like the collision hierarchies. Deterministic: the same calls
  /// give the same bits for any thread count, and distance(b, a) gives
  /// distance(a, b) with the roles swapped. Not to be called concurrently
  /// with other calls on the world. Throws std::invalid_argument for an
  /// unknown or removed id, or a == b.
  PartDistance distance(PartId a, PartId b, const PartDistanceRequest& request = {});
  /// Is the distance between parts a and b at most `eps` (>= 0)? Exact
  /// level: within_tolerance (stops at the first triangle pair within eps);
  /// hull level: GJK (intersecting, or a distance of at most eps). Throws
  /// std::invalid_argument as distance() does, and for eps < 0 or NaN.
  bool within(PartId a, PartId b, Real eps, const PartDistanceRequest& request = {});

  /// Bytes of the hierarchies (collision and distance) and hulls built so far
  /// (shared ones counted once).
  std::size_t model_bytes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dovetail::collision
