#include "broadphase/multi_box_pruning.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "broadphase/proxy_pairs.h"
#include "broadphase/scene_bulk.h"

namespace dovetail::collision {

MultiBoxPruning::MultiBoxPruning(Real column) : fixed_column_(column) {
  if (!(column >= 0) || !std::isfinite(column)) {
    throw std::invalid_argument("MultiBoxPruning: the column edge must be finite and >= 0");
  }
}

// ---- updates: O(1), the columns are rebuilt by pairs()

void MultiBoxPruning::add(ProxyId id, const Aabb& box) {
  if (id >= slot_.size()) {
    boxes_.resize(std::size_t{id} + 1);
    slot_.resize(std::size_t{id} + 1, kNone);
    stamp_.resize(std::size_t{id} + 1, 0);
  }
  assert(slot_[id] == kNone);
  boxes_[id] = box;
  slot_[id] = static_cast<std::uint32_t>(present_.size());
  present_.push_back(id);
}

void MultiBoxPruning::remove(ProxyId id) {
  assert(id < slot_.size() && slot_[id] != kNone);
  const ProxyId last = present_.back();
  present_[slot_[id]] = last;
  slot_[last] = slot_[id];
  present_.pop_back();
  slot_[id] = kNone;
}

void MultiBoxPruning::move(ProxyId id, const Aabb& box) {
  assert(id < slot_.size() && slot_[id] != kNone);
  boxes_[id] = box;
}

// ---- layout

void MultiBoxPruning::choose_layout() {
  const std::size_t n = present_.size();
  scratch_.resize(n);
  // The bulk of the scene: 2nd to 98th percentile of the box centres per axis.
  Real low[3], spread[3];
  for (int k = 0; k < 3; ++k) {
    const detail::Bulk bulk = detail::bulk_of_centres(boxes_, present_, k, scratch_);
    low[k] = bulk.low;
    // Coordinates near the largest doubles can overflow a centre or a spread.
    spread[k] = bulk.spread <= std::numeric_limits<Real>::max() ? bulk.spread
                                                                : std::numeric_limits<Real>::max();
  }
  s_ = 0;
  for (int k = 1; k < 3; ++k) {
    if (spread[k] > spread[s_]) s_ = k;
  }
  u_ = s_ == 0 ? 1 : 0;
  v_ = s_ == 2 ? 1 : 2;

  // The column edge: a multiple of the median extent across the sweep axis.
  Real extent_sum = 0;
  for (std::size_t i = 0; i < n; ++i) {
    scratch_[i] = extent_across(boxes_[present_[i]]);
    extent_sum += scratch_[i];
  }
  std::nth_element(scratch_.begin(), scratch_.begin() + static_cast<std::ptrdiff_t>(n / 2),
                   scratch_.end());
  Real column = fixed_column_ > 0 ? fixed_column_ : kColumnFactor * scratch_[n / 2];
  const Real across = std::max(spread[u_], spread[v_]);
  if (!(column > 0) || !std::isfinite(column)) column = across > 0 ? across / 8 : 1;
  // Columns cover the bulk, half a column beyond it; at most kMaxColumnsPerAxis
  // per axis, and (chosen automatically) at most max(16, n) in all.
  column = std::max(column, across / (kMaxColumnsPerAxis - 2));
  if (!(column > 0) || !std::isfinite(column)) column = 1;
  const auto count = [&](Real extent) {
    const Real columns = std::min(std::floor(extent / column), Real{kMaxColumnsPerAxis - 2});
    return static_cast<std::uint64_t>(columns) + 2;
  };
  const std::uint64_t limit =
      fixed_column_ > 0 ? std::uint64_t{1} << 20 : std::max<std::uint64_t>(16, n);
  while (count(spread[u_]) * count(spread[v_]) > limit) column *= 2;
  column_ = column;
  inverse_column_ = 1 / column;
  columns_u_ = static_cast<std::uint32_t>(count(spread[u_]));
  columns_v_ = static_cast<std::uint32_t>(count(spread[v_]));
  origin_u_ = low[u_] - column / 2;
  origin_v_ = low[v_] - column / 2;
  chosen_count_ = n;
  chosen_mean_extent_ = extent_sum / static_cast<Real>(n);
}

std::uint16_t MultiBoxPruning::column_of(Real x, Real origin, std::uint32_t columns) const {
  // floor((x - origin) / edge), clamped to [0, columns - 1]: monotone in x.
  const Real t = (x - origin) * inverse_column_;
  if (!(t > 0)) return 0;
  if (t >= static_cast<Real>(columns - 1)) return static_cast<std::uint16_t>(columns - 1);
  return static_cast<std::uint16_t>(t);
}

Real MultiBoxPruning::extent_across(const Aabb& b) const {
  return ((b.max[u_] - b.min[u_]) + (b.max[v_] - b.min[v_])) / 2;
}

bool MultiBoxPruning::span_all(bool allow_drift) {
  const std::size_t n = sequence_.size();
  spans_.resize(n);
  big_.clear();
  Real extent_sum = 0;
  std::size_t outside = 0;
  const Real end_u = origin_u_ + static_cast<Real>(columns_u_) * column_;
  const Real end_v = origin_v_ + static_cast<Real>(columns_v_) * column_;
  for (std::size_t i = 0; i < n; ++i) {
    const Aabb& b = boxes_[sequence_[i]];
    extent_sum += extent_across(b);
    const Real cu = (b.min[u_] + b.max[u_]) / 2, cv = (b.min[v_] + b.max[v_]) / 2;
    outside += (cu < origin_u_) | (cu > end_u) | (cv < origin_v_) | (cv > end_v);
    Span span{
        column_of(b.min[u_], origin_u_, columns_u_), column_of(b.max[u_], origin_u_, columns_u_),
        column_of(b.min[v_], origin_v_, columns_v_), column_of(b.max[v_], origin_v_, columns_v_)};
    const std::uint32_t cover =
        std::uint32_t{span.u1 - span.u0 + 1u} * std::uint32_t{span.v1 - span.v0 + 1u};
    if (cover > kMaxColumnsPerBox) {
      span.u0 = kBig;
      big_.push_back(sequence_[i]);
    }
    spans_[i] = span;
  }
  if (!allow_drift) return true;
  const Real mean = extent_sum / static_cast<Real>(n);
  const Real slack = column_ * Real(1e-9);
  const bool size_drift = fixed_column_ == 0 && (mean > 2 * chosen_mean_extent_ + slack ||
                                                 mean < chosen_mean_extent_ / 2 - slack);
  return !(size_drift || n > 2 * chosen_count_ || 2 * n < chosen_count_ || outside > n / 8 + 16);
}

// ---- the frame

void MultiBoxPruning::fill_columns() {
  // Counting sort of the boxes by column; a box goes into every column it covers.
  const std::size_t columns = std::size_t{columns_u_} * columns_v_;
  offsets_.assign(columns + 1, 0);
  for (const Span& span : spans_) {
    if (span.u0 == kBig) continue;
    for (std::uint32_t cu = span.u0; cu <= span.u1; ++cu) {
      for (std::uint32_t cv = span.v0; cv <= span.v1; ++cv) ++offsets_[cu * columns_v_ + cv + 1];
    }
  }
  for (std::size_t c = 1; c <= columns; ++c) offsets_[c] += offsets_[c - 1];
  cursor_.assign(offsets_.begin(), offsets_.end() - 1);
  entries_.resize(offsets_[columns]);
  for (std::size_t i = 0; i < sequence_.size(); ++i) {
    const Span& span = spans_[i];
    if (span.u0 == kBig) continue;
    const Aabb& b = boxes_[sequence_[i]];
    const Entry e{b.min[s_], b.max[s_],    b.min[u_], b.max[u_], b.min[v_],
                  b.max[v_], sequence_[i], span.u0,   span.v0};
    for (std::uint32_t cu = span.u0; cu <= span.u1; ++cu) {
      for (std::uint32_t cv = span.v0; cv <= span.v1; ++cv) {
        entries_[cursor_[cu * columns_v_ + cv]++] = e;
      }
    }
  }
}

void MultiBoxPruning::sort_columns() {
  // Insertion sort along the sweep axis: the boxes came in last frame's
  // order, so each column is nearly sorted. A column far from sorted (the
  // first frame, a rebuilt layout) goes to std::sort after a budget of moves.
  const std::size_t columns = std::size_t{columns_u_} * columns_v_;
  for (std::size_t c = 0; c < columns; ++c) {
    Entry* first = entries_.data() + offsets_[c];
    Entry* last = entries_.data() + offsets_[c + 1];
    const std::size_t m = static_cast<std::size_t>(last - first);
    if (m < 2) continue;
    std::uint64_t moves = 0;
    const std::uint64_t budget = 8 * std::uint64_t{m} + 64;
    bool sorted = true;
    for (Entry* i = first + 1; i < last; ++i) {
      if (!(i->lo_s < (i - 1)->lo_s)) continue;
      const Entry e = *i;
      Entry* j = i;
      do {
        *j = *(j - 1);
        --j;
        ++moves;
      } while (j > first && e.lo_s < (j - 1)->lo_s);
      *j = e;
      if (moves > budget) {
        sorted = false;
        break;
      }
    }
    if (!sorted) {
      std::sort(first, last, [](const Entry& a, const Entry& b) { return a.lo_s < b.lo_s; });
    }
    stats_.swaps += moves;
  }
}

template <typename Key>
std::size_t MultiBoxPruning::sweep_columns(std::vector<Key>& keys, int bits) {
  // In each column, every box against the boxes after it that start before it
  // ends along the sweep axis; branch-free: every tested pair is written past
  // the found ones and counted only when the boxes overlap across the sweep
  // axis and this column holds the lower corner of their intersection. The
  // pairs are written as the sort's keys, so they are not packed again.
  const std::size_t columns = std::size_t{columns_u_} * columns_v_;
  std::uint64_t tests = 0;
  std::size_t found = 0;
  for (std::size_t c = 0; c < columns; ++c) {
    const std::size_t begin = offsets_[c], end = offsets_[c + 1];
    if (end - begin < 2) continue;
    ++stats_.cells;
    const auto cu = static_cast<std::uint16_t>(c / columns_v_);
    const auto cv = static_cast<std::uint16_t>(c % columns_v_);
    const Entry* e = entries_.data();
    for (std::size_t i = begin; i + 1 < end; ++i) {
      const Entry a = e[i];
      // Room for every box after this one (the sort's half of `keys` stays free).
      if (2 * (found + end - i) > keys.size()) keys.resize(4 * (found + end - i) + 128);
      Key* dst = keys.data() + found;
      std::size_t j = i + 1;
      std::size_t hits = 0;
      for (; j < end && e[j].lo_s <= a.hi_s; ++j) {
        const Entry& b = e[j];
        const bool hit = (a.lo_u <= b.hi_u) & (b.lo_u <= a.hi_u) & (a.lo_v <= b.hi_v) &
                         (b.lo_v <= a.hi_v) & (std::max(a.u0, b.u0) == cu) &
                         (std::max(a.v0, b.v0) == cv);
        dst[hits] = detail::pair_key<Key>(a.id, b.id, bits);
        hits += hit;
      }
      tests += j - i - 1;
      found += hits;
    }
  }
  stats_.box_tests += tests;
  return found;
}

template <typename Key>
std::size_t MultiBoxPruning::test_big_boxes(std::vector<Key>& keys, std::size_t found, int bits) {
  // Each big box against every other box; two big boxes once.
  for (ProxyId big : big_) {
    const Aabb& box = boxes_[big];
    for (std::size_t i = 0; i < sequence_.size(); ++i) {
      const ProxyId other = sequence_[i];
      if (other == big || (spans_[i].u0 == kBig && other < big)) continue;
      ++stats_.box_tests;
      if (!box.overlaps(boxes_[other])) continue;
      if (2 * (found + 1) > keys.size()) keys.resize(4 * (found + 1) + 128);
      keys[found++] = detail::pair_key<Key>(big, other, bits);
    }
  }
  return found;
}

template <typename Key>
void MultiBoxPruning::find_pairs(std::vector<Key>& keys, int bits, std::vector<ProxyPair>& out) {
  std::size_t found = sweep_columns(keys, bits);
  found = test_big_boxes(keys, found, bits);
  detail::pairs_from_keys(keys, found, bits, sort_keys_.counts, out);
}

void MultiBoxPruning::pairs(std::vector<ProxyPair>& out) {
  out.clear();
  if (present_.empty()) {
    last_stats_ = stats_;
    stats_ = {};
    return;
  }
  // This frame's boxes in last frame's sweep order, new ones last.
  if (++frame_ == 0) {
    std::fill(stamp_.begin(), stamp_.end(), 0);
    frame_ = 1;
  }
  sequence_.clear();
  for (ProxyId id : order_) {
    if (slot_[id] != kNone && stamp_[id] != frame_) {
      stamp_[id] = frame_;
      sequence_.push_back(id);
    }
  }
  for (ProxyId id : present_) {
    if (stamp_[id] != frame_) {
      stamp_[id] = frame_;
      sequence_.push_back(id);
    }
  }

  if (!ready_) {
    choose_layout();
    ready_ = true;
  }
  if (!span_all(true)) {
    choose_layout();
    span_all(false);
  }
  fill_columns();
  sort_columns();
  // Keys of 32 bits while every id fits in 16 bits.
  const int bits = std::max(1, static_cast<int>(std::bit_width(slot_.size() - 1)));
  if (bits <= 16) {
    find_pairs(sort_keys_.narrow, bits, out);
  } else {
    find_pairs(sort_keys_.wide, bits, out);
  }
  drop_fixed_pairs(out);

  // Next frame's order: each box where its first column holds it, then the big ones.
  order_.clear();
  const std::size_t columns = std::size_t{columns_u_} * columns_v_;
  for (std::size_t c = 0; c < columns; ++c) {
    const auto cu = static_cast<std::uint16_t>(c / columns_v_);
    const auto cv = static_cast<std::uint16_t>(c % columns_v_);
    for (std::size_t i = offsets_[c]; i < offsets_[c + 1]; ++i) {
      if (entries_[i].u0 == cu && entries_[i].v0 == cv) order_.push_back(entries_[i].id);
    }
  }
  order_.insert(order_.end(), big_.begin(), big_.end());
  last_stats_ = stats_;
  stats_ = {};
}

}  // namespace dovetail::collision
