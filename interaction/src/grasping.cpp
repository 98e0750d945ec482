#include "dovetail/interaction/grasping.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <numbers>

#include "dovetail/collision/distance.h"
#include "dovetail/engine/scene.h"
#include "dovetail/interaction/overlap.h"

namespace dovetail::interaction {

namespace {

using engine::EventKind;
using engine::PartId;

constexpr Real kDegree = std::numbers::pi / 180;
/// A part drawn onto a mate's axis stays drawn until it is this many times
/// the mate's tolerances away.
constexpr Real kGuideHysteresis = 3;

/// The joints a digit closes with, and the segments that move with them.
struct DigitJoints {
  std::vector<std::size_t> joints;
  std::vector<std::size_t> flexion;  ///< of those, the ones whose sum is the digit's flexion
  std::vector<Segment> segments;
};

DigitJoints digit_joints(std::size_t digit) {
  if (digit == 0) {
    return {{0, 1, 2, 3},
            {0, 1, 2},
            {Segment::kThumbMetacarpal, Segment::kThumbProximal, Segment::kThumbDistal}};
  }
  const std::size_t j = static_cast<std::size_t>(Joint::kIndexMcp) + 3 * (digit - 1);
  const auto s = static_cast<std::size_t>(Segment::kIndexProximal) + 3 * (digit - 1);
  return {{j, j + 1, j + 2},
          {j, j + 1, j + 2},
          {static_cast<Segment>(s), static_cast<Segment>(s + 1), static_cast<Segment>(s + 2)}};
}

/// A digit's joints from the palm outward, those at one knuckle together:
/// the thumb's carpometacarpal joint turns by roll and abduction.
std::vector<std::vector<std::size_t>> joint_stages(std::size_t digit) {
  if (digit == 0) {
    return {
        {static_cast<std::size_t>(Joint::kThumbRoll), static_cast<std::size_t>(Joint::kThumbAbd)},
        {static_cast<std::size_t>(Joint::kThumbMcp)},
        {static_cast<std::size_t>(Joint::kThumbIp)}};
  }
  const std::size_t j = static_cast<std::size_t>(Joint::kIndexMcp) + 3 * (digit - 1);
  return {{j}, {j + 1}, {j + 2}};
}

Real flexion(const JointAngles& q, const DigitJoints& d) {
  Real sum = 0;
  for (std::size_t j : d.flexion) sum += q[j];
  return sum;
}

std::optional<std::size_t> digit_of(Segment s) {
  const auto i = static_cast<std::size_t>(s);
  if (i == 0) return std::nullopt;
  if (i <= 3) return 0;
  return 1 + (i - 4) / 3;
}

bool overlap(const collision::Bounds& a, const collision::Bounds& b, Real margin) {
  return (a.min.array() - margin <= b.max.array()).all() &&
         (b.min.array() - margin <= a.max.array()).all();
}

/// Do contacts i and j oppose: the line between them inside both friction cones?
bool oppose(const Vec3& p_i, const Vec3& n_i, const Vec3& p_j, const Vec3& n_j, Real cos_cone) {
  const Vec3 d = p_j - p_i;
  const Real length = d.norm();
  if (!(length > 0)) return false;
  return (-n_i).dot(d) >= cos_cone * length && (-n_j).dot(-d) >= cos_cone * length;
}

}  // namespace

std::string_view grasp_type_name(GraspType type) {
  switch (type) {
    case GraspType::kPrecision:
      return "precision";
    case GraspType::kTripod:
      return "tripod";
    case GraspType::kPower:
      return "power";
  }
  return "unknown";
}

/// Models of the meshes met, built once each and shared.
struct Grasping::Models {
  /// The OBB trees (sliding's and the snap's), and how deep parts overlap.
  OverlapGauge overlap;
  std::map<const collision::Mesh*, std::shared_ptr<const collision::DistanceModel>> distance;
  std::map<const collision::Mesh*, collision::Bounds> bounds;

  const std::shared_ptr<const collision::CollisionModel>& collision_model(
      const std::shared_ptr<const collision::Mesh>& mesh) {
    return overlap.model(mesh);
  }
  const std::shared_ptr<const collision::DistanceModel>& distance_shared(
      const std::shared_ptr<const collision::Mesh>& mesh) {
    auto& m = distance[mesh.get()];
    if (!m) m = collision::build_distance_model(mesh);
    return m;
  }
  const collision::DistanceModel& distance_model(
      const std::shared_ptr<const collision::Mesh>& mesh) {
    return *distance_shared(mesh);
  }
  const collision::Bounds& mesh_bounds(const std::shared_ptr<const collision::Mesh>& mesh) {
    auto it = bounds.find(mesh.get());
    if (it == bounds.end()) it = bounds.emplace(mesh.get(), collision::mesh_bounds(*mesh)).first;
    return it->second;
  }
};

Grasping::Grasping(engine::Simulation& simulation, Hand& hand)
    : Grasping(simulation, hand, InteractionSettings{}) {}

Grasping::Grasping(engine::Simulation& simulation, Hand& hand, const InteractionSettings& settings)
    : simulation_(&simulation),
      hand_(&hand),
      settings_(settings),
      models_(std::make_unique<Models>()) {
  using Clock = std::chrono::steady_clock;
  hand.set_finger_limiter([this](const HandModel& model, const Transform& X_WH,
                                 const JointAngles& previous, JointAngles& angles) {
    const auto start = Clock::now();
    limit_fingers(model, X_WH, previous, angles);
    stats_.frame_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  });
  simulation.add_frame_hook([this](engine::Simulation& sim, std::uint64_t frame, double t) {
    const auto start = Clock::now();
    update(sim, frame, t);
    stats_.frame_ms += std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  });
  simulation.add_event_filter([this](engine::Simulation&, std::vector<engine::Event>& events) {
    events.insert(events.end(), pending_.begin(), pending_.end());
    pending_.clear();
  });
}

Grasping::~Grasping() = default;

void Grasping::add_mate(const Mate& mate) {
  simulation_->scene().get(mate.part);
  simulation_->scene().get(mate.other);
  mates_.push_back(mate);
}

void Grasping::hold(const std::string& part, GraspType type) {
  const engine::Scene& scene = simulation_->scene();
  const PartId handle = scene.get(part);
  if (!scene.collision_mesh(handle)) {
    throw engine::SceneError("grasping: part '" + part + "' has no collision mesh to hold");
  }
  const PartId root = carried_root(scene, handle);
  if (!scene.movable(root)) {
    throw engine::SceneError("grasping: part '" + part + "' is attached to '" + scene.name(root) +
                             "', which is fixed, so it cannot be held");
  }
  held_ = part;
  carried_ = scene.name(root);
  type_ = type;
  last_slide_ = {};
  fronts_.clear();
  contact_parts_.clear();
  contact_bodies_.clear();
  sliding_pairs_.clear();
  X_HO_ = engine::compose(hand_->X_WH().inverse(), scene.world_pose(root));
  for (std::size_t d = 0; d < kDigitCount; ++d) {
    flexion_at_grasp_[d] = flexion(hand_->glove_angles(), digit_joints(d));
    settle_floor_[d] = flexion_at_grasp_[d] - settings_.grasp.release_open_deg / 2;
    peak_flexion_[d] = flexion_at_grasp_[d];
    release_opening_[d] = settings_.grasp.release_open_deg;
    grasping_digit_[d] = type == GraspType::kPower || d <= (type == GraspType::kTripod ? 2U : 1U);
  }
  opened_since_ = -1;
  grasped_at_ = simulation_->time();
}

PartId Grasping::carried_root(const engine::Scene& scene, PartId part) {
  PartId root = part;
  for (PartId p = scene.parent(part); p.valid() && !scene.has_tag(p, "hand"); p = scene.parent(p)) {
    root = p;
  }
  return root;
}

Transform Grasping::pose_in(const engine::Scene& scene, PartId root, PartId part) {
  if (part == root) return Transform{};
  Transform X_RP = scene.local_pose(part);
  for (PartId p = scene.parent(part); p != root; p = scene.parent(p)) {
    X_RP = engine::compose(scene.local_pose(p), X_RP);
  }
  return X_RP;
}

std::optional<std::pair<PartId, PartId>> Grasping::outward_mate(const engine::Scene& scene,
                                                                const Mate& mate, PartId root) {
  const PartId p = scene.find(mate.part), o = scene.find(mate.other);
  if (!p.valid() || !o.valid() || !scene.descends_from(p, root) || scene.descends_from(o, root))
    return std::nullopt;
  return std::pair{p, o};
}

Transform Grasping::root_pose_for(const engine::Scene& scene, PartId root, PartId part,
                                  const Transform& X_WP) {
  return part == root ? X_WP : engine::compose(X_WP, pose_in(scene, root, part).inverse());
}

Transform Grasping::carried_pose(const engine::Scene& scene, PartId part,
                                 const Transform& X_WH) const {
  if (!carried_) return scene.world_pose(part);
  const PartId root = scene.get(*carried_);
  if (part == root) return engine::compose(X_WH, X_HO_);
  if (!scene.descends_from(part, root)) return scene.world_pose(part);
  return engine::compose(engine::compose(X_WH, X_HO_), pose_in(scene, root, part));
}

std::vector<PartId> Grasping::candidates(const engine::Scene& scene, const Transform& X_WH,
                                         Real reach) const {
  std::vector<PartId> out;
  const collision::Bounds around{X_WH.t - Vec3::Constant(reach), X_WH.t + Vec3::Constant(reach)};
  for (const PartId part : scene.parts()) {
    const auto& mesh = scene.collision_mesh(part);
    if (!mesh || scene.has_tag(part, "hand")) continue;
    const Transform X_WP = carried_pose(scene, part, X_WH);
    if (overlap(collision::transformed_bounds(models_->mesh_bounds(mesh), X_WP), around, 0))
      out.push_back(part);
  }
  return out;
}

void Grasping::limit_fingers(const HandModel& model, const Transform& X_WH,
                             const JointAngles& previous, JointAngles& angles) {
  const engine::Scene& scene = simulation_->scene();
  const std::vector<PartId> parts = candidates(scene, X_WH, 1.2 * model.hand_length());
  if (parts.empty()) return;
  std::vector<SlideObstacle> obstacles;
  for (const PartId part : parts) {
    obstacles.push_back({models_->collision_model(scene.collision_mesh(part)), nullptr,
                         carried_pose(scene, part, X_WH), part.index});
  }
  auto posed_digit_collides = [&](const HandPose& pose, const DigitJoints& d,
                                  std::span<const SlideObstacle> against) {
    for (const Segment s : d.segments) {
      const auto& proxy = models_->collision_model(model.proxy(s));
      const Transform X_WS = engine::compose(X_WH, pose.X_HS[static_cast<std::size_t>(s)]);
      int queries = 0;
      const bool hit = collides(*proxy, X_WS, against, &queries);
      stats_.finger_queries += static_cast<std::uint64_t>(queries);
      if (hit) return true;
    }
    return false;
  };
  auto digit_collides = [&](const JointAngles& q, const DigitJoints& d,
                            std::span<const SlideObstacle> against) {
    return posed_digit_collides(model.forward_kinematics(q), d, against);
  };
  const JointAngles target = angles;
  std::vector<SlideObstacle> others;
  for (std::size_t digit = 0; digit < kDigitCount; ++digit) {
    const DigitJoints d = digit_joints(digit);
    if (flexion(target, d) <= flexion(previous, d)) continue;  // opening: nothing to stop
    std::span<const SlideObstacle> against = obstacles;
    if (!digit_collides(angles, d, against)) continue;
    // Closing into a part: from the last free posture toward the glove's, to
    // the first contact. Then, as a finger curls round a handle once its
    // base is stopped, the joints beyond the first close on together toward
    // the glove's angles, to their own first contact, and so on outward: a
    // digit stopped whole at its first contact leaves its tip in the air.
    JointAngles q = angles;
    for (std::size_t j : d.joints) q[j] = previous[j];
    if (digit_collides(q, d, against)) {
      // Already in a part where it was (the tracker put the hand there). In
      // a fixed part (a finger inside a table) it closes no further, through
      // the part or round it, until the hand moves it free; it may still
      // open. In a movable part (a palm pressed a little into a handle) it
      // closes through that part, and stops at the others.
      others.clear();
      bool in_fixed = false;
      const HandPose where_it_was = model.forward_kinematics(q);
      for (std::size_t i = 0; i < obstacles.size(); ++i) {
        if (!posed_digit_collides(where_it_was, d, std::span(&obstacles[i], 1))) {
          others.push_back(obstacles[i]);
        } else if (!scene.movable(parts[i])) {
          in_fixed = true;
        }
      }
      if (in_fixed) {
        for (std::size_t j : d.joints) angles[j] = previous[j];
        continue;
      }
      against = others;
      if (!digit_collides(angles, d, against)) continue;  // the glove's angles
    }
    const std::vector<std::vector<std::size_t>> stages = joint_stages(digit);
    for (std::size_t stage = 0; stage < stages.size(); ++stage) {
      std::vector<std::size_t> moving;
      for (std::size_t k = stage; k < stages.size(); ++k) {
        moving.insert(moving.end(), stages[k].begin(), stages[k].end());
      }
      const JointAngles from = q;
      const auto at = [&](Real f) {
        for (std::size_t j : moving) q[j] = from[j] + f * (target[j] - from[j]);
      };
      at(1);
      if (!digit_collides(q, d, against)) break;  // the rest reach the glove's angles
      Real free = 0, hit = 1;
      for (int i = 0; i < settings_.grasp.finger_bisection_steps; ++i) {
        const Real mid = (free + hit) / 2;
        at(mid);
        (digit_collides(q, d, against) ? hit : free) = mid;
      }
      at(free);
    }
    for (std::size_t j : d.joints) angles[j] = q[j];
  }
}

std::vector<GraspContact> Grasping::touches(const engine::Scene& scene, PartId part) {
  std::vector<GraspContact> out;
  const auto& mesh = scene.collision_mesh(part);
  const collision::DistanceModel& part_model = models_->distance_model(mesh);
  const Transform X_WP = scene.world_pose(part);
  const Transform X_PW = X_WP.inverse();
  const HandModel& model = hand_->model();
  const HandPose& pose = hand_->pose();
  const collision::Bounds part_box =
      collision::transformed_bounds(models_->mesh_bounds(mesh), X_WP);
  for (std::size_t i = 0; i < kSegmentCount; ++i) {
    const auto segment = static_cast<Segment>(i);
    const Transform X_WS = engine::compose(hand_->X_WH(), pose.X_HS[i]);
    const auto& proxy = model.proxy(segment);
    const Real gap = segment == Segment::kPalm
                         ? std::max(settings_.grasp.palm_gap, settings_.grasp.contact_gap)
                         : settings_.grasp.contact_gap;
    if (!overlap(collision::transformed_bounds(models_->mesh_bounds(proxy), X_WS), part_box, gap)) {
      continue;
    }
    // A contact of the segment through `shape` (its proxy, or a strip of
    // the palm), with the part's face normal at the witness point.
    const auto touch = [&](const std::shared_ptr<const collision::Mesh>& shape) {
      ++stats_.contact_queries;
      const collision::ToleranceResult r = collision::within_tolerance(
          part_model, models_->distance_model(shape), engine::compose(X_PW, X_WS), gap);
      if (!r.within) return false;
      const auto& tri = mesh->triangles[r.triangle_a];
      const Vec3 n_P = (mesh->vertices[tri[1]] - mesh->vertices[tri[0]])
                           .cross(mesh->vertices[tri[2]] - mesh->vertices[tri[0]])
                           .normalized();
      out.push_back({segment, X_WP.apply(r.p_A), X_WP.R * n_P});
      return true;
    };
    if (!touch(proxy) || segment != Segment::kPalm) continue;
    // The palm meets a handle along a line, where its one nearest point may
    // lie under another finger than the one that wraps round: each strip
    // of it (one a finger's ray) touches where it does.
    for (const auto& strip : model.palm_strips()) touch(strip);
  }
  return out;
}

std::optional<GraspType> classify_grasp(std::span<const GraspContact> touches, Real friction) {
  const Real cos_cone = std::cos(std::atan(friction));
  std::vector<const GraspContact*> palm;  // the palm may touch in several places
  const GraspContact* tip[kDigitCount] = {};
  std::vector<const GraspContact*> fingers;  // touching segments of the digits
  for (const GraspContact& t : touches) {
    if (t.segment == Segment::kPalm) palm.push_back(&t);
    const std::optional<std::size_t> digit = digit_of(t.segment);
    if (!digit) continue;
    fingers.push_back(&t);
    const DigitJoints d = digit_joints(*digit);
    if (t.segment == d.segments.back()) tip[*digit] = &t;
  }
  auto opposes = [&](const GraspContact* a, const GraspContact* b) {
    return a && b && oppose(a->p_W, a->n_W, b->p_W, b->n_W, cos_cone);
  };
  if (!palm.empty() && fingers.size() >= 2) {
    for (const GraspContact* p : palm) {
      for (const GraspContact* f : fingers) {
        if (opposes(p, f)) return GraspType::kPower;
      }
    }
  }
  // 3-point pinch: the index and middle tips act as one virtual finger (Feix et al.)
  // that the thumb opposes.
  if (tip[0] && tip[1] && tip[2]) {
    const GraspContact pair{Segment::kIndexDistal, (tip[1]->p_W + tip[2]->p_W) / 2,
                            (tip[1]->n_W + tip[2]->n_W).normalized()};
    if (opposes(tip[0], &pair)) return GraspType::kTripod;
  }
  if (opposes(tip[0], tip[1]) || opposes(tip[0], tip[2])) return GraspType::kPrecision;
  return std::nullopt;
}

void Grasping::update(engine::Simulation& simulation, std::uint64_t frame, Real t) {
  engine::Scene& scene = simulation.scene();
  const JointAngles& glove = hand_->glove_angles();
  Real total_flexion = 0;
  std::array<Real, kDigitCount> digit_flexion{};
  for (std::size_t d = 0; d < kDigitCount; ++d) {
    digit_flexion[d] = flexion(glove, digit_joints(d));
    total_flexion += digit_flexion[d];
  }
  auto emit = [&](EventKind kind, const std::string& a, const std::string& b) {
    pending_.push_back({kind, frame, t, a, b});
  };
  // The total flexion low-passed (a time constant of kSmoothing_s divides
  // the glove's white noise by about three at 90 Hz), and how much it rose
  // over the last kClosingWindow_s.
  constexpr Real kSmoothing_s = 0.04;
  constexpr Real kClosingWindow_s = 0.25;
  if (!smoothed_started_) {
    smoothed_flexion_ = last_smoothed_ = total_flexion;
    smoothed_started_ = true;
  } else {
    last_smoothed_ = smoothed_flexion_;
    const Real alpha = 1 - std::exp(-std::max<Real>(t - last_time_, 0) / kSmoothing_s);
    smoothed_flexion_ += alpha * (total_flexion - smoothed_flexion_);
  }
  last_time_ = t;
  while (!smoothed_window_.empty() &&
         smoothed_window_.front().first < t - kClosingWindow_s - 1e-9) {
    smoothed_window_.pop_front();
  }
  smoothed_window_.emplace_back(t, smoothed_flexion_);
  Real window_low = smoothed_flexion_;
  for (const auto& [time, value] : smoothed_window_) window_low = std::min(window_low, value);
  const Real closed_lately = smoothed_flexion_ - window_low;

  if (held_) {
    // The flexion at the grasp settles on the closed hand's, below the
    // noise of the sample it was taken from: by half the release opening at
    // most, so that a hand opening at once still lets go.
    constexpr Real kSettle_s = 0.1;
    if (t - grasped_at_ <= kSettle_s + 1e-9) {
      for (std::size_t d = 0; d < kDigitCount; ++d) {
        flexion_at_grasp_[d] =
            std::max(settle_floor_[d], std::min(flexion_at_grasp_[d], digit_flexion[d]));
      }
    }
    // Release: a grasping digit opened past its flexion at the grasp, long enough.
    // Or opened by release_opening_, less, after closing release_open_deg past
    // the grasp: squeezing, then opening, is a gesture glove jitter does not make.
    bool opened = false;
    const Real open_deg = settings_.grasp.release_open_deg;
    for (std::size_t d = 0; d < kDigitCount; ++d) {
      peak_flexion_[d] = std::max(peak_flexion_[d], digit_flexion[d]);
      const Real at_grasp = flexion_at_grasp_[d];
      const bool squeezed = peak_flexion_[d] >= at_grasp + open_deg;
      opened = opened || (grasping_digit_[d] &&
                          (digit_flexion[d] < at_grasp - open_deg ||
                           (squeezed && digit_flexion[d] < at_grasp - release_opening_[d])));
    }
    if (!opened) {
      opened_since_ = -1;
    } else if (opened_since_ < 0) {
      opened_since_ = t;
    }
    if (opened && t - opened_since_ >= settings_.grasp.release_time_s - 1e-9) {
      release(simulation, "opened");
    } else {
      carry(simulation);
    }
    last_flexion_ = total_flexion;
    last_digit_flexion_ = digit_flexion;
    return;
  }

  // And the hand must have closed lately while the grasp built up: an open or
  // still hand moved against a part (drawn back along a rod it just let go
  // of, or slid along a bar with the glove's noise on every joint) grasps
  // nothing. A closing hand sweeps tens of degrees of total flexion in a
  // quarter second; the smoothed noise of a still one rises by more than
  // kMinClosing about once in 10^4 frames at 1.5 degrees a joint.
  constexpr Real kMinClosing = 10;  // degrees of total flexion, smoothed, within kClosingWindow_s
  // Grasp onset: the same part and type for onset_frames frames while the hand closes.
  std::optional<GraspType> found;
  std::string found_part;
  std::vector<GraspContact> found_contacts;
  for (const PartId part : candidates(scene, hand_->X_WH(), 1.2 * hand_->model().hand_length())) {
    // Fixed parts, and parts attached to a fixed one, stop the fingers but are not grasped.
    if (!scene.movable(part) || !scene.movable(carried_root(scene, part))) continue;
    std::vector<GraspContact> touching = touches(scene, part);
    if (touching.empty()) continue;
    const std::optional<GraspType> type = classify_grasp(touching, settings_.grasp.friction);
    // The closest try so far at this part, for why_not_grasped.
    std::vector<Segment> segments;
    for (const GraspContact& c : touching) {
      if (std::find(segments.begin(), segments.end(), c.segment) == segments.end()) {
        segments.push_back(c.segment);
      }
    }
    const bool closing_now = closed_lately >= kMinClosing;
    if (Attempt& best = attempts_[scene.name(part)];
        std::pair(closing_now, segments.size()) > std::pair(best.closing, best.touching.size())) {
      best = {t, std::move(segments), type, closing_now};
    }
    if (type) {
      found = type;
      found_part = scene.name(part);
      found_contacts = std::move(touching);
      break;
    }
  }
  constexpr Real kClosingSlack = 2;    // degrees of glove jitter tolerated while closing
  constexpr int kOnsetMisses = 2;      // frames in a row without the grasp, tolerated
  constexpr Real kStillClosing = 0.5;  // degrees per frame: the hand is still closing
  // Against the last frame for a grasp starting to build up; against where it
  // started for one building up (the sum of 15 joints' noise swings by more
  // than the slack from frame to frame, but does not open the hand).
  const bool closing = smoothed_flexion_ >= (candidate_.empty() || found_part != candidate_
                                                 ? last_smoothed_
                                                 : candidate_start_smoothed_) -
                                                kClosingSlack;
  const bool still_closing = total_flexion > last_flexion_ + kStillClosing;
  if (found && closing && found_part == candidate_) {
    ++candidate_frames_;
    candidate_type_ = *found;  // more fingers may arrive while the hand closes
    candidate_closing_ = std::max(candidate_closing_, closed_lately);
  } else if (found && closing) {
    candidate_ = found_part;
    candidate_type_ = *found;
    candidate_frames_ = 1;
    candidate_start_flexion_ = last_flexion_;
    candidate_start_smoothed_ = last_smoothed_;
    candidate_start_digits_ = last_digit_flexion_;
    candidate_closing_ = closed_lately;
  } else if (!found && closing && !candidate_.empty() && candidate_misses_ < kOnsetMisses) {
    // A frame in which glove noise lifts a finger or the palm off the part
    // interrupts the grasp building up, but does not start it again: a hand
    // that has stopped closing could never start it again.
    ++candidate_misses_;
  } else {
    candidate_.clear();
    candidate_frames_ = 0;
  }
  if (found) candidate_misses_ = 0;
  last_flexion_ = total_flexion;
  last_digit_flexion_ = digit_flexion;
  // The grasp holds for onset_frames; its type is taken once the hand stops closing
  // (or after four times as long), so that the last fingers to arrive count.
  if (found && found_part == candidate_ && candidate_frames_ >= settings_.grasp.onset_frames &&
      candidate_closing_ >= kMinClosing &&
      (!still_closing || candidate_frames_ >= 4 * settings_.grasp.onset_frames)) {
    hold(candidate_, candidate_type_);
    // The digits that grasp are those touching the part now (a grasp fires only in a
    // frame that found it, so these are the candidate's contacts).
    grasping_digit_.fill(false);
    for (const GraspContact& touch : found_contacts) {
      if (const std::optional<std::size_t> d = digit_of(touch.segment)) grasping_digit_[*d] = true;
    }
    // A grasp made as the fingers barely moved (a bar against the palm, the
    // fingers stopped on it at once) may sit less than release_open_deg above
    // the open hand, which could then never release it: such a digit
    // releases when it opens back half of what it closed while the grasp
    // built up.
    // Not less than a degree (the glove's jitter), where the open hand can
    // still get there: half the flexion at the grasp, when that is less.
    constexpr Real kJitter = 1;  // degrees
    for (std::size_t d = 0; d < kDigitCount; ++d) {
      const Real closed = flexion_at_grasp_[d] - candidate_start_digits_[d];
      if (closed > 0) {
        const Real floor = std::min(kJitter, flexion_at_grasp_[d] / 2);
        release_opening_[d] =
            std::min(std::max(closed / 2, floor), settings_.grasp.release_open_deg);
      }
    }
    emit(EventKind::kGrasp, candidate_, std::string(grasp_type_name(candidate_type_)));
    candidate_.clear();
    candidate_frames_ = 0;
  }
}

namespace {

/// `box` grown to hold `other` too.
void grow(collision::Bounds& box, const collision::Bounds& other) {
  box.min = box.min.cwiseMin(other.min);
  box.max = box.max.cwiseMax(other.max);
}

}  // namespace

Grasping::MovingBodies Grasping::moving_bodies(const engine::Scene& scene, PartId part) {
  MovingBodies out;
  out.parts.push_back(part);
  out.local = models_->mesh_bounds(scene.collision_mesh(part));
  for (const PartId q : scene.parts()) {
    const auto& q_mesh = scene.collision_mesh(q);
    if (q == part || !q_mesh || scene.has_tag(q, "hand") || !scene.descends_from(q, part)) continue;
    // From the chain of local poses: relative to a moving part, the world poses
    // round differently each frame.
    const Transform X_OA = pose_in(scene, part, q);
    out.attached.push_back({models_->collision_model(q_mesh), X_OA});
    out.parts.push_back(q);
    grow(out.local, collision::transformed_bounds(models_->mesh_bounds(q_mesh), X_OA));
  }
  return out;
}

void Grasping::carry(engine::Simulation& simulation) {
  engine::Scene& scene = simulation.scene();
  const PartId held = scene.get(*held_);
  const PartId part = carried_root(scene, held);
  if (scene.name(part) != *carried_) {
    // Attached or detached while held (a rule's attach): the hand carries the
    // new top of the sub-assembly from where it is now, or lets go of a part
    // now attached to a fixed one.
    if (!scene.movable(part)) {
      release(simulation, "attached");
      return;
    }
    carried_ = scene.name(part);
    X_HO_ = engine::compose(hand_->X_WH().inverse(), scene.world_pose(part));
  }
  const auto& mesh = scene.collision_mesh(part);
  const Transform X_WO = scene.world_pose(part);
  const Transform X_WO_target = guided(scene, part, engine::compose(hand_->X_WH(), X_HO_));
  // The parts attached to the carried part move with it and are kept out of the others as it is.
  const MovingBodies moving = moving_bodies(scene, part);
  const std::vector<PartId>& bodies = moving.parts;
  const collision::Bounds& local = moving.local;
  // Obstacles: every other part that the swept box of the move reaches.
  collision::Bounds swept = collision::transformed_bounds(local, X_WO);
  grow(swept, collision::transformed_bounds(local, X_WO_target));
  std::vector<SlideObstacle> obstacles;
  std::vector<PartId> handles;
  for (const PartId other : scene.parts()) {
    const auto& other_mesh = scene.collision_mesh(other);
    if (!other_mesh || scene.has_tag(other, "hand") || scene.descends_from(other, part)) continue;
    const Transform X_WB = scene.world_pose(other);
    if (!overlap(collision::transformed_bounds(models_->mesh_bounds(other_mesh), X_WB), swept,
                 1e-3))
      continue;
    obstacles.push_back({models_->collision_model(other_mesh), models_->distance_shared(other_mesh),
                         X_WB, static_cast<std::uint32_t>(handles.size())});
    handles.push_back(other);
  }
  SlideRequest request;
  request.part = models_->collision_model(mesh);
  request.part_distance = models_->distance_shared(mesh);
  request.attached = moving.attached;
  request.p_PC = (local.min + local.max) / 2;
  request.size = std::max<Real>((local.max - local.min).norm() / 2, 1e-4);
  request.X_WP = X_WO;
  request.X_WP_target = X_WO_target;
  request.obstacles = obstacles;
  // Last frame's contacts, with their obstacles and bodies renumbered for this frame's
  // lists (a part attached or detached since is a body more or less).
  std::vector<SlideContact> previous;
  for (const SlideContact& k : last_slide_.contacts) {
    const auto it = std::find(handles.begin(), handles.end(), contact_parts_[k.obstacle]);
    const auto body = std::find(bodies.begin(), bodies.end(), contact_bodies_[k.body]);
    if (it == handles.end() || body == bodies.end()) continue;
    SlideContact renumbered = k;
    renumbered.obstacle = static_cast<std::uint32_t>(it - handles.begin());
    renumbered.body = static_cast<std::uint32_t>(body - bodies.begin());
    previous.push_back(renumbered);
  }
  request.previous_contacts = previous;
  request.start_proof = &last_slide_.proof;
  request.fronts = settings_.sliding.separation_fronts ? &fronts_ : nullptr;
  last_slide_ = slide(request, settings_.sliding);
  contact_parts_ = handles;
  contact_bodies_ = bodies;
  stats_.slide_queries += static_cast<std::uint64_t>(last_slide_.collision_queries);
  stats_.max_stretch_m = std::max(stats_.max_stretch_m, last_slide_.stretch_m);
  const std::uint64_t frame = simulation.frame();
  const Real t = simulation.time();
  if (last_slide_.status == SlideStatus::kOverstretched) {
    release(simulation, "overstretched");
    return;
  }
  scene.set_world_pose(part, last_slide_.X_WP);
  report_sliding(scene, bodies, handles, frame, t);
}

void Grasping::report_sliding(const engine::Scene& scene, std::span<const PartId> bodies,
                              std::span<const PartId> handles, std::uint64_t frame, Real t) {
  // What slides on what: each moving body against each obstacle it has a contact with.
  std::vector<std::pair<std::string, std::string>> sliding;
  if (last_slide_.status == SlideStatus::kReached) {
    // Moving freely: on nothing.
  } else if (last_slide_.contacts.empty()) {
    // Held back with no contact found (a part grasped again where it was just snapped,
    // its start touching): as it was.
    sliding = sliding_pairs_;
  } else {
    for (const SlideContact& k : last_slide_.contacts) {
      sliding.emplace_back(scene.name(bodies[k.body]), scene.name(handles[k.obstacle]));
    }
    std::sort(sliding.begin(), sliding.end());
    sliding.erase(std::unique(sliding.begin(), sliding.end()), sliding.end());
  }
  for (const auto& [a, b] : sliding_pairs_) {
    if (!std::binary_search(sliding.begin(), sliding.end(), std::pair(a, b)))
      pending_.push_back({EventKind::kSlideEnd, frame, t, a, b});
  }
  for (const auto& [a, b] : sliding) {
    if (!std::binary_search(sliding_pairs_.begin(), sliding_pairs_.end(), std::pair(a, b)))
      pending_.push_back({EventKind::kSlideBegin, frame, t, a, b});
  }
  sliding_pairs_ = std::move(sliding);
}

std::pair<Real, Real> Grasping::extent_along(const engine::Scene& scene, PartId part,
                                             const Transform& X_WP, const Vec3& q_W,
                                             const Vec3& b_W) {
  const collision::Bounds box =
      collision::transformed_bounds(models_->mesh_bounds(scene.collision_mesh(part)), X_WP);
  Real low = std::numeric_limits<Real>::infinity();
  Real high = -low;
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3 c((corner & 1) != 0 ? box.max.x() : box.min.x(),
                 (corner & 2) != 0 ? box.max.y() : box.min.y(),
                 (corner & 4) != 0 ? box.max.z() : box.min.z());
    low = std::min(low, b_W.dot(c - q_W));
    high = std::max(high, b_W.dot(c - q_W));
  }
  return {low, high};
}

Transform Grasping::guided(const engine::Scene& scene, PartId root, const Transform& X_WR_target) {
  for (std::size_t m = 0; m < mates_.size(); ++m) {
    const Mate& mate = mates_[m];
    if (!mate.guide) continue;
    const auto parts = outward_mate(scene, mate, root);
    if (!parts) continue;
    const auto [p, o] = *parts;
    const Transform X_WP_target =
        p == root ? X_WR_target : engine::compose(X_WR_target, pose_in(scene, root, p));
    const Transform X_WO = scene.world_pose(o);
    const Vec3 q_W = X_WO.apply(mate.p_OF);
    const Vec3 b_W = (X_WO.R * mate.axis_O).normalized();
    const Vec3 p_W = X_WP_target.apply(mate.p_PF);
    const Vec3 a_W = (X_WP_target.R * mate.axis_P).normalized();
    // Within the capture region: the feature point near the other's axis line, the axes aligned.
    const Vec3 off_axis = (p_W - q_W) - b_W * b_W.dot(p_W - q_W);
    const Real angle = std::atan2(a_W.cross(b_W).norm(), a_W.dot(b_W));
    // Captured within the tolerances, kept within three times them (glove noise
    // must not pull the part in and out of the guide), once the part has
    // come within the position tolerance of the other along the axis: a
    // chamfer draws in a peg that reaches the hole, not one held above it.
    const Real widen = guiding_ == m ? kGuideHysteresis : 1;
    // Whichever way the mate's axis points: the two parts' spans along it
    // overlap, the other's widened by the tolerance.
    const auto [other_low, other_high] = extent_along(scene, o, scene.world_pose(o), q_W, b_W);
    const auto [part_low, part_high] = extent_along(scene, p, X_WP_target, q_W, b_W);
    const Real reach = widen * mate.position_tolerance;
    const bool at_the_other = part_high >= other_low - reach && part_low <= other_high + reach;
    if (off_axis.norm() > widen * mate.position_tolerance ||
        angle > widen * mate.angle_tolerance_deg * kDegree || !at_the_other) {
      if (guiding_ == m) guiding_.reset();
      continue;
    }
    guiding_ = m;
    // The target turned by the least rotation onto the axis, its point moved onto the line.
    Transform X = X_WP_target;
    if (angle > 0) {
      X.R = rotation_from_vector(a_W.cross(b_W).normalized() * angle) * X.R;
    }
    const Vec3 p_new = X.apply(mate.p_PF);
    const Vec3 on_line = q_W + b_W * b_W.dot(p_new - q_W);
    X.t += on_line - p_new;
    return root_pose_for(scene, root, p, X);
  }
  return X_WR_target;
}

std::string Grasping::why_not_grasped(const std::string& part) const {
  const auto it = attempts_.find(part);
  if (it == attempts_.end()) return "the hand never touched it while it held nothing";
  const Attempt& a = it->second;
  bool palm = false, thumb_tip = false, finger_tip = false;
  std::size_t fingers = 0;
  std::string names;
  for (const Segment s : a.touching) {
    names += (names.empty() ? "" : ", ") + std::string(segment_name(s));
    palm = palm || s == Segment::kPalm;
    thumb_tip = thumb_tip || s == Segment::kThumbDistal;
    finger_tip = finger_tip || s == Segment::kIndexDistal || s == Segment::kMiddleDistal;
    fingers += s != Segment::kPalm;
  }
  char when[48];
  std::snprintf(when, sizeof when, "at t=%.3f s", a.time);
  std::string why;
  constexpr const char* kClosingNeeded =
      "a grasp needs the glove's flexion to rise by 10 degrees within a quarter second while it "
      "builds up";
  if (a.type && !a.closing) {
    why = "they made a " + std::string(grasp_type_name(*a.type)) +
          " grasp, but the hand was not closing (" + kClosingNeeded + ")";
  } else if (a.type) {
    why = "they made a " + std::string(grasp_type_name(*a.type)) +
          " grasp as the hand closed, but not for the " +
          std::to_string(settings_.grasp.onset_frames) +
          " frames in a row a grasp needs while it builds up";
  } else if (!a.closing) {
    why = "the hand never touched it while closing (" + std::string(kClosingNeeded) + ")";
  } else if (!palm && !thumb_tip) {
    why = "neither the palm (within " +
          std::to_string(static_cast<int>(std::round(settings_.grasp.palm_gap * 1000))) +
          " mm) nor the thumb's tip touched it: a power grasp needs the palm, a pinch the "
          "thumb's tip";
  } else if (palm && fingers < 2) {
    why = "a power grasp needs the palm and two finger segments";
  } else if (palm) {
    why = "no finger segment opposed the palm (their contacts within the friction cones)";
  } else if (!finger_tip) {
    why = "a pinch needs the thumb's tip and the index's or middle's tip";
  } else {
    why =
        "the thumb's tip did not oppose the index's or middle's (their contacts within the "
        "friction cones)";
  }
  return "the hand's closest try was " + std::string(when) + ", touching it with " + names + "; " +
         why;
}

void Grasping::release(engine::Simulation& simulation, const std::string& reason) {
  const std::string part = *held_;
  pending_.push_back({EventKind::kRelease, simulation.frame(), simulation.time(), part, reason});
  for (const auto& [a, b] : sliding_pairs_) {
    pending_.push_back({EventKind::kSlideEnd, simulation.frame(), simulation.time(), a, b});
  }
  sliding_pairs_.clear();
  held_.reset();
  carried_.reset();
  guiding_.reset();
  opened_since_ = -1;
  snap(simulation, part);
}

void Grasping::snap(engine::Simulation& simulation, const std::string& part) {
  engine::Scene& scene = simulation.scene();
  // The first mate of the released part's sub-assembly within its tolerances
  // (in the order they were added) seats it, moving the whole sub-assembly.
  const PartId root = carried_root(scene, scene.get(part));
  if (!scene.movable(root)) return;
  for (const Mate& mate : mates_) {
    const auto parts = outward_mate(scene, mate, root);
    if (!parts) continue;
    const auto [p, o] = *parts;
    const Transform X_WP = scene.world_pose(p), X_WO = scene.world_pose(o);
    if (!within_tolerance(mate, X_WP, X_WO)) continue;
    const Transform X_WR_seated = root_pose_for(scene, root, p, mate_pose(mate, X_WP, X_WO));
    if (const Overlap overlap = deepest_overlap(scene, root, X_WR_seated);
        overlap.depth > kSnapOverlap) {
      refused_snaps_.push_back({mate.name, mate.part, overlap.blocker, overlap.overlapping,
                                overlap.depth, simulation.time()});
      continue;
    }
    scene.set_world_pose(root, X_WR_seated);
    pending_.push_back(
        {EventKind::kMate, simulation.frame(), simulation.time(), mate.part, mate.other});
    // The sub-assembly's other fits that hold where it is seated are made
    // too (a shaft carried with its bearing lands in its bore and the bearing
    // in its seat): each fires, though only the first moved it.
    for (const Mate& other : mates_) {
      if (&other == &mate) continue;
      const auto also = outward_mate(scene, other, root);
      if (!also) continue;
      if (within_tolerance(other, scene.world_pose(also->first), scene.world_pose(also->second))) {
        pending_.push_back(
            {EventKind::kMate, simulation.frame(), simulation.time(), other.part, other.other});
      }
    }
    return;
  }
}

Grasping::Overlap Grasping::deepest_overlap(const engine::Scene& scene, PartId part,
                                            const Transform& X_WP) {
  // The part and the parts attached to it move together, rigidly: each by
  // the same move, and none is checked against another of them.
  const Transform move = engine::compose(X_WP, scene.world_pose(part).inverse());
  std::vector<std::pair<PartId, Transform>> moved;
  for (const PartId q : scene.parts()) {
    if (scene.descends_from(q, part) && scene.collision_mesh(q)) {
      moved.emplace_back(q, q == part ? X_WP : engine::compose(move, scene.world_pose(q)));
    }
  }
  Overlap deepest;
  for (const auto& [q, X_WQ] : moved) {
    const auto& mesh = scene.collision_mesh(q);
    const collision::Bounds box = collision::transformed_bounds(models_->mesh_bounds(mesh), X_WQ);
    for (const PartId other : scene.parts()) {
      const auto& other_mesh = scene.collision_mesh(other);
      if (!other_mesh || scene.has_tag(other, "hand") || scene.descends_from(other, part)) continue;
      const Transform X_WB = scene.world_pose(other);
      if (!overlap(collision::transformed_bounds(models_->mesh_bounds(other_mesh), X_WB), box, 0)) {
        continue;
      }
      const Real depth = models_->overlap.depth(mesh, X_WQ, other_mesh, X_WB);
      if (depth > deepest.depth) deepest = {scene.name(q), scene.name(other), depth};
    }
  }
  return deepest;
}

MateOffset mate_offset(const Mate& mate, const Transform& X_WP, const Transform& X_WO) {
  const Vec3 a_W = (X_WP.R * mate.axis_P).normalized(), b_W = (X_WO.R * mate.axis_O).normalized();
  const Vec3 d_W = X_WP.apply(mate.p_PF) - X_WO.apply(mate.p_OF);
  const Real along = -d_W.dot(b_W);  // the axis points in, along the way the part goes
  return {d_W.norm(), std::atan2(a_W.cross(b_W).norm(), a_W.dot(b_W)) / kDegree, along,
          (d_W + along * b_W).norm()};
}

bool within_tolerance(const Mate& mate, const Transform& X_WP, const Transform& X_WO) {
  const MateOffset offset = mate_offset(mate, X_WP, X_WO);
  return offset.distance_m <= mate.position_tolerance &&
         offset.angle_deg <= mate.angle_tolerance_deg;
}

Transform mate_pose(const Mate& mate, const Transform& X_WP, const Transform& X_WO) {
  const Vec3 a_W = (X_WP.R * mate.axis_P).normalized(), b_W = (X_WO.R * mate.axis_O).normalized();
  const Real angle = std::atan2(a_W.cross(b_W).norm(), a_W.dot(b_W)) / kDegree;
  Transform X_new;
  X_new.R = X_WP.R;
  if (angle > 0) {
    // The least turn of a onto b; opposite axes turn half a turn about a normal of a.
    const Vec3 cross = a_W.cross(b_W);
    const Vec3 turn_axis = cross.norm() > 0 ? Vec3(cross.normalized()) : Vec3(a_W.unitOrthogonal());
    X_new.R = rotation_from_vector(turn_axis * (angle * kDegree)) * X_WP.R;
  }
  // Then the point onto the point.
  X_new.t = X_WO.apply(mate.p_OF) - X_new.R * mate.p_PF;
  return X_new;
}

}  // namespace dovetail::interaction
