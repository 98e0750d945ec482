#include "broadphase/octree.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <stdexcept>

#include "broadphase/proxy_pairs.h"

namespace dovetail::collision {

Octree::Octree(int leaf_size, int max_depth) : leaf_size_(leaf_size), max_depth_(max_depth) {
  if (leaf_size < 1 || max_depth < 0 || max_depth > 40) {
    throw std::invalid_argument("Octree: leaf size must be >= 1 and max depth in [0, 40]");
  }
}

// ---- geometry

bool Octree::inside(const Node& node, const Aabb& box) const {
  // A face on the root's boundary is closed; a face on a split plane is open,
  // so a box touching a split plane belongs to the node that owns the plane.
  const Node& root = nodes_[0];
  for (int k = 0; k < 3; ++k) {
    const bool low_ok =
        node.lo[k] == root.lo[k] ? box.min[k] >= node.lo[k] : box.min[k] > node.lo[k];
    const bool high_ok =
        node.hi[k] == root.hi[k] ? box.max[k] <= node.hi[k] : box.max[k] < node.hi[k];
    if (!low_ok || !high_ok) return false;
  }
  return true;
}

std::uint32_t Octree::child_for(const Node& node, const Aabb& box) {
  std::uint32_t child = 0;
  for (int k = 0; k < 3; ++k) {
    if (box.max[k] < node.mid[k]) continue;
    if (box.min[k] > node.mid[k]) {
      child |= 1u << k;
      continue;
    }
    return kNone;
  }
  return node.first_child + child;
}

bool Octree::reaches(const Aabb& box, const Node& node) {
  return box.min.x() <= node.hi.x() && node.lo.x() <= box.max.x() && box.min.y() <= node.hi.y() &&
         node.lo.y() <= box.max.y() && box.min.z() <= node.hi.z() && node.lo.z() <= box.max.z();
}

// ---- updates

void Octree::add(ProxyId id, const Aabb& box) {
  if (id >= entries_.size()) {
    entries_.resize(std::size_t{id} + 1);
    boxes_.resize(std::size_t{id} + 1);
  }
  Entry& e = entries_[id];
  assert(e.present_slot == kNone);
  boxes_[id] = box;
  e.present_slot = static_cast<std::uint32_t>(present_.size());
  present_.push_back(id);
  if (ready_) insert(id);
}

void Octree::remove(ProxyId id) {
  assert(id < entries_.size() && entries_[id].present_slot != kNone);
  if (ready_) detach(id);
  Entry& e = entries_[id];
  const ProxyId last = present_.back();
  present_[e.present_slot] = last;
  entries_[last].present_slot = e.present_slot;
  present_.pop_back();
  e.present_slot = kNone;
}

void Octree::move(ProxyId id, const Aabb& box) {
  assert(id < entries_.size() && entries_[id].present_slot != kNone);
  boxes_[id] = box;
  if (!ready_) return;
  const Entry& e = entries_[id];
  const Node& node = nodes_[e.node];
  // Stay when the box still fits the node and no child of it.
  const bool stay =
      e.outside ? !inside(nodes_[0], box)
                : inside(node, box) && (node.first_child == kNone || child_for(node, box) == kNone);
  if (stay) return;
  detach(id);
  insert(id);
}

// ---- tree maintenance

std::uint32_t Octree::allocate_children() {
  if (!free_blocks_.empty()) {
    const std::uint32_t first = free_blocks_.back();
    free_blocks_.pop_back();
    return first;
  }
  const auto first = static_cast<std::uint32_t>(nodes_.size());
  nodes_.resize(nodes_.size() + 8);
  return first;
}

void Octree::place(ProxyId id, std::uint32_t node) {
  Entry& e = entries_[id];
  e.node = node;
  e.slot = static_cast<std::uint32_t>(nodes_[node].ids.size());
  nodes_[node].ids.push_back(id);
  for (std::uint32_t n = node; n != kNone; n = nodes_[n].parent) ++nodes_[n].subtree;
}

void Octree::insert(ProxyId id) {
  const Aabb& box = boxes_[id];
  Entry& e = entries_[id];
  // Outside the root cell: stays at the root.
  e.outside = !inside(nodes_[0], box);
  if (e.outside) {
    ++outside_;
    place(id, 0);
    return;
  }
  // Down to the deepest existing node that holds the box.
  std::uint32_t node = 0;
  while (nodes_[node].first_child != kNone) {
    ++stats_.cells;
    const std::uint32_t child = child_for(nodes_[node], box);
    if (child == kNone) break;
    node = child;
  }
  place(id, node);
  const Node& n = nodes_[node];
  if (n.first_child == kNone && n.ids.size() > static_cast<std::size_t>(leaf_size_) &&
      n.depth < max_depth_) {
    split(node);
  }
}

void Octree::split(std::uint32_t node) {
  const std::uint32_t first = allocate_children();
  // Eight children, bit k of the index set for the upper half along axis k.
  for (std::uint32_t c = 0; c < 8; ++c) {
    Node& child = nodes_[first + c];
    const Node& parent = nodes_[node];
    for (int k = 0; k < 3; ++k) {
      const bool upper = ((c >> k) & 1u) != 0;
      child.lo[k] = upper ? parent.mid[k] : parent.lo[k];
      child.hi[k] = upper ? parent.hi[k] : parent.mid[k];
    }
    child.mid = (child.lo + child.hi) / 2;
    child.first_child = kNone;
    child.parent = node;
    child.depth = parent.depth + 1;
    child.subtree = 0;
    child.ids.clear();
  }
  nodes_[node].first_child = first;
  // Boxes clear of every split plane move down one level; the others stay.
  std::vector<ProxyId> staying;
  for (ProxyId id : nodes_[node].ids) {
    const std::uint32_t child = child_for(nodes_[node], boxes_[id]);
    if (child == kNone) {
      entries_[id].slot = static_cast<std::uint32_t>(staying.size());
      staying.push_back(id);
      continue;
    }
    Entry& e = entries_[id];
    e.node = child;
    e.slot = static_cast<std::uint32_t>(nodes_[child].ids.size());
    nodes_[child].ids.push_back(id);
    ++nodes_[child].subtree;
  }
  nodes_[node].ids.swap(staying);
  // A child that received too many splits in turn.
  for (std::uint32_t c = 0; c < 8; ++c) {
    const Node& child = nodes_[first + c];
    if (child.ids.size() > static_cast<std::size_t>(leaf_size_) && child.depth < max_depth_) {
      split(first + c);
    }
  }
}

void Octree::gather(std::uint32_t node, std::uint32_t into) {
  const std::uint32_t first = nodes_[node].first_child;
  if (first == kNone) return;
  for (std::uint32_t c = first; c < first + 8; ++c) {
    gather(c, into);
    for (ProxyId id : nodes_[c].ids) {
      Entry& e = entries_[id];
      e.node = into;
      e.slot = static_cast<std::uint32_t>(nodes_[into].ids.size());
      nodes_[into].ids.push_back(id);
    }
    nodes_[c].ids.clear();
  }
  free_blocks_.push_back(first);
  nodes_[node].first_child = kNone;
}

void Octree::collapse(std::uint32_t node) { gather(node, node); }

void Octree::detach(ProxyId id) {
  Entry& e = entries_[id];
  const std::uint32_t node = e.node;
  // Swap-remove from the node's list.
  std::vector<ProxyId>& ids = nodes_[node].ids;
  const ProxyId last = ids.back();
  ids[e.slot] = last;
  entries_[last].slot = e.slot;
  ids.pop_back();
  if (e.outside) --outside_;
  e.node = kNone;
  e.outside = false;
  // Fewer boxes up the chain; merge the highest subtree that became small.
  const std::uint32_t merge_limit = static_cast<std::uint32_t>(leaf_size_ / 2);
  std::uint32_t merge = kNone;
  for (std::uint32_t n = node; n != kNone; n = nodes_[n].parent) {
    --nodes_[n].subtree;
    if (nodes_[n].subtree <= merge_limit && nodes_[n].first_child != kNone) merge = n;
  }
  if (merge != kNone) collapse(merge);
}

void Octree::rebuild() {
  const std::size_t n = present_.size();
  // Scene bounds: all boxes, unless a few far outliers would blow the root up;
  // then the 1st to 99th percentile of the box bounds, widened by half.
  Vec3 lo = Vec3::Constant(0), hi = Vec3::Constant(0);
  if (n > 0) {
    lo = boxes_[present_[0]].min;
    hi = boxes_[present_[0]].max;
    for (ProxyId id : present_) {
      lo = lo.cwiseMin(boxes_[id].min);
      hi = hi.cwiseMax(boxes_[id].max);
    }
    const std::size_t cut = n / 100;
    scratch_.resize(n);
    for (int k = 0; k < 3; ++k) {
      for (std::size_t i = 0; i < n; ++i) scratch_[i] = boxes_[present_[i]].min[k];
      std::nth_element(scratch_.begin(), scratch_.begin() + cut, scratch_.end());
      const Real low = scratch_[cut];
      for (std::size_t i = 0; i < n; ++i) scratch_[i] = boxes_[present_[i]].max[k];
      std::nth_element(scratch_.begin(), scratch_.begin() + (n - 1 - cut), scratch_.end());
      const Real high = scratch_[n - 1 - cut];
      const Real bulk = high - low;
      if (hi[k] - lo[k] > 4 * bulk) {
        lo[k] = low - bulk / 2;
        hi[k] = high + bulk / 2;
      }
    }
  }
  // A cube around them, a little larger, so cells stay cubic.
  const Vec3 center = (lo + hi) / 2;
  Real half = ((hi - lo) / 2).maxCoeff() * Real(1.05);
  if (!(half > 0) || !std::isfinite(half)) half = 1;

  nodes_.assign(1, Node{});
  free_blocks_.clear();
  outside_ = 0;
  Node& root = nodes_[0];
  root.lo = center - Vec3::Constant(half);
  root.hi = center + Vec3::Constant(half);
  root.mid = center;
  for (ProxyId id : present_) insert(id);
  outside_after_rebuild_ = outside_;
  ready_ = true;
}

// ---- query

void Octree::visit(std::uint32_t index, std::size_t candidates_begin, std::vector<ProxyPair>& out) {
  ++stats_.cells;
  const Node& node = nodes_[index];
  const std::size_t candidates_end = candidates_.size();
  std::uint64_t tests = 0;
  // Branch-free: every tested pair is written past the found ones, and
  // counted as found only when the boxes overlap (a test that mostly fails
  // would otherwise mispredict its branch often).
  std::size_t& found = found_;
  const auto test = [&](ProxyId a, const Aabb& box_a, ProxyId b, const Aabb& box_b) {
    ++tests;
    const bool hit = box_a.overlaps(box_b);
    if (found == out.size()) out.resize(2 * found + 64);
    out[found] = a < b ? ProxyPair{a, b} : ProxyPair{b, a};
    found += hit;
  };
  // The node's boxes with each other, then with the ancestors' boxes reaching in.
  const std::size_t m = node.ids.size();
  for (std::size_t i = 0; i < m; ++i) {
    const ProxyId a = node.ids[i];
    const Aabb box_a = boxes_[a];
    for (std::size_t j = i + 1; j < m; ++j) test(a, box_a, node.ids[j], boxes_[node.ids[j]]);
    for (std::size_t c = candidates_begin; c < candidates_end; ++c)
      test(a, box_a, candidates_[c].id, candidates_[c].box);
  }
  stats_.box_tests += tests;
  if (node.first_child == kNone) return;
  // Each non-empty child with the candidates that reach into its cell.
  for (std::uint32_t c = node.first_child; c < node.first_child + 8; ++c) {
    const Node& child = nodes_[c];
    if (child.subtree == 0) continue;
    const std::size_t start = candidates_.size();
    for (std::size_t i = candidates_begin; i < candidates_end; ++i) {
      const Candidate k = candidates_[i];
      if (reaches(k.box, child)) candidates_.push_back(k);
    }
    for (ProxyId id : node.ids) {
      if (reaches(boxes_[id], child)) candidates_.push_back({boxes_[id], id});
    }
    visit(c, start, out);
    candidates_.resize(start);
  }
}

void Octree::pairs(std::vector<ProxyPair>& out) {
  out.clear();
  const std::size_t n = present_.size();
  const std::size_t allowance = std::max<std::size_t>(static_cast<std::size_t>(leaf_size_), n / 32);
  if (!ready_ || outside_ > outside_after_rebuild_ + allowance) {
    rebuild();
  }
  candidates_.clear();
  found_ = 0;
  visit(0, 0, out);
  out.resize(found_);
  drop_fixed_pairs(out);
  detail::sort_proxy_pairs(out, sort_keys_);
  last_stats_ = stats_;
  stats_ = {};
}

}  // namespace dovetail::collision
