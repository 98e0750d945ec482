#pragma once
/// \file events.h
/// Typed simulation events and the bus that delivers them.
///
/// Why: scripts, expectations and reports react to what changed in a frame
/// (a contact began, a part entered a region, a timer fired), not to raw
/// contact sets. Each frame's events are sorted by (frame, kind, a, b) before
/// anyone sees them, so the order never depends on worker threads or on the
/// order of internal containers.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace dovetail::engine {

/// What happened. The order of the enumerators is the delivery order within
/// a frame; kinds after kRegionLeave are produced by the interaction layer.
enum class EventKind : std::uint8_t {
  kTimer,             ///< a timer fired: a = timer name
  kPartMoved,         ///< a part's world pose changed: a = part
  kContactBegin,      ///< a and b (a < b by name) touch now, not in the last frame
  kContactEnd,        ///< a and b touched in the last frame, not now
  kRegionEnter,       ///< part a entered region b
  kRegionLeave,       ///< part a left region b
  kHandContactBegin,  ///< hand segment a (its part, `hand.index_distal`) touches part b now
  kHandContactEnd,    ///< hand segment a touched part b in the last frame, not now
  kGrasp,             ///< the hand grasped part a; b: the grasp type
  kRelease,           ///< the hand released part a; b: why ("opened", "overstretched")
  kSlideBegin,        ///< held part a began sliding on part b
  kSlideEnd,          ///< held part a stopped sliding on part b
  kMate,              ///< part a snapped onto part b
};

/// Number of event kinds.
inline constexpr std::size_t kEventKindCount = static_cast<std::size_t>(EventKind::kMate) + 1;

/// The kind's name in reports: "contact_begin", "region_enter", ...
std::string_view event_kind_name(EventKind kind);

/// One event.
struct Event {
  EventKind kind = EventKind::kTimer;
  std::uint64_t frame = 0;  ///< the frame in which it happened
  double time = 0;          ///< simulated time of that frame, frame * time step
  std::string a{};          ///< first part (or the timer's name)
  std::string b{};          ///< second part or the region; empty when not used
  friend bool operator==(const Event&, const Event&) = default;
};

/// The delivery order: frame, kind, a, b.
bool event_less(const Event& x, const Event& y);

/// Subscribers by kind; each frame's events are delivered in event_less
/// order, and for one event to its subscribers in subscription order.
class EventBus {
 public:
  using Handler = std::function<void(const Event&)>;
  /// Identifies a subscription, for unsubscribe.
  using SubscriptionId = std::uint64_t;

  /// Calls `handler` for every event of `kind`.
  SubscriptionId subscribe(EventKind kind, Handler handler);
  /// Calls `handler` for every event.
  SubscriptionId subscribe_all(Handler handler);
  void unsubscribe(SubscriptionId id);

  /// Sorts `events` (event_less) and delivers them.
  void publish(std::vector<Event>& events);

 private:
  struct Subscription {
    SubscriptionId id = 0;
    bool all = false;
    EventKind kind = EventKind::kTimer;
    Handler handler;
  };
  std::vector<Subscription> subscriptions_;
  SubscriptionId next_id_ = 1;
};

}  // namespace dovetail::engine
