#include "broadphase/uniform_grid.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
#include <stdexcept>

#include "broadphase/proxy_pairs.h"
#include "broadphase/scene_bulk.h"

namespace dovetail::collision {

namespace {

/// The size of a box for choosing cells: its mean edge length.
Real box_size(const Aabb& box) { return ((box.max - box.min).sum()) / 3; }

bool contains(const auto& range, std::int32_t x, std::int32_t y, std::int32_t z) {
  return range.lo[0] <= x && x <= range.hi[0] && range.lo[1] <= y && y <= range.hi[1] &&
         range.lo[2] <= z && z <= range.hi[2];
}

std::uint64_t cell_count(const auto& range) {
  std::uint64_t n = 1;
  for (int k = 0; k < 3; ++k) n *= static_cast<std::uint64_t>(range.hi[k] - range.lo[k] + 1);
  return n;
}

}  // namespace

UniformGrid::UniformGrid(Real cell) : fixed_cell_(cell) {
  if (!(cell >= 0) || !std::isfinite(cell)) {
    throw std::invalid_argument("UniformGrid: cell size must be finite and >= 0");
  }
}

std::int32_t UniformGrid::index_of(Real x) const {
  Real f = std::floor(x * inverse_cell_);
  if (!(f >= -kCellLimit)) f = -kCellLimit;
  if (f > kCellLimit) f = kCellLimit;
  return static_cast<std::int32_t>(f);
}

UniformGrid::Range UniformGrid::range_of(const Aabb& box) const {
  Range r;
  for (int k = 0; k < 3; ++k) {
    r.lo[k] = index_of(box.min[k]);
    r.hi[k] = index_of(box.max[k]);
  }
  return r;
}

std::uint64_t UniformGrid::cell_key(const CellIndex& c) {
  // 21 bits per axis, each index offset to [1, 2^21 - 1], so no key is 0.
  constexpr std::int64_t kOffset = std::int64_t{1} << 20;
  return (static_cast<std::uint64_t>(c[0] + kOffset) << 42) |
         (static_cast<std::uint64_t>(c[1] + kOffset) << 21) |
         static_cast<std::uint64_t>(c[2] + kOffset);
}

// ---- updates

void UniformGrid::add(ProxyId id, const Aabb& box) {
  if (id >= entries_.size()) {
    entries_.resize(std::size_t{id} + 1);
    boxes_.resize(std::size_t{id} + 1);
  }
  Entry& e = entries_[id];
  assert(e.slot == kNone);
  boxes_[id] = box;
  e.slot = static_cast<std::uint32_t>(present_.size());
  present_.push_back(id);
  size_sum_ += box_size(box);
  if (ready_) register_box(id);
}

void UniformGrid::remove(ProxyId id) {
  assert(id < entries_.size() && entries_[id].slot != kNone);
  if (ready_) unregister_box(id);
  Entry& e = entries_[id];
  const ProxyId last = present_.back();
  present_[e.slot] = last;
  entries_[last].slot = e.slot;
  present_.pop_back();
  e.slot = kNone;
  size_sum_ -= box_size(boxes_[id]);
}

void UniformGrid::move(ProxyId id, const Aabb& box) {
  assert(id < entries_.size() && entries_[id].slot != kNone);
  size_sum_ += box_size(box) - box_size(boxes_[id]);
  boxes_[id] = box;
  if (!ready_) return;
  // Most moves stay within the same cells: nothing to do but the range check.
  const Range range = range_of(box);
  if (range == entries_[id].range) return;
  update_box(id, range);
}

// ---- registration

void UniformGrid::register_box(ProxyId id) {
  Entry& e = entries_[id];
  e.range = range_of(boxes_[id]);
  if (cell_count(e.range) > kMaxCells) {
    e.big_slot = static_cast<std::uint32_t>(big_.size());
    big_.push_back(id);
    return;
  }
  e.big_slot = kNone;
  for (std::int32_t x = e.range.lo[0]; x <= e.range.hi[0]; ++x) {
    for (std::int32_t y = e.range.lo[1]; y <= e.range.hi[1]; ++y) {
      for (std::int32_t z = e.range.lo[2]; z <= e.range.hi[2]; ++z) enter({x, y, z}, id);
    }
  }
}

void UniformGrid::unregister_box(ProxyId id) {
  Entry& e = entries_[id];
  if (e.big_slot != kNone) {
    const ProxyId last = big_.back();
    big_[e.big_slot] = last;
    entries_[last].big_slot = e.big_slot;
    big_.pop_back();
    e.big_slot = kNone;
    return;
  }
  for (std::int32_t x = e.range.lo[0]; x <= e.range.hi[0]; ++x) {
    for (std::int32_t y = e.range.lo[1]; y <= e.range.hi[1]; ++y) {
      for (std::int32_t z = e.range.lo[2]; z <= e.range.hi[2]; ++z) leave({x, y, z}, id);
    }
  }
}

void UniformGrid::update_box(ProxyId id, const Range& range) {
  Entry& e = entries_[id];
  if (e.big_slot != kNone || cell_count(range) > kMaxCells) {
    unregister_box(id);
    register_box(id);
    return;
  }
  // Leave the cells only the old range covers, enter those only the new one covers.
  const Range old = e.range;
  for (std::int32_t x = old.lo[0]; x <= old.hi[0]; ++x) {
    for (std::int32_t y = old.lo[1]; y <= old.hi[1]; ++y) {
      for (std::int32_t z = old.lo[2]; z <= old.hi[2]; ++z) {
        if (!contains(range, x, y, z)) leave({x, y, z}, id);
      }
    }
  }
  for (std::int32_t x = range.lo[0]; x <= range.hi[0]; ++x) {
    for (std::int32_t y = range.lo[1]; y <= range.hi[1]; ++y) {
      for (std::int32_t z = range.lo[2]; z <= range.hi[2]; ++z) {
        if (!contains(old, x, y, z)) enter({x, y, z}, id);
      }
    }
  }
  e.range = range;
}

void UniformGrid::grow_table() {
  const std::size_t capacity = table_.empty() ? 1024 : 2 * table_.size();
  table_.assign(capacity, Slot{});
  mask_ = capacity - 1;
  shift_ = 64 - std::countr_zero(capacity);
  for (std::uint32_t c = 0; c < cells_.size(); ++c) {
    if (cells_[c].key == 0) continue;
    std::size_t i = home(cells_[c].key);
    while (table_[i].key != 0) i = (i + 1) & mask_;
    table_[i] = {cells_[c].key, c};
  }
}

void UniformGrid::enter(const CellIndex& c, ProxyId id) {
  ++stats_.cells;
  const std::uint64_t key = cell_key(c);
  if (2 * (table_count_ + 1) > table_.size()) grow_table();
  std::size_t i = home(key);
  while (table_[i].key != 0 && table_[i].key != key) i = (i + 1) & mask_;
  if (table_[i].key == 0) {
    // A new cell, from the free list when there is one.
    std::uint32_t index;
    if (!free_cells_.empty()) {
      index = free_cells_.back();
      free_cells_.pop_back();
    } else {
      index = static_cast<std::uint32_t>(cells_.size());
      cells_.emplace_back();
    }
    Cell& fresh = cells_[index];
    fresh.key = key;
    fresh.at = c;
    fresh.ids.clear();
    fresh.crowded_slot = kNone;
    table_[i] = {key, index};
    ++table_count_;
  }
  const std::uint32_t index = table_[i].cell;
  Cell& cell = cells_[index];
  cell.ids.push_back(id);
  if (cell.ids.size() == 2) {
    cell.crowded_slot = static_cast<std::uint32_t>(crowded_.size());
    crowded_.push_back(index);
  }
}

void UniformGrid::leave(const CellIndex& c, ProxyId id) {
  ++stats_.cells;
  const std::uint64_t key = cell_key(c);
  std::size_t i = home(key);
  while (table_[i].key != key) i = (i + 1) & mask_;
  const std::uint32_t index = table_[i].cell;
  Cell& cell = cells_[index];
  // Swap-remove the id from the cell.
  auto it = std::find(cell.ids.begin(), cell.ids.end(), id);
  assert(it != cell.ids.end());
  *it = cell.ids.back();
  cell.ids.pop_back();
  if (cell.ids.size() == 1) {
    const std::uint32_t moved = crowded_.back();
    crowded_[cell.crowded_slot] = moved;
    cells_[moved].crowded_slot = cell.crowded_slot;
    crowded_.pop_back();
    cell.crowded_slot = kNone;
  }
  if (!cell.ids.empty()) return;
  // The cell is empty: free it, and close the hole in the table by backward shift.
  cell.key = 0;
  free_cells_.push_back(index);
  --table_count_;
  std::size_t hole = i;
  for (std::size_t j = (hole + 1) & mask_; table_[j].key != 0; j = (j + 1) & mask_) {
    const std::size_t h = home(table_[j].key);
    const bool movable = hole <= j ? (h <= hole || h > j) : (h <= hole && h > j);
    if (movable) {
      table_[hole] = table_[j];
      hole = j;
    }
  }
  table_[hole].key = 0;
}

// ---- cell size

void UniformGrid::choose_cell() {
  const std::size_t n = present_.size();
  Real cell = fixed_cell_;
  if (cell == 0 && n > 0) {
    // Twice the median box size: most boxes then cover 1 to 2 cells per axis.
    scratch_.resize(n);
    for (std::size_t i = 0; i < n; ++i) scratch_[i] = box_size(boxes_[present_[i]]);
    std::nth_element(scratch_.begin(), scratch_.begin() + n / 2, scratch_.end());
    cell = 2 * scratch_[n / 2];
    // Never so small that the bulk of the scene (2nd to 98th percentile of the
    // box centres) spans more than 2^18 cells on an axis.
    Real spread = 0;
    for (int k = 0; k < 3; ++k) {
      spread = std::max(spread, detail::bulk_of_centres(boxes_, present_, k, scratch_).spread);
    }
    cell = std::max(cell, spread / (1 << 18));
    // All boxes are points at one place: any cell size will do.
    if (!(cell > 0) || !std::isfinite(cell)) cell = 1;
  }
  if (cell == 0) cell = 1;
  cell_ = cell;
  inverse_cell_ = 1 / cell;
  // The running sum of sizes, recomputed exactly (it drifts by rounding).
  size_sum_ = 0;
  for (ProxyId id : present_) size_sum_ += box_size(boxes_[id]);
  chosen_mean_size_ = n > 0 ? size_sum_ / static_cast<Real>(n) : 0;
}

void UniformGrid::register_all() {
  // Forget every cell and register the present boxes again.
  table_.clear();
  table_count_ = 0;
  cells_.clear();
  free_cells_.clear();
  crowded_.clear();
  big_.clear();
  grow_table();
  for (ProxyId id : present_) register_box(id);
}

// ---- query

void UniformGrid::pairs(std::vector<ProxyPair>& out) {
  const std::size_t n = present_.size();
  if (!ready_) {
    if (n == 0) {
      out.clear();
      last_stats_ = stats_;
      stats_ = {};
      return;
    }
    choose_cell();
    ready_ = true;
    register_all();
  } else if (fixed_cell_ == 0 && n > 0) {
    // (The slack of 1e-9 cells absorbs the rounding of the running sum, so a
    // scene of points does not re-choose on noise.)
    const Real mean = size_sum_ / static_cast<Real>(n);
    const Real slack = cell_ * Real(1e-9);
    if (mean > 2 * chosen_mean_size_ + slack || mean < chosen_mean_size_ / 2 - slack) {
      choose_cell();
      register_all();
    }
  }

  out.clear();
  // Pairs sharing a cell, each reported from the cell of its intersection's lower corner.
  std::uint64_t tests = 0;
  for (std::uint32_t index : crowded_) {
    const Cell& cell = cells_[index];
    const std::size_t m = cell.ids.size();
    for (std::size_t i = 0; i + 1 < m; ++i) {
      const ProxyId a = cell.ids[i];
      const Aabb& box_a = boxes_[a];
      for (std::size_t j = i + 1; j < m; ++j) {
        const ProxyId b = cell.ids[j];
        const Aabb& box_b = boxes_[b];
        ++tests;
        if (!box_a.overlaps(box_b)) continue;
        if (index_of(std::max(box_a.min.x(), box_b.min.x())) != cell.at[0] ||
            index_of(std::max(box_a.min.y(), box_b.min.y())) != cell.at[1] ||
            index_of(std::max(box_a.min.z(), box_b.min.z())) != cell.at[2]) {
          continue;
        }
        out.push_back(a < b ? ProxyPair{a, b} : ProxyPair{b, a});
      }
    }
  }
  stats_.cells += crowded_.size();
  // Boxes too big for the grid: against every box (each big pair once).
  for (ProxyId big : big_) {
    const Aabb& box_big = boxes_[big];
    for (ProxyId other : present_) {
      if (other == big || (entries_[other].big_slot != kNone && other < big)) continue;
      ++tests;
      if (box_big.overlaps(boxes_[other])) {
        out.push_back(big < other ? ProxyPair{big, other} : ProxyPair{other, big});
      }
    }
  }
  stats_.box_tests += tests;
  drop_fixed_pairs(out);
  detail::sort_proxy_pairs(out, sort_keys_);
  last_stats_ = stats_;
  stats_ = {};
}

}  // namespace dovetail::collision
