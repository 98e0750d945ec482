#pragma once
/// \file broadphase.h
/// Object level: which of n moving axis-aligned boxes overlap.
///
/// Why: the first stage of the collision pipeline must be output sensitive,
/// O(n + s) for s overlapping pairs, using the coherence between frames and
/// assuming nothing about velocities. Every method sits behind one incremental
/// interface (add, remove, move, then pairs), so the pipeline, the command line
/// and the benchmarks choose one at run time, and `kBrute` (all n^2/2 box
/// tests) is the reference the others must match exactly.

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "dovetail/collision/types.h"

namespace dovetail::collision {

/// A closed axis-aligned box: boxes that only touch overlap.
struct Aabb {
  Vec3 min = Vec3::Zero();
  Vec3 max = Vec3::Zero();

  /// All six comparisons, joined without short-circuit: no branch for a
  /// predictor to miss where most tests fail in no pattern (crowded scenes).
  bool overlaps(const Aabb& o) const {
    return (min.x() <= o.max.x()) & (o.min.x() <= max.x()) & (min.y() <= o.max.y()) &
           (o.min.y() <= max.y()) & (min.z() <= o.max.z()) & (o.min.z() <= max.z());
  }
};

/// Identifies one box in a broad phase. Chosen by the caller: small, dense,
/// unique among the boxes present (the pipeline uses part indices).
using ProxyId = std::uint32_t;

/// An overlapping pair, a < b.
struct ProxyPair {
  ProxyId a = 0;
  ProxyId b = 0;
  friend bool operator==(const ProxyPair&, const ProxyPair&) = default;
  friend auto operator<=>(const ProxyPair&, const ProxyPair&) = default;
};

/// Object-level methods.
enum class BroadphaseMethod { kBrute, kSweepAndPrune, kGrid, kOctree, kMultiBoxPruning };

/// Command-line name: brute, sap, grid, octree, mbp.
std::string_view broadphase_name(BroadphaseMethod method);
std::optional<BroadphaseMethod> parse_broadphase(std::string_view name);
std::span<const BroadphaseMethod> all_broadphases();

/// Work counters of the last `pairs()` call (and the updates before it).
struct BroadphaseStats {
  std::uint64_t box_tests = 0;  ///< full box-box overlap tests
  std::uint64_t swaps = 0;      ///< sweep and prune: endpoint swaps
  std::uint64_t cells = 0;      ///< grid / octree: cells touched
};

/// Settings; the defaults suit a scene whose boxes change size slowly.
struct BroadphaseSettings {
  /// Grid: cell edge length; 0 = chosen from the boxes present at the first
  /// `pairs()` (and re-chosen when the mean box size drifts by more than 2x).
  Real grid_cell = 0;
  /// Octree: subdivide a cell holding more than this many boxes...
  int octree_leaf_size = 8;
  /// ... until this depth.
  int octree_max_depth = 10;
  /// Multi-box pruning: column edge across the sweep axis; 0 = chosen from
  /// the boxes (8 times their median extent across it).
  Real mbp_column = 0;
};

/// An incremental broad phase. Not thread-safe: one owner updates and queries it.
class Broadphase {
 public:
  virtual ~Broadphase() = default;

  /// Adds box `id` (not present yet).
  virtual void add(ProxyId id, const Aabb& box) = 0;
  /// Removes box `id` (present).
  virtual void remove(ProxyId id) = 0;
  /// Moves box `id` (present) to `box`.
  virtual void move(ProxyId id, const Aabb& box) = 0;
  /// Every overlapping pair of present boxes, sorted by (a, b), into `out`
  /// (cleared first), except pairs of two fixed boxes.
  virtual void pairs(std::vector<ProxyPair>& out) = 0;

  virtual std::size_t size() const = 0;
  virtual BroadphaseStats stats() const = 0;

  /// Marks box `id` fixed, or not (every id starts not fixed). The mark
  /// belongs to the id, present or not, until it is set again. A pair of two
  /// fixed boxes is never reported: the pipeline marks the parts whose pairs
  /// with each other it never tests, and their overlaps, in a packed
  /// assembly most of them, are then not gathered and sorted every frame
  /// only to be thrown away.
  void set_fixed(ProxyId id, bool fixed);
  bool fixed(ProxyId id) const { return id < fixed_.size() && fixed_[id] != 0; }

 protected:
  /// Whether pairs() leaves out the pair of a and b.
  bool both_fixed(ProxyId a, ProxyId b) const { return fixed_count_ > 1 && fixed(a) && fixed(b); }
  /// Removes the pairs of two fixed boxes from `out`, keeping the order of the rest.
  void drop_fixed_pairs(std::vector<ProxyPair>& out) const;

 private:
  std::vector<std::uint8_t> fixed_;
  std::size_t fixed_count_ = 0;
};

/// Makes an empty broad phase of `method`.
std::unique_ptr<Broadphase> make_broadphase(BroadphaseMethod method,
                                            const BroadphaseSettings& settings = {});

}  // namespace dovetail::collision
