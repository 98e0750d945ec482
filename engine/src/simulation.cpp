#include "dovetail/engine/simulation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>
#include <tuple>
#include <utility>

namespace dovetail::engine {

using collision::Vec3;

/// A scene part as the loop last committed it.
struct Simulation::Registered {
  PartId handle;
  collision::PartId id;  ///< invalid for a part without a collision mesh
  Transform X_WP;
  Box local_box;  ///< bounds of the collision mesh in the part's frame
};

namespace {

bool same_bits(const Transform& x, const Transform& y) {
  return std::memcmp(x.R.data(), y.R.data(), sizeof(double) * 9) == 0 &&
         std::memcmp(x.t.data(), y.t.data(), sizeof(double) * 3) == 0;
}

/// World box of a local box under X_WP: the bounds of its 8 transformed corners.
Box world_box(const Box& local, const Transform& X_WP) {
  const collision::Bounds b = collision::transformed_bounds({local.min, local.max}, X_WP);
  return {b.min, b.max};
}

bool overlap(const Box& x, const Box& y) {
  return (x.min.array() <= y.max.array()).all() && (y.min.array() <= x.max.array()).all();
}

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace

Simulation::Simulation(Scene scene, const SimulationSettings& settings)
    : scene_(std::move(scene)), settings_(settings) {
  if (!(settings_.time_step > 0) || !std::isfinite(settings_.time_step)) {
    throw std::invalid_argument("simulation: the time step must be a positive number of seconds");
  }
  world_ = std::make_unique<collision::CollisionWorld>(
      collision::WorldSettings{.method = settings_.method,
                               .tolerance = settings_.tolerance,
                               .broadphase = settings_.broadphase,
                               .convex_level = settings_.convex_level,
                               .threads = settings_.collision_threads,
                               .contacts = settings_.contacts,
                               .capture = settings_.capture,
                               .cross_check = settings_.cross_check});
  std::vector<Event> ignored;
  commit(ignored, 0);
  state_hash_ = current_state_hash();
  report_.time_step = settings_.time_step;
  report_.parts = scene_.part_count();
  report_.state_hash = state_hash_;
}

Simulation::~Simulation() = default;
Simulation::Simulation(Simulation&&) noexcept = default;
Simulation& Simulation::operator=(Simulation&&) noexcept = default;

collision::PartId Simulation::collision_id(PartId part) const {
  if (!part.valid() || part.index >= registered_.size() || !registered_[part.index] ||
      registered_[part.index]->handle != part) {
    return {};
  }
  return registered_[part.index]->id;
}

void Simulation::queue_pose(const PoseCommand& command) {
  scene_.get(command.part);  // unknown names fail now, not at frame k
  const auto at =
      std::upper_bound(commands_.begin(), commands_.end(), command.frame,
                       [](std::uint64_t frame, const PoseCommand& c) { return frame < c.frame; });
  commands_.insert(at, command);
}

void Simulation::add_timer(const std::string& name, double time) {
  timers_.push_back({name, time, false});
}

void Simulation::add_region(const Region& region) {
  for (const RegionState& r : regions_) {
    if (r.region.name == region.name) {
      throw SceneError("simulation: duplicate region name '" + region.name + "'");
    }
  }
  for (const std::string& part : region.parts) scene_.get(part);
  regions_.push_back({region, {}});
}

void Simulation::commit(std::vector<Event>& events, double now) {
  // Parts gone from the scene leave the collision world.
  for (std::unique_ptr<Registered>& r : registered_) {
    if (r && !scene_.contains(r->handle)) {
      if (r->id.valid()) {
        world_->remove_part(r->id);
        removed_.push_back(r->id);
      }
      r.reset();
    }
  }
  // In name order (Scene::parts), so the part moves reach the bus sorted,
  // and the state hash is folded on the way.
  StateHasher hasher;
  for (const PartId part : scene_.parts()) {
    const Transform X_WP = scene_.world_pose(part);
    hasher.add(scene_.name(part), X_WP);
    if (part.index >= registered_.size()) registered_.resize(part.index + 1);
    std::unique_ptr<Registered>& r = registered_[part.index];
    if (!r) {
      r = std::make_unique<Registered>();
      r->handle = part;
      r->X_WP = X_WP;
      const auto& mesh = scene_.collision_mesh(part);
      if (mesh) {
        r->id = world_->add_part({.mesh = mesh,
                                  .X_WP = X_WP,
                                  .movable = scene_.movable(part),
                                  .level = collision::LevelOfDetail::kExact,
                                  .name = scene_.name(part)});
        collision_names_[r->id] = scene_.name(part);
        const std::string& group = scene_.collision_group(part);
        if (!group.empty()) {
          for (const std::unique_ptr<Registered>& other : registered_) {
            if (other && other.get() != r.get() && other->id.valid() &&
                scene_.contains(other->handle) && scene_.collision_group(other->handle) == group) {
              world_->set_interest(r->id, other->id, false);
            }
          }
        }
        const collision::Bounds b = collision::mesh_bounds(*mesh);
        r->local_box = {b.min, b.max};
      }
      continue;
    }
    if (same_bits(r->X_WP, X_WP)) continue;
    r->X_WP = X_WP;
    if (r->id.valid()) world_->set_pose(r->id, X_WP);
    events.push_back({EventKind::kPartMoved, frame_, now, scene_.name(part), {}});
  }
  committed_hash_ = hasher.value();
  committed_revision_ = scene_.revision();
}

std::uint64_t Simulation::current_state_hash() const {
  return scene_.revision() == committed_revision_ ? committed_hash_ : engine::state_hash(scene_);
}

void Simulation::contact_events(const collision::StepResult& step, std::vector<Event>& events,
                                double now) {
  auto names = [this](const collision::PartPair& pair) {
    std::pair<std::string, std::string> n{collision_names_.at(pair.a), collision_names_.at(pair.b)};
    if (n.second < n.first) std::swap(n.first, n.second);
    return n;
  };
  for (const collision::PartPair& pair : step.began) {
    auto [a, b] = names(pair);
    events.push_back({EventKind::kContactBegin, frame_, now, std::move(a), std::move(b)});
  }
  for (const collision::PartPair& pair : step.ended) {
    auto [a, b] = names(pair);
    events.push_back({EventKind::kContactEnd, frame_, now, std::move(a), std::move(b)});
  }
  // Contacts are sorted by pair: count each pair's run.
  std::size_t i = 0;
  while (i < step.contacts.size()) {
    const collision::PartPair pair{step.contacts[i].a, step.contacts[i].b};
    std::size_t j = i;
    while (j < step.contacts.size() && step.contacts[j].a == pair.a &&
           step.contacts[j].b == pair.b) {
      ++j;
    }
    // By ids first: the names' map only on a pair's first contact.
    PairContactStats*& cached = contact_stats_by_id_[{pair.a, pair.b}];
    if (!cached) {
      const auto key = names(pair);
      auto it = contact_stats_.find(key);
      if (it == contact_stats_.end()) {
        it = contact_stats_.emplace(key, PairContactStats{key.first, key.second}).first;
        it->second.first_frame = frame_;
      }
      cached = &it->second;
    }
    PairContactStats& s = *cached;
    ++s.frames_in_contact;
    s.last_frame = frame_;
    s.max_contacts = std::max<std::uint64_t>(s.max_contacts, j - i);
    i = j;
  }
}

void Simulation::timer_events(std::vector<Event>& events, double now) {
  std::vector<Event> fired;
  for (Timer& timer : timers_) {
    if (timer.fired || now < timer.time) continue;
    timer.fired = true;
    fired.push_back({EventKind::kTimer, frame_, now, timer.name, {}});
  }
  // In front, where their kind sorts: the bus then usually finds the frame's
  // events in kind order already.
  events.insert(events.begin(), std::make_move_iterator(fired.begin()),
                std::make_move_iterator(fired.end()));
}

void Simulation::region_events(std::vector<Event>& events, double now) {
  for (RegionState& state : regions_) {
    std::vector<std::string> inside;
    auto test = [&](PartId part) {
      if (!part.valid() || part.index >= registered_.size() || !registered_[part.index]) return;
      const Registered& r = *registered_[part.index];
      if (!r.id.valid()) return;
      if (overlap(world_box(r.local_box, r.X_WP), state.region.box)) {
        inside.push_back(scene_.name(part));
      }
    };
    if (state.region.parts.empty()) {
      for (const PartId part : scene_.parts()) test(part);
    } else {
      for (const std::string& name : state.region.parts) test(scene_.find(name));
      std::sort(inside.begin(), inside.end());
    }
    std::vector<std::string> entered, left;
    std::set_difference(inside.begin(), inside.end(), state.inside.begin(), state.inside.end(),
                        std::back_inserter(entered));
    std::set_difference(state.inside.begin(), state.inside.end(), inside.begin(), inside.end(),
                        std::back_inserter(left));
    for (std::string& part : entered) {
      events.push_back({EventKind::kRegionEnter, frame_, now, std::move(part), state.region.name});
    }
    for (std::string& part : left) {
      events.push_back({EventKind::kRegionLeave, frame_, now, std::move(part), state.region.name});
    }
    state.inside = std::move(inside);
  }
}

const FrameResult& Simulation::step() {
  const auto frame_start = std::chrono::steady_clock::now();
  const double now = time();
  // Last frame's buffer, emptied: a thousand part moves a frame need no
  // reallocation.
  std::vector<Event> events = std::move(last_.events);
  events.clear();

  // 1-3. Actions queued for this frame, then input, hand and interaction.
  auto due = commands_.begin();
  while (due != commands_.end() && due->frame <= frame_) {
    scene_.set_local_pose(due->part, due->X_QP);
    ++due;
  }
  commands_.erase(commands_.begin(), due);
  if (hook_) hook_(*this, frame_, now);
  for (const FrameHook& hook : hooks_) hook(*this, frame_, now);

  // 4. Commit the poses.
  commit(events, now);

  // 5. Collision pipeline.
  const auto collision_start = std::chrono::steady_clock::now();
  const collision::StepResult& result = world_->step();
  const double collision_ms = ms_since(collision_start);
  if (world_->plans_version() != plans_version_) update_plans();

  // 6. Events: differences from the last frame.
  contact_events(result, events, now);
  // Removed parts' pairs have ended now; their names are no longer needed.
  for (const collision::PartId id : removed_) {
    collision_names_.erase(id);
    std::erase_if(contact_stats_by_id_,
                  [id](const auto& kv) { return kv.first.first == id || kv.first.second == id; });
  }
  removed_.clear();
  timer_events(events, now);
  region_events(events, now);
  for (const EventFilter& filter : filters_) filter(*this, events);

  // 7. Subscribers react; what they change is committed by the next frame.
  bus_.publish(events);

  // 8. Output.
  state_hash_ = current_state_hash();
  last_.frame = frame_;
  last_.time = now;
  last_.state_hash = state_hash_;
  last_.collision = result.stats;
  for (const Event& e : events) {
    if (e.kind != EventKind::kPartMoved || settings_.timeline_part_moved) {
      report_.events.push_back(e);
    }
  }
  last_.events = std::move(events);
  report_stale_ = true;
  ++frame_;
  report_.frames = frame_;
  report_.parts = scene_.part_count();
  report_.state_hash = state_hash_;
  report_.timings.push_back({collision_ms, ms_since(frame_start)});
  return last_;
}

const Report& Simulation::report() const {
  // Contacts and plans are copied into the report when it is read, not every
  // frame: both grow with the pairs ever met.
  if (report_stale_) {
    report_.contacts.clear();
    for (const auto& [key, stats] : contact_stats_) report_.contacts.push_back(stats);
    report_.plans.clear();
    report_.plans.reserve(plans_.size());
    for (const auto& [names, plan] : plans_) {
      report_.plans.push_back({.a = names.first,
                               .b = names.second,
                               .level = std::string(collision::level_name(plan.level)),
                               .method = plan.method
                                             ? std::string(collision::method_name(*plan.method))
                                             : std::string(),
                               .convex_level = plan.convex_level,
                               .front = plan.front,
                               .max_size = plan.max_size,
                               .reason = *plan_reasons_[plan.reason]});
    }
    std::sort(report_.plans.begin(), report_.plans.end(),
              [](const PairPlanReport& x, const PairPlanReport& y) {
                return std::tie(x.a, x.b) < std::tie(y.a, y.b);
              });
    report_stale_ = false;
  }
  return report_;
}

void Simulation::update_plans() {
  const std::vector<collision::PairPlan> made = world_->plans_since(plans_version_);
  plans_version_ = world_->plans_version();
  for (const collision::PairPlan& plan : made) {
    std::string a = collision_names_.at(plan.pair.a);
    std::string b = collision_names_.at(plan.pair.b);
    if (b < a) std::swap(a, b);
    const auto [reason, added] =
        plan_reason_ids_.emplace(plan.reason, static_cast<std::uint32_t>(plan_reasons_.size()));
    if (added) plan_reasons_.push_back(&reason->first);
    plans_[{std::move(a), std::move(b)}] = KeptPlan{.level = plan.level,
                                                    .method = plan.method,
                                                    .convex_level = plan.convex_level,
                                                    .front = plan.front,
                                                    .max_size = plan.max_size,
                                                    .reason = reason->second};
  }
}

std::uint64_t Simulation::run(std::uint64_t frames, bool progress) {
  std::unique_ptr<ProgressMeter> meter;
  if (progress) meter = std::make_unique<ProgressMeter>(frames);
  std::uint64_t done = 0;
  while (done < frames && !paused_) {
    step();
    ++done;
    if (meter) meter->update(done);
  }
  if (meter) meter->finish();
  return done;
}

}  // namespace dovetail::engine
