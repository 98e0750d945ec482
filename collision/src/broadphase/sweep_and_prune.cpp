#include "broadphase/sweep_and_prune.h"

#include <algorithm>
#include <bit>
#include <cassert>

#include "broadphase/proxy_pairs.h"

namespace dovetail::collision {

namespace {

std::uint64_t pair_key(std::uint32_t a, std::uint32_t b) {
  return a < b ? (std::uint64_t{a} << 32) | b : (std::uint64_t{b} << 32) | a;
}

}  // namespace

// ---- PairSet

void SweepAndPrune::PairSet::clear() {
  for (std::uint64_t key : dense_) {
    std::size_t i = home(key);
    while (slots_[i].key != key) i = (i + 1) & mask_;
    slots_[i].key = kEmpty;
    degree_[key >> 32] = 0;
    degree_[static_cast<std::uint32_t>(key)] = 0;
  }
  dense_.clear();
}

void SweepAndPrune::PairSet::grow() {
  const std::size_t capacity = slots_.empty() ? 64 : 2 * slots_.size();
  slots_.assign(capacity, Slot{});
  mask_ = capacity - 1;
  shift_ = 64 - std::countr_zero(capacity);
  for (std::uint32_t index = 0; index < dense_.size(); ++index) {
    std::size_t i = home(dense_[index]);
    while (slots_[i].key != kEmpty) i = (i + 1) & mask_;
    slots_[i] = {dense_[index], index};
  }
}

void SweepAndPrune::PairSet::insert(std::uint32_t a, std::uint32_t b) {
  if (2 * (dense_.size() + 1) > slots_.size()) grow();
  const std::uint64_t key = pair_key(a, b);
  std::size_t i = home(key);
  while (slots_[i].key != kEmpty) {
    if (slots_[i].key == key) return;
    i = (i + 1) & mask_;
  }
  slots_[i] = {key, static_cast<std::uint32_t>(dense_.size())};
  dense_.push_back(key);
  if (std::max(a, b) >= degree_.size()) degree_.resize(std::size_t{std::max(a, b)} + 1, 0);
  ++degree_[a];
  ++degree_[b];
}

void SweepAndPrune::PairSet::erase(std::uint32_t a, std::uint32_t b) {
  // Most boxes overlap nothing: then there is nothing to look up.
  if (a >= degree_.size() || b >= degree_.size() || degree_[a] == 0 || degree_[b] == 0) return;
  const std::uint64_t key = pair_key(a, b);
  std::size_t i = home(key);
  while (slots_[i].key != key) {
    if (slots_[i].key == kEmpty) return;
    i = (i + 1) & mask_;
  }
  --degree_[a];
  --degree_[b];
  // Swap-remove the key from the dense list and re-point the slot of the key moved.
  const std::uint32_t index = slots_[i].index;
  const std::uint64_t last = dense_.back();
  dense_.pop_back();
  if (last != key) {
    dense_[index] = last;
    std::size_t m = home(last);
    while (slots_[m].key != last) m = (m + 1) & mask_;
    slots_[m].index = index;
  }
  // Backward-shift deletion: pull later members of the probe run into the hole.
  std::size_t hole = i;
  for (std::size_t j = (hole + 1) & mask_; slots_[j].key != kEmpty; j = (j + 1) & mask_) {
    const std::size_t h = home(slots_[j].key);
    const bool movable = hole <= j ? (h <= hole || h > j) : (h <= hole && h > j);
    if (movable) {
      slots_[hole] = slots_[j];
      hole = j;
    }
  }
  slots_[hole].key = kEmpty;
}

template <typename Keep>
void SweepAndPrune::PairSet::filter(Keep keep) {
  std::vector<std::uint64_t> kept;
  kept.reserve(dense_.size());
  for (std::uint64_t key : dense_) {
    if (keep(key)) kept.push_back(key);
  }
  clear();
  for (std::uint64_t key : kept) {
    insert(static_cast<std::uint32_t>(key >> 32), static_cast<std::uint32_t>(key));
  }
}

// ---- SweepAndPrune

std::uint32_t SweepAndPrune::new_handle() {
  if (!free_handles_.empty()) {
    const std::uint32_t h = free_handles_.back();
    free_handles_.pop_back();
    return h;
  }
  const auto h = static_cast<std::uint32_t>(id_of_.size());
  id_of_.push_back(0);
  alive_.push_back(0);
  sorted_in_.push_back(0);
  for (std::vector<Real>& b : bounds_) b.resize(2 * id_of_.size());
  return h;
}

void SweepAndPrune::add(ProxyId id, const Aabb& box) {
  if (id >= handle_of_.size()) handle_of_.resize(std::size_t{id} + 1, kNone);
  assert(handle_of_[id] == kNone);
  const std::uint32_t h = new_handle();
  handle_of_[id] = h;
  id_of_[h] = id;
  alive_[h] = 1;
  sorted_in_[h] = 0;
  for (int k = 0; k < 3; ++k) {
    bounds_[k][2 * h] = box.min[k];
    bounds_[k][2 * h + 1] = box.max[k];
  }
  added_.push_back(h);
  ++count_;
}

void SweepAndPrune::remove(ProxyId id) {
  assert(id < handle_of_.size() && handle_of_[id] != kNone);
  const std::uint32_t h = handle_of_[id];
  handle_of_[id] = kNone;
  alive_[h] = 0;
  if (sorted_in_[h] != 0) {
    ++dead_in_arrays_;  // compacted out by the next pairs()
  } else {
    // Added and removed between two pairs(): never reached the arrays.
    added_.erase(std::find(added_.begin(), added_.end(), h));
    free_handles_.push_back(h);
  }
  --count_;
}

void SweepAndPrune::move(ProxyId id, const Aabb& box) {
  assert(id < handle_of_.size() && handle_of_[id] != kNone);
  const std::uint32_t h = handle_of_[id];
  for (int k = 0; k < 3; ++k) {
    bounds_[k][2 * h] = box.min[k];
    bounds_[k][2 * h + 1] = box.max[k];
  }
  moved_ = true;
}

void SweepAndPrune::remove_dead() {
  // Pairs of removed boxes leave the set.
  overlapping_.filter([this](std::uint64_t key) {
    return alive_[key >> 32] != 0 && alive_[static_cast<std::uint32_t>(key)] != 0;
  });
  // Their endpoints leave the arrays; the others keep their order.
  for (std::vector<Endpoint>& axis : axes_) {
    std::erase_if(axis, [this](const Endpoint& e) { return alive_[e.key >> 1] == 0; });
  }
  // Their handles become free, lowest handed out first.
  for (std::uint32_t h = static_cast<std::uint32_t>(id_of_.size()); h-- > 0;) {
    if (sorted_in_[h] != 0 && alive_[h] == 0) {
      sorted_in_[h] = 0;
      free_handles_.push_back(h);
    }
  }
  dead_in_arrays_ = 0;
}

void SweepAndPrune::rebuild() {
  // Every present box into the arrays, fully sorted by (value, end flag, handle).
  for (int k = 0; k < 3; ++k) {
    std::vector<Endpoint>& axis = axes_[k];
    axis.clear();
    for (std::uint32_t h = 0; h < id_of_.size(); ++h) {
      if (alive_[h] == 0) continue;
      axis.push_back({bounds_[k][2 * h], 2 * h});
      axis.push_back({bounds_[k][2 * h + 1], 2 * h + 1});
    }
    std::sort(axis.begin(), axis.end(), [](const Endpoint& p, const Endpoint& q) {
      if (p.value != q.value) return p.value < q.value;
      if ((p.key & 1) != (q.key & 1)) return (p.key & 1) < (q.key & 1);
      return p.key < q.key;
    });
  }
  for (std::uint32_t h = 0; h < id_of_.size(); ++h) sorted_in_[h] = alive_[h];
  added_.clear();
  // Sweep along x: a box begins while the boxes in `active_` have not ended.
  overlapping_.clear();
  active_.clear();
  for (const Endpoint& e : axes_[0]) {
    const std::uint32_t h = e.key >> 1;
    if ((e.key & 1) != 0) {
      active_.erase(std::find(active_.begin(), active_.end(), h));
      continue;
    }
    for (std::uint32_t other : active_) {
      ++stats_.box_tests;
      if (overlap_on(1, h, other) && overlap_on(2, h, other)) overlapping_.insert(h, other);
    }
    active_.push_back(h);
  }
}

void SweepAndPrune::sort_axis(int axis) {
  std::vector<Endpoint>& ep = axes_[axis];
  const int k1 = (axis + 1) % 3;
  const int k2 = (axis + 2) % 3;
  // q goes before p: smaller value, or the same value and q a begin, p an end.
  const auto before = [](const Endpoint& q, const Endpoint& p) {
    return q.value < p.value || (q.value == p.value && (q.key & 1) < (p.key & 1));
  };
  std::uint64_t swaps = 0;
  for (std::size_t i = 1; i < ep.size(); ++i) {
    if (!before(ep[i], ep[i - 1])) continue;
    const Endpoint q = ep[i];
    std::size_t j = i;
    do {
      const Endpoint& p = ep[j - 1];
      // A begin passing an end starts a 1-D overlap, an end passing a begin ends one.
      if ((q.key & 1) != (p.key & 1)) {
        const std::uint32_t a = q.key >> 1;
        const std::uint32_t b = p.key >> 1;
        if ((q.key & 1) == 0) {
          ++stats_.box_tests;
          if (overlap_on(k1, a, b) && overlap_on(k2, a, b)) overlapping_.insert(a, b);
        } else {
          overlapping_.erase(a, b);
        }
      }
      ep[j] = p;
      --j;
      ++swaps;
    } while (j > 0 && before(q, ep[j - 1]));
    ep[j] = q;
  }
  stats_.swaps += swaps;
}

void SweepAndPrune::merge_added() {
  // Pairs of each new box: every box already in the arrays, and the new boxes before it.
  std::uint64_t tests = 0;
  const auto test = [&](std::uint32_t a, std::uint32_t b) {
    ++tests;
    if (overlap_on(0, a, b) && overlap_on(1, a, b) && overlap_on(2, a, b)) {
      overlapping_.insert(a, b);
    }
  };
  for (std::size_t i = 0; i < added_.size(); ++i) {
    const std::uint32_t a = added_[i];
    for (std::uint32_t h = 0; h < id_of_.size(); ++h) {
      if (sorted_in_[h] != 0) test(a, h);
    }
    for (std::size_t j = 0; j < i; ++j) test(a, added_[j]);
  }
  stats_.box_tests += tests;
  // Their endpoints merged in at their sorted places.
  const auto by_key = [](const Endpoint& p, const Endpoint& q) {
    return p.value < q.value || (p.value == q.value && (p.key & 1) < (q.key & 1));
  };
  for (int k = 0; k < 3; ++k) {
    fresh_.clear();
    for (std::uint32_t h : added_) {
      fresh_.push_back({bounds_[k][2 * h], 2 * h});
      fresh_.push_back({bounds_[k][2 * h + 1], 2 * h + 1});
    }
    std::sort(fresh_.begin(), fresh_.end(), [&](const Endpoint& p, const Endpoint& q) {
      return by_key(p, q) || (!by_key(q, p) && p.key < q.key);
    });
    merged_.resize(axes_[k].size() + fresh_.size());
    std::merge(axes_[k].begin(), axes_[k].end(), fresh_.begin(), fresh_.end(), merged_.begin(),
               by_key);
    axes_[k].swap(merged_);
  }
  for (std::uint32_t h : added_) sorted_in_[h] = 1;
  added_.clear();
}

void SweepAndPrune::pairs(std::vector<ProxyPair>& out) {
  if (dead_in_arrays_ > 0) remove_dead();
  // Many new boxes (or the first frame): sort from scratch. Otherwise the
  // boxes present are re-sorted by insertion sort, then the few new ones are
  // tested against all and merged in.
  const std::size_t sorted_count = axes_[0].size() / 2;
  if (!added_.empty() && 32 * added_.size() > sorted_count) {
    rebuild();
  } else {
    if (moved_) {
      for (int k = 0; k < 3; ++k) {
        for (Endpoint& e : axes_[k]) e.value = bounds_[k][e.key];
      }
    }
    for (int k = 0; k < 3; ++k) sort_axis(k);
    if (!added_.empty()) merge_added();
  }
  moved_ = false;

  out.clear();
  out.reserve(overlapping_.keys().size());
  for (std::uint64_t key : overlapping_.keys()) {
    const ProxyId a = id_of_[key >> 32];
    const ProxyId b = id_of_[static_cast<std::uint32_t>(key)];
    if (both_fixed(a, b)) continue;
    out.push_back(a < b ? ProxyPair{a, b} : ProxyPair{b, a});
  }
  detail::sort_proxy_pairs(out, sort_keys_);
  last_stats_ = stats_;
  stats_ = {};
}

}  // namespace dovetail::collision
