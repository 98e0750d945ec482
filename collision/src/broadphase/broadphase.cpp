#include "dovetail/collision/broadphase.h"

#include <algorithm>
#include <array>
#include <stdexcept>

#include "broadphase/brute_broadphase.h"
#include "broadphase/multi_box_pruning.h"
#include "broadphase/octree.h"
#include "broadphase/sweep_and_prune.h"
#include "broadphase/uniform_grid.h"

namespace dovetail::collision {

namespace {

constexpr std::array<BroadphaseMethod, 5> kBroadphases = {
    BroadphaseMethod::kBrute, BroadphaseMethod::kSweepAndPrune, BroadphaseMethod::kGrid,
    BroadphaseMethod::kOctree, BroadphaseMethod::kMultiBoxPruning};
constexpr std::array<std::string_view, 5> kBroadphaseNames = {"brute", "sap", "grid", "octree",
                                                              "mbp"};

}  // namespace

std::string_view broadphase_name(BroadphaseMethod method) {
  for (std::size_t i = 0; i < kBroadphases.size(); ++i) {
    if (kBroadphases[i] == method) return kBroadphaseNames[i];
  }
  return "unknown";
}

std::optional<BroadphaseMethod> parse_broadphase(std::string_view name) {
  for (std::size_t i = 0; i < kBroadphases.size(); ++i) {
    if (kBroadphaseNames[i] == name) return kBroadphases[i];
  }
  return std::nullopt;
}

std::span<const BroadphaseMethod> all_broadphases() { return kBroadphases; }

void Broadphase::set_fixed(ProxyId id, bool fixed) {
  if (id >= fixed_.size()) {
    if (!fixed) return;
    fixed_.resize(std::size_t{id} + 1, 0);
  }
  const std::uint8_t mark = fixed ? 1 : 0;
  if (fixed_[id] == mark) return;
  fixed_[id] = mark;
  if (fixed)
    ++fixed_count_;
  else
    --fixed_count_;
}

void Broadphase::drop_fixed_pairs(std::vector<ProxyPair>& out) const {
  if (fixed_count_ < 2) return;
  std::erase_if(out, [this](const ProxyPair& p) { return both_fixed(p.a, p.b); });
}

std::unique_ptr<Broadphase> make_broadphase(BroadphaseMethod method,
                                            const BroadphaseSettings& settings) {
  switch (method) {
    case BroadphaseMethod::kBrute:
      return std::make_unique<BruteBroadphase>();
    case BroadphaseMethod::kSweepAndPrune:
      return std::make_unique<SweepAndPrune>();
    case BroadphaseMethod::kGrid:
      return std::make_unique<UniformGrid>(settings.grid_cell);
    case BroadphaseMethod::kOctree:
      return std::make_unique<Octree>(settings.octree_leaf_size, settings.octree_max_depth);
    case BroadphaseMethod::kMultiBoxPruning:
      return std::make_unique<MultiBoxPruning>(settings.mbp_column);
  }
  throw std::invalid_argument("make_broadphase: unknown method");
}

}  // namespace dovetail::collision
