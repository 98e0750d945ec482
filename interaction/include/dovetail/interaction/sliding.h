#pragma once
/// \file sliding.h
/// Rubber-band sliding: one step of a held part toward the pose the hand
/// wants for it, along the surfaces it meets instead of through them.
///
/// Why: without force feedback a user cannot feel a part touch another, so a
/// part tied rigidly to the hand would pass through everything. Tied by a
/// rubber band, it goes where the hand pulls it as far as the other parts
/// allow, and slides tangentially where they do not. Every pose this step
/// accepts is collision-free by the exact triangle test, so a sliding part
/// never penetrates; a jammed part stays behind until the band overstretches.
///
/// The state machine of one step, after ALGORITHMS.md ("Rubber-band sliding"):
///   1. try the wanted motion; where it collides, approximate the exact
///      contact pose by bisection between the last free pose and the
///      colliding one, halving on the colliding triangle pair alone and
///      confirming with one whole-part query (SlidingSettings::pair_guided);
///   2. classify the contact from the contact patches of the colliding pose
///      (face, curve: edge on face or edge on edge, point); a hit whose
///      triangle pair has the normal of a known contact only adds its point;
///   3. take the contact normal from the closest points of the last free
///      pose, a hair's breadth from the contact: the direction from the other
///      part's closest point to the sliding part's, which is the face normal
///      for a vertex or edge on a face and the common perpendicular for two
///      edges (a patch's own normal averages the faces around an edge and
///      would let a peg's rim through a hole's rim);
///   4. project the rest of the motion onto what the contacts allow: the
///      motion (v, w) about the part's centre closest to the wanted one, in
///      the metric |v|^2 + L^2 |w|^2 (L the part's size), with
///      n . (v + w x r) >= 0 at every contact (a peg in a hole keeps only the
///      motion along the hole's axis);
///   5. stop when the band is overstretched, the part is at rest, or the goal
///      is reached; otherwise go on with the projected motion, up to a
///      budget of sub-steps.

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "dovetail/collision/contacts.h"
#include "dovetail/collision/distance.h"
#include "dovetail/collision/model.h"
#include "dovetail/interaction/glove_sample.h"

namespace dovetail::interaction {

/// How a sliding part behaves.
struct SlidingSettings {
  int substeps = 4;  ///< projected moves per frame at most
  /// Whole-part collision queries toward the exact contact pose at most (14
  /// halvings take a 10 mm move to 0.6 um).
  int bisection_steps = 14;
  Real resolution_m = 1e-6;  ///< ... stopping once the bracket moves a point less than this
  /// Let the colliding triangle pair guide the search: find the contact pose
  /// by halving on that pair alone, then one whole-part query to confirm,
  /// instead of a whole-part query per halving; and when the pair's normal is
  /// already a contact's (the part pivoting into a surface it touches), add
  /// the pair's point instead of analysing the contact patches. Both ways stop
  /// at the same resolution and accept only poses the whole-part query finds
  /// collision-free; false is the plain way, kept for comparison.
  bool pair_guided = true;
  /// Keep each obstacle's separation front between the queries of a held
  /// part (SlideFronts): the same answers for less work; false for comparison.
  bool separation_fronts = true;
  Real band_limit_m = 0.05;  ///< stretch (centre to centre) past which the band breaks
  Real band_limit_deg = 20;  ///< ... or angle between held and wanted orientation
  Real rest_m = 5e-6;        ///< a sub-step moving less than this ends the frame: at rest
  /// How much more the band resists turning than moving: the metric's length
  /// is turn_stiffness * L. Near 1 a part held back at one end pivots about
  /// the contact; larger keeps the hand's orientation and slides instead.
  Real turn_stiffness = 3;
  /// A part in contact moves out to this clearance from the contact while
  /// sliding along it: room for the curvature the linearised contact misses.
  Real skin_m = 2e-6;
};

/// Another part, as the sliding part sees it.
struct SlideObstacle {
  std::shared_ptr<const collision::CollisionModel> model;    ///< exact-level model (kObb)
  std::shared_ptr<const collision::DistanceModel> distance;  ///< of the same mesh
  Transform X_WO;                                            ///< its pose in the world
  std::uint32_t id = 0;                                      ///< caller's index, in the contacts
};

/// One contact of the sliding part in the world.
struct SlideContact {
  std::uint32_t obstacle = 0;  ///< SlideObstacle::id
  Vec3 p_W = Vec3::Zero();     ///< contact point
  Vec3 n_W = Vec3::UnitY();    ///< unit normal from the obstacle toward the part
  collision::ContactKind kind = collision::ContactKind::kPoint;
  /// How far the part has moved away from the contact along its normal since
  /// it was found; past kContactExpiry the contact no longer constrains.
  Real separation = 0;
  /// Which of the moving bodies touches: 0 the sliding part, i its
  /// attachment i - 1 (SlideRequest::attached).
  std::uint32_t body = 0;
};

/// A part attached to the sliding part: it moves with it, rigidly, and is kept
/// out of the obstacles as the sliding part is (a collar fixed on a peg stops
/// on the block's face where the peg alone would go on into the hole).
struct SlideAttachment {
  std::shared_ptr<const collision::CollisionModel> model;  ///< exact-level model (kObb)
  Transform X_PA{};                                        ///< its pose in the sliding part's frame
};

/// A contact the part has moved this far away from is forgotten (metres).
inline constexpr Real kContactExpiry = 1e-4;

/// A pose of the part that a step proved collision-free, and against what:
/// a step starting from that very pose among the same obstacle models at the
/// very same poses (bit for bit) need not prove it again.
struct SlideProof {
  std::shared_ptr<const collision::CollisionModel> part;  ///< null: nothing proved
  Transform X_WP{};
  std::vector<SlideAttachment> attached;  ///< with these attached, at these poses
  std::vector<SlideObstacle> obstacles;   ///< their models and poses (ids do not matter)
};

/// What the steps of one sliding part keep of each obstacle between their
/// queries: the collision layer's SeparationFront of the last query against
/// it that visited the whole front.
///
/// Why: a part pushed along a wall is queried many times a frame at poses
/// micrometres apart, and each query that finds it free descends again to
/// the same thousands of box pairs along the wall. From the front, box pairs
/// still apart by more than the part moved are skipped without a test. The
/// queries give the same answers with or without it.
class SlideFronts {
 public:
  /// The front of queries of `obstacle` against `part`, empty the first time
  /// (obstacles of one model share it: exact all the same, less to gain).
  collision::SeparationFront& of(const std::shared_ptr<const collision::CollisionModel>& obstacle,
                                 const std::shared_ptr<const collision::CollisionModel>& part);
  /// Forgets the fronts of every obstacle not in `obstacles` and of every part
  /// other than `part` and its attachments.
  void keep_only(std::span<const SlideObstacle> obstacles,
                 const std::shared_ptr<const collision::CollisionModel>& part,
                 std::span<const SlideAttachment> attached = {});
  void clear() { fronts_.clear(); }
  std::size_t size() const { return fronts_.size(); }

 private:
  struct Kept {
    // Held, so that no other model can take their addresses while the front lives.
    std::shared_ptr<const collision::CollisionModel> obstacle, part;
    collision::SeparationFront front;
  };
  std::vector<Kept> fronts_;
};

/// What one step wants.
struct SlideRequest {
  std::shared_ptr<const collision::CollisionModel> part;          ///< the sliding part (kObb)
  std::shared_ptr<const collision::DistanceModel> part_distance;  ///< of the same mesh
  /// The parts attached to it (not among the obstacles): they move with it
  /// and collide as it does. Its centre and size are then those of the whole.
  std::span<const SlideAttachment> attached;
  Vec3 p_PC = Vec3::Zero();  ///< its centre in its own frame (the point it turns about)
  /// Its size L in metres: weights turning against moving, and no point of it
  /// (or of what is attached) is further than L from the centre.
  Real size = 0.05;
  Transform X_WP{};         ///< where it is: collision-free
  Transform X_WP_target{};  ///< where the hand wants it
  std::span<const SlideObstacle> obstacles;
  /// The contacts of the last step (SlideResult::contacts): the part is
  /// still against them, so they constrain the first move of this step and
  /// a part resting in a corner costs no search (contact coherence).
  std::span<const SlideContact> previous_contacts;
  /// The last step's proof (SlideResult::proof). When it covers X_WP and
  /// every obstacle, the step skips its first query (is the starting pose
  /// free?): a part resting in contact then costs no query at all.
  const SlideProof* start_proof = nullptr;
  /// The part's fronts, read and rewritten by the step's queries (optional:
  /// null costs more work, never another answer).
  SlideFronts* fronts = nullptr;
};

/// How the step ended.
enum class SlideStatus : std::uint8_t {
  kReached,        ///< at the target, no contact on the way
  kSliding,        ///< held back by contacts, moved as far as they allow
  kAtRest,         ///< held back and no further motion possible this frame
  kOverstretched,  ///< the target is past the band's limit: the part stays where it is
  kBlocked,        ///< the starting pose already collides: nothing moved
};

/// Outcome of a step.
struct SlideResult {
  SlideStatus status = SlideStatus::kReached;
  Transform X_WP{};  ///< the new pose (collision-free unless kBlocked)
  /// The contacts that constrained the step: the previous step's, then those
  /// met on the way, without repeats (same obstacle, point within 0.1 mm,
  /// normal within 1 degree), at most kMaxSlideContacts, the newest kept.
  std::vector<SlideContact> contacts;
  int new_contacts = 0;  ///< of those, met in this step
  int substeps = 0;
  int collision_queries = 0;
  Real stretch_m = 0;    ///< band stretch at the end: target centre to part centre
  Real stretch_deg = 0;  ///< and angle
  /// The final pose, proved collision-free against the request's obstacles
  /// (empty when kOverstretched or kBlocked): the next step's start_proof.
  SlideProof proof;
};

/// Most contacts a step keeps.
inline constexpr std::size_t kMaxSlideContacts = 48;

/// One step of a held part toward its target (see the file comment).
SlideResult slide(const SlideRequest& request, const SlidingSettings& settings = {});

/// Whether the part at X_WP collides with any obstacle (exact first-hit tests).
bool collides(const collision::CollisionModel& part, const Transform& X_WP,
              std::span<const SlideObstacle> obstacles, int* queries = nullptr);

/// A motion of a part: translation v of its centre (metres) over the turn w about it
/// (rotation vector, radians).
using Motion = Eigen::Matrix<Real, 6, 1>;

/// The motion closest to `wanted` in the metric |v|^2 + length^2 |w|^2 with
/// a_i . x >= b_i for every i, exactly (up to rounding): Goldfarb and Idnani's
/// dual active-set method, deterministic. Nothing when no motion meets them all
/// (or, not expected, when it does not settle within 8 steps a constraint).
std::optional<Motion> project_motion(const Motion& wanted, std::span<const Motion> a,
                                     std::span<const Real> b, Real length);

/// The rotation vector (axis times angle, radians) of R, and its inverse.
Vec3 rotation_vector(const Mat3& R);
Mat3 rotation_from_vector(const Vec3& w);

}  // namespace dovetail::interaction
