#include "dovetail/interaction/hand.h"

#include <cstdio>
#include <stdexcept>
#include <utility>

namespace dovetail::interaction {

namespace {

std::string format_angle(Real degrees) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", degrees);
  return buffer;
}

}  // namespace

std::vector<engine::RenderItem> hand_render_items(const HandModel& model, const GloveSample& sample,
                                                  const std::string& name) {
  const HandPose pose = model.forward_kinematics(clamp_to_limits(sample.joints));
  const Transform X_WH = sample.X_WH();
  std::vector<engine::RenderItem> items;
  for (std::size_t i = 0; i < kSegmentCount; ++i) {
    const auto segment = static_cast<Segment>(i);
    engine::RenderItem item;
    item.mesh = model.proxy(segment);
    item.X_WP = engine::compose(X_WH, pose.X_HS[i]);
    item.color = engine::Color{kHandColor[0], kHandColor[1], kHandColor[2]};
    item.name = name + "." + std::string(segment_name(segment));
    items.push_back(std::move(item));
  }
  return items;
}

Hand::Hand(engine::Simulation& simulation, std::shared_ptr<const GloveSource> source,
           const HandSettings& settings)
    : model_(settings.model), source_(std::move(source)), settings_(settings) {
  if (!source_) throw std::invalid_argument("hand: no glove source");
  if (settings_.name.empty()) throw std::invalid_argument("hand: the hand needs a name");
  sample_ = source_->sample(simulation.time());
  glove_angles_ = clamp_to_limits(sample_.joints);
  angles_ = glove_angles_;
  pose_ = model_.forward_kinematics(angles_);
  X_WH_ = sample_.X_WH();

  engine::Scene& scene = simulation.scene();
  for (std::size_t i = 0; i < kSegmentCount; ++i) {  // all names first: all parts or none
    const std::string name =
        settings_.name + "." + std::string(segment_name(static_cast<Segment>(i)));
    if (scene.find(name).valid()) {
      throw engine::SceneError("hand: the scene already has a part named '" + name + "'");
    }
  }
  for (std::size_t i = 0; i < kSegmentCount; ++i) {
    const auto segment = static_cast<Segment>(i);
    engine::PartDef desc;
    desc.name = settings_.name + "." + std::string(segment_name(segment));
    desc.tags = {"hand"};
    desc.movable = true;
    desc.render_mesh = model_.proxy(segment);
    desc.collision_group = settings_.name;
    desc.color = kHandColor;
    desc.X_QP = engine::compose(X_WH_, pose_.X_HS[i]);
    parts_[i] = scene.add_part(desc);
    segment_by_part_.emplace(desc.name, segment);
  }
  simulation.add_frame_hook(
      [this](engine::Simulation& sim, std::uint64_t frame, double t) { update(sim, frame, t); });
  simulation.add_event_filter([this](engine::Simulation& sim, std::vector<engine::Event>& events) {
    filter(sim.scene(), events);
  });
}

Hand::Hand(engine::Simulation& simulation, std::shared_ptr<const GloveSource> source)
    : Hand(simulation, std::move(source), HandSettings{}) {}

std::optional<Segment> Hand::segment_of(const std::string& part_name) const {
  const auto it = segment_by_part_.find(part_name);
  if (it == segment_by_part_.end()) return std::nullopt;
  return it->second;
}

void Hand::update(engine::Simulation& simulation, std::uint64_t frame, Real t) {
  // 1. Input.
  sample_ = source_->sample(t);
  if (settings_.record) recorded_.push_back(sample_);
  // 2. Hand: limits, forward kinematics, the proxies' poses.
  std::bitset<kJointCount> clamped;
  glove_angles_ = clamp_to_limits(sample_.joints, &clamped);
  for (std::size_t j = 0; j < kJointCount; ++j) {
    if (!clamped[j]) continue;
    if (clamped_frames_[j]++ == 0) {
      const JointLimit& limit = joint_limits()[j];
      simulation.add_note(settings_.name + ": " + std::string(joint_name(static_cast<Joint>(j))) +
                          " " + format_angle(sample_.joints[j]) + " deg is outside its range [" +
                          format_angle(limit.min) + ", " + format_angle(limit.max) + "] at frame " +
                          std::to_string(frame) + "; clamped (here and whenever it recurs)");
    }
  }
  X_WH_ = sample_.X_WH();
  const JointAngles previous = angles_;
  angles_ = glove_angles_;
  if (limiter_)
    angles_ = clamp_to_limits([&] {
      JointAngles limited = glove_angles_;
      limiter_(model_, X_WH_, previous, limited);
      return limited;
    }());
  pose_ = model_.forward_kinematics(angles_);
  pose_parts(simulation.scene());
}

void Hand::pose_parts(engine::Scene& scene) const {
  for (std::size_t i = 0; i < kSegmentCount; ++i) {
    if (scene.contains(parts_[i]))
      scene.set_local_pose(parts_[i], engine::compose(X_WH_, pose_.X_HS[i]));
  }
}

void Hand::filter(const engine::Scene& scene, std::vector<engine::Event>& events) {
  merge_region_events(events);
  auto is_any_hand = [&](const std::string& name) {
    const engine::PartId part = scene.find(name);
    return part.valid() && scene.has_tag(part, "hand");
  };
  for (engine::Event& e : events) {
    if (e.kind != engine::EventKind::kContactBegin && e.kind != engine::EventKind::kContactEnd) {
      continue;
    }
    // The segment's part first; a contact between two hands stays a contact event.
    const bool a_is_hand = segment_of(e.a).has_value();
    const bool b_is_hand = segment_of(e.b).has_value();
    if (a_is_hand == b_is_hand || is_any_hand(a_is_hand ? e.b : e.a)) continue;
    e.kind = e.kind == engine::EventKind::kContactBegin ? engine::EventKind::kHandContactBegin
                                                        : engine::EventKind::kHandContactEnd;
    if (b_is_hand) std::swap(e.a, e.b);
  }
}

void Hand::merge_region_events(std::vector<engine::Event>& events) {
  auto is_segment_in_region = [&](const engine::Event& e) {
    return (e.kind == engine::EventKind::kRegionEnter ||
            e.kind == engine::EventKind::kRegionLeave) &&
           segment_of(e.a).has_value();
  };
  // Per region touched this frame, its count before the frame's events.
  std::map<std::string, std::size_t, std::less<>> before;
  std::uint64_t frame = 0;
  double time = 0;
  for (const engine::Event& e : events) {
    if (!is_segment_in_region(e)) continue;
    frame = e.frame;
    time = e.time;
    std::size_t& inside = segments_inside_[e.b];
    before.try_emplace(e.b, inside);
    if (e.kind == engine::EventKind::kRegionEnter) {
      ++inside;
    } else if (inside > 0) {  // a leave without its enter (a region added later) counts none
      --inside;
    }
  }
  if (before.empty()) return;
  std::erase_if(events, is_segment_in_region);
  for (const auto& [region, was] : before) {
    const std::size_t after = segments_inside_[region];
    if ((was == 0) == (after == 0)) continue;
    events.push_back({after > 0 ? engine::EventKind::kRegionEnter : engine::EventKind::kRegionLeave,
                      frame, time, settings_.name, region});
  }
}

}  // namespace dovetail::interaction
