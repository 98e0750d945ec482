#include "pose_queries.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>

#include "cli.h"
#include "dovetail/collision/task_system.h"

namespace dovetail::cli {

namespace {

void add_stats(collision::CollideStats& total, const collision::CollideStats& one) {
  total.volume_tests += one.volume_tests;
  total.triangle_tests += one.triangle_tests;
}

// One pose's share of the ContactQueryResult counters.
struct ContactCounts {
  std::uint64_t colliding = 0;
  std::uint64_t pairs = 0;
  std::uint64_t patches = 0;
  std::uint64_t face = 0;
  std::uint64_t curve = 0;
  std::uint64_t point = 0;
  std::uint64_t penetrating = 0;
  collision::CollideStats stats;
};

std::string json_vec3(const collision::Vec3& v) {
  return json_array({json_number(v.x()), json_number(v.y()), json_number(v.z())});
}

}  // namespace

double for_each_pose(std::size_t n, int threads, const std::function<void(std::size_t)>& one) {
  const auto start = std::chrono::steady_clock::now();
  if (threads == 1 || n < 2) {
    for (std::size_t i = 0; i < n; ++i) one(i);
  } else {
    // Threads come from the collision layer's task system, as everywhere
    // else; a grain of 1: a pose's query may cost anything from a volume
    // test to a deep traversal.
    const std::unique_ptr<collision::TaskSystem> tasks = collision::make_task_system(threads);
    tasks->parallel_for(n, 1, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i != end; ++i) one(i);
    });
  }
  return ms_since(start);
}

PoseQueryResult run_pose_queries(const collision::CollisionModel& a,
                                 const collision::CollisionModel& b,
                                 std::span<const collision::Transform> poses,
                                 const collision::CollideRequest& request, int threads) {
  const std::size_t n = poses.size();
  PoseQueryResult result;
  result.colliding.assign(n, 0);
  std::vector<collision::CollideStats> stats(n);
  std::vector<std::uint64_t> pairs(n, 0);

  result.wall_ms = for_each_pose(n, threads, [&](std::size_t i) {
    const collision::CollideResult r = a.collide(b, poses[i], request);
    result.colliding[i] = r.colliding ? 1 : 0;
    stats[i] = r.stats;
    pairs[i] = r.pairs.size();
  });

  // Summed in pose order, so the totals do not depend on scheduling.
  for (std::size_t i = 0; i < n; ++i) {
    result.colliding_count += result.colliding[i];
    result.pairs_total += pairs[i];
    add_stats(result.stats, stats[i]);
  }
  return result;
}

DistanceQueryResult run_distance_queries(const DistanceInputs& inputs,
                                         std::span<const collision::Transform> poses, int threads) {
  const std::size_t n = poses.size();
  const bool brute = inputs.model_a == nullptr || inputs.model_b == nullptr;
  DistanceQueryResult result;
  result.distances.assign(n, 0.0);
  std::vector<collision::CollideStats> stats(n);

  result.wall_ms = for_each_pose(n, threads, [&](std::size_t i) {
    const collision::DistanceResult r =
        brute ? collision::distance_brute(*inputs.mesh_a, *inputs.mesh_b, poses[i])
              : collision::distance(*inputs.model_a, *inputs.model_b, poses[i]);
    result.distances[i] = r.distance;
    stats[i] = r.stats;
  });

  result.distance_min = std::numeric_limits<double>::infinity();
  result.distance_max = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    const double d = result.distances[i];
    if (d == 0) ++result.colliding_count;
    result.distance_min = std::min(result.distance_min, d);
    result.distance_max = std::max(result.distance_max, d);
    add_stats(result.stats, stats[i]);
  }
  return result;
}

ToleranceQueryResult run_tolerance_queries(const DistanceInputs& inputs,
                                           std::span<const collision::Transform> poses,
                                           double tolerance, int threads) {
  const std::size_t n = poses.size();
  const bool brute = inputs.model_a == nullptr || inputs.model_b == nullptr;
  ToleranceQueryResult result;
  result.within.assign(n, 0);
  std::vector<collision::CollideStats> stats(n);

  result.wall_ms = for_each_pose(n, threads, [&](std::size_t i) {
    const collision::ToleranceResult r =
        brute
            ? collision::within_tolerance_brute(*inputs.mesh_a, *inputs.mesh_b, poses[i], tolerance)
            : collision::within_tolerance(*inputs.model_a, *inputs.model_b, poses[i], tolerance);
    result.within[i] = r.within ? 1 : 0;
    stats[i] = r.stats;
  });

  for (std::size_t i = 0; i < n; ++i) {
    result.within_count += result.within[i];
    add_stats(result.stats, stats[i]);
  }
  return result;
}

ContactQueryResult run_contact_queries(const collision::CollisionModel& a,
                                       const collision::CollisionModel& b,
                                       std::span<const collision::Transform> poses,
                                       const collision::ContactRequest& request, int threads) {
  const std::size_t n = poses.size();
  ContactQueryResult result;
  result.lines.assign(n, std::string());
  std::vector<ContactCounts> counts(n);

  collision::CollideRequest all_pairs;
  all_pairs.all_pairs = true;
  result.wall_ms = for_each_pose(n, threads, [&](std::size_t i) {
    const collision::CollideResult r = a.collide(b, poses[i], all_pairs);
    const std::vector<collision::ContactPatch> patches =
        collision::compute_contacts(a.mesh(), b.mesh(), poses[i], r.pairs, request);
    result.lines[i] = contact_line_json(i, r.colliding, patches);
    ContactCounts& c = counts[i];
    c.colliding = r.colliding ? 1 : 0;
    c.pairs = r.pairs.size();
    c.patches = patches.size();
    for (const collision::ContactPatch& patch : patches) {
      switch (patch.kind) {
        case collision::ContactKind::kFace:
          ++c.face;
          break;
        case collision::ContactKind::kCurve:
          ++c.curve;
          break;
        case collision::ContactKind::kPoint:
          ++c.point;
          break;
      }
      if (patch.penetrating) ++c.penetrating;
    }
    c.stats = r.stats;
  });

  // Summed in pose order, so the totals do not depend on scheduling.
  for (const ContactCounts& c : counts) {
    result.colliding_count += c.colliding;
    result.pairs_total += c.pairs;
    result.patches_total += c.patches;
    result.face_patches += c.face;
    result.curve_patches += c.curve;
    result.point_patches += c.point;
    result.penetrating_patches += c.penetrating;
    add_stats(result.stats, c.stats);
  }
  return result;
}

std::string format_distance(double distance) {
  char buffer[40];
  const int length = std::snprintf(buffer, sizeof buffer, "%.17g", distance);
  return std::string(buffer, static_cast<std::size_t>(length));
}

std::string contact_line_json(std::size_t pose, bool colliding,
                              std::span<const collision::ContactPatch> patches) {
  std::vector<std::string> items;
  items.reserve(patches.size());
  for (const collision::ContactPatch& patch : patches) {
    JsonLine json;
    json.add("kind", collision::contact_kind_name(patch.kind))
        .add_raw("point", json_vec3(patch.point))
        .add_raw("normal", json_vec3(patch.normal))
        .add("area", patch.area)
        .add("length", patch.length)
        .add("depth", patch.depth)
        .add("penetrating", patch.penetrating)
        .add("pairs", std::uint64_t{patch.pairs.size()});
    items.push_back(json.str());
  }
  JsonLine line;
  line.add("pose", std::uint64_t{pose})
      .add("colliding", colliding)
      .add_raw("patches", json_array(items));
  return line.str();
}

}  // namespace dovetail::cli
