#pragma once
/// \file harness.h
/// The two protocols for a pair of objects, shared by `dovetail bench` and
/// the bench programs (which add the peers that are installed):
///
/// * Zachmann's: both objects scaled into [-1, 1]^3; at each distance of
///   their centres the moving one tumbles through a full rotation
///   (collision::tumble_poses); per distance the mean and maximum query time
///   and the traversal counters, apart for colliding and free queries.
/// * Trenkel, Weller and Zachmann's contact-distance poses
///   (collision::contact_distance_poses): per contender the median over runs
///   of the mean query time, overall and per gap, and its false positives and
///   false negatives against the exact answer.
///
/// A contender is anything that answers "do A and B collide at X_AB?": every
/// hierarchy of the polygon level, the approximations of the convex and
/// polygon levels, or a peer library.

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "dovetail/collision/mesh.h"
#include "dovetail/collision/model.h"
#include "dovetail/collision/pose_sampling.h"

namespace dovetail::bench {

using MeshPtr = std::shared_ptr<const collision::Mesh>;

/// One way of answering the yes/no query of B at X_AB against A.
struct Contender {
  std::string name;    ///< "obb", "obb depth 24", "hull", "fcl-obbrss", ...
  std::string family;  ///< exact, volume, depth-obb, depth-dop18, depth-aabb, hull, plane, peer
  /// Held to the exact answer (a hierarchy, an exact peer); otherwise an
  /// approximation whose wrong verdicts are false positives and negatives.
  bool exact = true;
  /// The query; adds the work it did to the counters (left alone by peers).
  std::function<bool(const collision::Transform& X_AB, collision::CollideStats& work)> query;
  double build_ms = 0;                       ///< both objects' structures
  double bytes_per_triangle = std::nan("");  ///< of both; NaN when not known
};

/// `mesh` moved and scaled uniformly so that its bounding box is centred in
/// [-1, 1]^3 and touches it; an empty mesh is returned as it is.
collision::Mesh normalized(collision::Mesh mesh);

/// Every hierarchy of the polygon level (brute force excluded), exact; `b`
/// may be `a`, and then one structure serves both.
std::vector<Contender> exact_contenders(const MeshPtr& a, const MeshPtr& b);

/// The approximate settings: each hierarchy's root volume alone (aabb: the
/// bounding box; not the Boxtree, whose traversal has no depth cut), the
/// OBB, 18-DOP and AABB trees cut at depths 2 to 48 (time-critical
/// detection), the convex hulls (GJK), and the separating-plane search capped
/// at 1 to 64 iterations (giving up counts as colliding).
std::vector<Contender> approximate_contenders(const MeshPtr& a, const MeshPtr& b);

/// The convex level as the pipeline runs it: the hulls' separating-plane
/// test with a cache kept from query to query (conservative: giving up counts
/// as colliding).
Contender hull_plane_contender(const MeshPtr& a, const MeshPtr& b);

/// What `dovetail bench --protocol tumble` and tumble_bench run: every
/// hierarchy, then hull_plane_contender (the peers come after).
std::vector<Contender> tumble_contenders(const MeshPtr& a, const MeshPtr& b);

/// What `dovetail bench --protocol poses` and accuracy_bench run: every
/// hierarchy, then every approximate setting (the peers come after).
std::vector<Contender> contact_pose_contenders(const MeshPtr& a, const MeshPtr& b);

/// The contact-distance poses of B against A (`b` may be `a`), the bisection
/// run on OBB trees; every exact method gives the same list (the bisection
/// only asks exact yes/no questions), the one `dovetail poses` writes.
std::vector<collision::SampledPose> contact_poses(const MeshPtr& a, const MeshPtr& b,
                                                  const collision::ContactPoseSettings& settings);

/// Called with (done, total) while a protocol runs; may be empty.
using Progress = std::function<void(std::size_t done, std::size_t total)>;

// --- Zachmann's protocol ----------------------------------------------------

/// One contender at one distance.
struct TumbleCell {
  int colliding = 0, free = 0;
  double sum_us_colliding = 0, max_us_colliding = 0;
  double sum_us_free = 0, max_us_free = 0;
  double volume_tests = 0, triangle_tests = 0;  ///< summed over the cell's queries
};

/// The cells of all distances together (sums, and maxima of the maxima).
TumbleCell total(const std::vector<TumbleCell>& cells);

struct TumbleResult {
  std::vector<collision::Real> distances;
  int turns = 0;
  std::vector<std::vector<TumbleCell>> cells;  ///< [contender][distance]
  /// Per contender: verdicts unlike the first exact contender's (0 for the
  /// reference itself and for approximations, which are not held to it).
  std::vector<std::size_t> disagreements;
  std::size_t reference = 0;  ///< index of the contender whose verdicts are the reference
};

/// Runs every contender on every pose of the tumble, contenders interleaved
/// pose by pose, each query timed alone. Needs at least one exact contender.
TumbleResult run_tumble(const std::vector<Contender>& contenders,
                        const collision::TumbleSettings& settings, const Progress& progress = {});

/// Mean µs per query over all distances, colliding and free apart, with the
/// maxima, one row per contender; then the disagreements.
void print_tumble(std::FILE* out, const std::vector<Contender>& contenders,
                  const TumbleResult& result);

/// The table behind the chart, one line per contender and distance:
/// `method distance colliding free mean_us mean_us_colliding max_us_colliding
/// mean_us_free max_us_free volume_tests triangle_tests` (spaces in names
/// become underscores). False when `path` cannot be written.
bool write_tumble_table(const std::string& path, const std::vector<Contender>& contenders,
                        const TumbleResult& result);

// --- Contact-distance poses -------------------------------------------------

/// One contender over the runs.
struct PoseRow {
  double us_per_query = 0;                      ///< median over runs of the mean
  std::vector<double> us_per_gap;               ///< median over runs, per gap of the settings
  std::size_t false_positives = 0;              ///< colliding where the exact answer is free
  std::size_t false_negatives = 0;              ///< free where the exact answer is colliding
  double volume_tests = 0, triangle_tests = 0;  ///< per query
};

struct PoseResult {
  std::vector<collision::Real> gaps;
  std::size_t poses = 0, colliding = 0;  ///< colliding: by the exact answer
  std::size_t reference = 0;             ///< the contender whose verdicts are the exact answer
  double best_exact_us = 0;              ///< the fastest exact contender's median
  std::vector<PoseRow> rows;             ///< per contender
  int runs = 0;
};

/// Verdicts once (the first exact contender's are the exact answer), then
/// `runs` timed runs, contenders interleaved within each run and each gap
/// timed as a block. Needs at least one exact contender and runs >= 1.
PoseResult run_contact_poses(const std::vector<Contender>& contenders,
                             const std::vector<collision::SampledPose>& poses,
                             const std::vector<collision::Real>& gaps, int runs,
                             const Progress& progress = {});

/// One row per contender: µs per query, × the best exact, false positives
/// and negatives in % of all poses, the work per query, then per gap.
void print_contact_poses(std::FILE* out, const std::vector<Contender>& contenders,
                         const PoseResult& result);

/// The table behind the time-against-error chart, one line per contender:
/// `family setting us_per_query x_best_exact fp_percent fn_percent`. False
/// when `path` cannot be written.
bool write_contact_pose_table(const std::string& path, const std::vector<Contender>& contenders,
                              const PoseResult& result);

/// Dovetail's hierarchies (family "exact", not the peers) that did not give
/// the exact answer everywhere: their names, comma-separated; empty when all
/// agree.
std::string exact_contenders_wrong(const std::vector<Contender>& contenders,
                                   const PoseResult& result);

}  // namespace dovetail::bench
