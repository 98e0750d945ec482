#include "dovetail/engine/events.h"

#include <algorithm>
#include <tuple>

namespace dovetail::engine {

std::string_view event_kind_name(EventKind kind) {
  switch (kind) {
    case EventKind::kTimer:
      return "timer";
    case EventKind::kPartMoved:
      return "part_moved";
    case EventKind::kContactBegin:
      return "contact_begin";
    case EventKind::kContactEnd:
      return "contact_end";
    case EventKind::kRegionEnter:
      return "region_enter";
    case EventKind::kRegionLeave:
      return "region_leave";
    case EventKind::kHandContactBegin:
      return "hand_contact_begin";
    case EventKind::kHandContactEnd:
      return "hand_contact_end";
    case EventKind::kGrasp:
      return "grasp";
    case EventKind::kRelease:
      return "release";
    case EventKind::kSlideBegin:
      return "slide_begin";
    case EventKind::kSlideEnd:
      return "slide_end";
    case EventKind::kMate:
      return "mate";
  }
  return "unknown";
}

bool event_less(const Event& x, const Event& y) {
  return std::tie(x.frame, x.kind, x.a, x.b) < std::tie(y.frame, y.kind, y.a, y.b);
}

EventBus::SubscriptionId EventBus::subscribe(EventKind kind, Handler handler) {
  subscriptions_.push_back({next_id_, false, kind, std::move(handler)});
  return next_id_++;
}

EventBus::SubscriptionId EventBus::subscribe_all(Handler handler) {
  subscriptions_.push_back({next_id_, true, EventKind::kTimer, std::move(handler)});
  return next_id_++;
}

void EventBus::unsubscribe(SubscriptionId id) {
  std::erase_if(subscriptions_, [id](const Subscription& s) { return s.id == id; });
}

void EventBus::publish(std::vector<Event>& events) {
  // Sorted as by event_less, comparing names only where needed: by frame and
  // kind first, then each run of one kind by its names unless it is in order
  // already (the simulation emits part moves by name).
  const auto by_kind = [](const Event& x, const Event& y) {
    return std::tie(x.frame, x.kind) < std::tie(y.frame, y.kind);
  };
  if (!std::is_sorted(events.begin(), events.end(), by_kind)) {
    std::stable_sort(events.begin(), events.end(), by_kind);
  }
  for (auto run = events.begin(); run != events.end();) {
    const auto end = std::find_if(run, events.end(), [&](const Event& e) {
      return e.frame != run->frame || e.kind != run->kind;
    });
    if (!std::is_sorted(run, end, event_less)) std::sort(run, end, event_less);
    run = end;
  }
  // A handler may subscribe or unsubscribe; deliver to a snapshot.
  const std::vector<Subscription> current = subscriptions_;
  for (const Event& event : events) {
    for (const Subscription& s : current) {
      if (s.all || s.kind == event.kind) s.handler(event);
    }
  }
}

}  // namespace dovetail::engine
