#pragma once
/// \file simulation.h
/// The fixed-step simulation loop over a Scene and a collision::CollisionWorld.
///
/// Why: one frame runs the same stages in the same order every time (see
/// docs/engine.md, "One frame, in order"): queued actions and the frame hook
/// (where input, hand and interaction plug in), commit of the poses,
/// collision pipeline, events, output. Simulated time is frame * time step,
/// never wall time, so a headless run goes as fast as it can and gives the
/// same report on any machine and at any thread count.

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "dovetail/collision/collision_world.h"
#include "dovetail/engine/events.h"
#include "dovetail/engine/report.h"
#include "dovetail/engine/scene.h"

namespace dovetail::engine {

/// Loop settings.
struct SimulationSettings {
  double time_step = 1.0 / 90.0;  ///< seconds per frame (90 Hz)
  int collision_threads = 1;      ///< worker threads of the pipeline; 0 = all cores
  /// The polygon-level hierarchy of every pair; unset (the default): planned
  /// per pair by the collision world (collision::PairPlan).
  std::optional<collision::Method> method{};
  /// The accuracy the collision world keeps, in metres: 0 (the default),
  /// exact; > 0, contact may be reported up to this far apart
  /// (collision::WorldSettings::tolerance).
  double tolerance = 0;
  collision::BroadphaseMethod broadphase = collision::BroadphaseMethod::kSweepAndPrune;
  bool convex_level = true;
  /// Pairs (default): the pipeline only decides whether parts touch, enough
  /// for events and reports; triangles: every intersecting triangle pair,
  /// for highlighting or contact analysis (much dearer for deep penetration).
  collision::ContactDetail contacts = collision::ContactDetail::kPairs;
  /// Whether part_moved events go into the report's timeline (they are
  /// always delivered to subscribers). Off by default: a moving part gives one per frame.
  bool timeline_part_moved = false;
  /// Failure capture of the collision pipeline (collision::WorldSettings::capture,
  /// ::cross_check): not owned, nullptr = off.
  collision::CaptureSink* capture = nullptr;
  std::optional<collision::Method> cross_check{};
};

/// "Set part X's local pose at frame k": applied at the start of frame k, in
/// the order the commands were queued.
struct PoseCommand {
  std::uint64_t frame = 0;
  std::string part{};
  Transform X_QP{};  ///< the new local pose
};

/// An axis-aligned box in the world frame.
struct Box {
  collision::Vec3 min = collision::Vec3::Zero();
  collision::Vec3 max = collision::Vec3::Zero();
};

/// A named region: parts whose world box overlaps it are inside (touching
/// counts); entering and leaving are events.
struct Region {
  std::string name{};
  Box box{};
  /// Only these parts (by name); empty: every part with a collision mesh.
  std::vector<std::string> parts{};
};

/// What one frame did.
struct FrameResult {
  std::uint64_t frame = 0;    ///< the frame just simulated
  double time = 0;            ///< its simulated time
  std::vector<Event> events;  ///< in delivery order
  std::uint64_t state_hash = 0;
  collision::StepStats collision{};
};

/// Runs a scene frame by frame.
class Simulation {
 public:
  /// Called at the start of each frame, after the queued pose commands and
  /// before the commit: the place for input, hand and interaction.
  using FrameHook = std::function<void(Simulation&, std::uint64_t frame, double time)>;
  /// Called with each frame's events after the engine has made them and
  /// before anyone sees them: the place where upper layers turn contacts
  /// into their own events (a hand segment touching a part) or add events.
  /// The events are sorted (event_less) after all filters have run.
  using EventFilter = std::function<void(Simulation&, std::vector<Event>& events)>;

  explicit Simulation(Scene scene, const SimulationSettings& settings = {});
  ~Simulation();
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;
  Simulation(Simulation&&) noexcept;
  Simulation& operator=(Simulation&&) noexcept;

  /// The scene; changes made between frames are committed by the next frame
  /// (parts added or removed there are added to or removed from the collision world).
  Scene& scene() { return scene_; }
  const Scene& scene() const { return scene_; }
  EventBus& events() { return bus_; }
  const SimulationSettings& settings() const { return settings_; }

  /// Queues a pose command; throws SceneError for an unknown part (and step()
  /// throws it at frame k if the part was removed by then).
  void queue_pose(const PoseCommand& command);
  /// Sets the one frame hook that runs before the added ones (replacing the
  /// last one set this way; hooks added with add_frame_hook stay).
  void set_frame_hook(FrameHook hook) { hook_ = std::move(hook); }
  /// Adds a frame hook; they run after the set one, in the order added.
  void add_frame_hook(FrameHook hook) { hooks_.push_back(std::move(hook)); }
  /// Adds an event filter; filters run in the order added.
  void add_event_filter(EventFilter filter) { filters_.push_back(std::move(filter)); }
  /// Adds a note to the report (see Report::notes).
  void add_note(std::string note) { report_.notes.push_back(std::move(note)); }
  /// A timer firing in the first frame whose time reaches `time`.
  void add_timer(const std::string& name, double time);
  /// Adds a region; throws SceneError for a duplicate name or an unknown part.
  void add_region(const Region& region);

  /// Builds the collision hulls and hierarchies of the current parts now
  /// (CollisionWorld::prepare) rather than on first contact; optional, the
  /// frames are the same either way.
  void prepare() { world_->prepare(); }

  /// Simulates one frame, paused or not.
  const FrameResult& step();
  /// Simulates up to `frames` frames; stops early when paused (a subscriber
  /// may pause). With progress, shows a ProgressMeter on stderr. Returns the
  /// frames simulated.
  std::uint64_t run(std::uint64_t frames, bool progress = false);
  void set_paused(bool paused) { paused_ = paused; }
  bool paused() const { return paused_; }

  /// Frames simulated so far; the next frame's number.
  std::uint64_t frame() const { return frame_; }
  /// Simulated time of the next frame.
  double time() const { return static_cast<double>(frame_) * settings_.time_step; }
  /// state_hash of the scene after the last frame (of the initial scene before any).
  std::uint64_t state_hash() const { return state_hash_; }
  const FrameResult& last_frame() const { return last_; }
  /// The report so far (timeline, contact statistics, state hash, timings).
  const Report& report() const;

  /// The collision world, for settings such as interest and levels of detail.
  collision::CollisionWorld& collision_world() { return *world_; }
  /// The collision world, read only (for instance its last step's contacts).
  const collision::CollisionWorld& collision_world() const { return *world_; }
  /// The collision id of a part, or an invalid id when it has no collision mesh.
  collision::PartId collision_id(PartId part) const;

 private:
  struct Registered;
  void commit(std::vector<Event>& events, double now);
  /// The state hash of the scene now: the one commit() folded while it read
  /// every pose, unless the scene has changed since (subscribers may move
  /// parts).
  std::uint64_t current_state_hash() const;
  void contact_events(const collision::StepResult& step, std::vector<Event>& events, double now);
  void timer_events(std::vector<Event>& events, double now);
  void region_events(std::vector<Event>& events, double now);
  void update_plans();

  Scene scene_;
  SimulationSettings settings_;
  std::unique_ptr<collision::CollisionWorld> world_;
  EventBus bus_;
  FrameHook hook_;
  std::vector<FrameHook> hooks_;
  std::vector<EventFilter> filters_;
  std::vector<PoseCommand> commands_;  ///< sorted by frame, stable
  struct Timer {
    std::string name;
    double time = 0;
    bool fired = false;
  };
  std::vector<Timer> timers_;
  struct RegionState {
    Region region;
    std::vector<std::string> inside;  ///< sorted part names inside now
  };
  std::vector<RegionState> regions_;
  /// Per scene slot: the registered part, if any.
  std::vector<std::unique_ptr<Registered>> registered_;
  /// Hash of collision ids and of pairs of them, for the lookups below.
  struct IdHash {
    static std::uint64_t mix(std::uint64_t x) {
      x ^= x >> 31;
      x *= 0x7fb5d329728ea185ull;
      x ^= x >> 27;
      return x;
    }
    static std::uint64_t word(collision::PartId id) {
      return (std::uint64_t{id.index} << 32) | id.generation;
    }
    std::size_t operator()(collision::PartId id) const { return mix(word(id)); }
    std::size_t operator()(const std::pair<collision::PartId, collision::PartId>& p) const {
      return mix(word(p.first) ^ mix(word(p.second)));
    }
  };
  /// The scene name of every part in the collision world.
  std::unordered_map<collision::PartId, std::string, IdHash> collision_names_;
  std::vector<collision::PartId> removed_;  ///< removed since the last collision step
  /// Contact statistics by (a, b) names.
  std::map<std::pair<std::string, std::string>, PairContactStats> contact_stats_;
  /// The same statistics by the pair's collision ids, while both parts live.
  std::unordered_map<std::pair<collision::PartId, collision::PartId>, PairContactStats*, IdHash>
      contact_stats_by_id_;
  /// Pair plans by (a, b) names, kept after a part is removed.
  /// Hashed, not ordered: a crowded scene meets new pairs every frame; the
  /// report sorts them by name when it is read.
  struct NamePairHash {
    std::size_t operator()(const std::pair<std::string, std::string>& p) const {
      const std::size_t h = std::hash<std::string>{}(p.first);
      return h ^ (std::hash<std::string>{}(p.second) + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2));
    }
  };
  /// A pair's plan as kept until the report is read: a PairPlanReport
  /// without the names (the key's) and with its reason an index into
  /// plan_reasons_ (a crowded scene plans a hundred thousand pairs with a
  /// handful of sentences).
  struct KeptPlan {
    collision::LevelOfDetail level = collision::LevelOfDetail::kExact;
    std::optional<collision::Method> method{};
    bool convex_level = false;
    bool front = false;
    double max_size = 0;
    std::uint32_t reason = 0;
  };
  std::unordered_map<std::pair<std::string, std::string>, KeptPlan, NamePairHash> plans_;
  std::vector<const std::string*> plan_reasons_;  ///< the keys of plan_reason_ids_
  std::unordered_map<std::string, std::uint32_t> plan_reason_ids_;
  std::uint64_t plans_version_ = 0;
  std::uint64_t frame_ = 0;
  bool paused_ = false;
  std::uint64_t state_hash_ = 0;
  std::uint64_t committed_hash_ = 0;                      ///< state hash of the scene commit() read
  std::uint64_t committed_revision_ = ~std::uint64_t{0};  ///< Scene::revision() then; none yet
  FrameResult last_;
  /// The report; its contacts and plans are filled in by report() when a
  /// frame has passed since (report_stale_).
  mutable Report report_;
  mutable bool report_stale_ = false;
};

}  // namespace dovetail::engine
