#pragma once
// Sweep and prune (I-COLLIDE): three sorted endpoint arrays kept sorted by
// insertion sort from frame to frame.

#include <array>
#include <cstdint>
#include <vector>

#include "broadphase/proxy_pairs.h"
#include "dovetail/collision/broadphase.h"

namespace dovetail::collision {

/// Why: with coherent motion the endpoint order changes little between frames,
/// so re-sorting each axis by insertion sort costs O(n + swaps), and every swap
/// of one box's begin with another's end is exactly a change of the two boxes'
/// overlap on that axis. The overlapping pairs are kept in a hash set keyed by
/// the pair, changed only at those swaps, so a frame costs O(n + swaps + s).
///
/// The per-axis overlap bits of I-COLLIDE are not stored: the bit of axis k is
/// the order of the two boxes' endpoints in array k, which the swap flips. When
/// a swap on axis k makes two boxes overlap there, the pair enters the set if
/// their current coordinates overlap on the other two axes; when a swap ends
/// the overlap, the pair leaves the set. After all three axes are sorted the
/// set is exactly the overlapping pairs (see docs/broadphase.md). Memory is
/// O(n + s), not O(pairs overlapping on one axis).
///
/// New boxes are tested against all boxes and merged into the arrays (O(n)
/// each, no swaps); more than n/32 at once, and the first frame, sort from
/// scratch and rebuild the set by one sweep along x.
///
/// Ties: an endpoint is ordered by (value, begin before end), so boxes that
/// only touch overlap, as `Aabb::overlaps` says.
class SweepAndPrune final : public Broadphase {
 public:
  void add(ProxyId id, const Aabb& box) override;
  void remove(ProxyId id) override;
  void move(ProxyId id, const Aabb& box) override;
  void pairs(std::vector<ProxyPair>& out) override;

  std::size_t size() const override { return count_; }
  BroadphaseStats stats() const override { return last_stats_; }

 private:
  detail::PairSortScratch sort_keys_;  ///< scratch of pairs()
  static constexpr std::uint32_t kNone = 0xffffffffu;

  /// One box end on one axis. `key` is handle * 2 + (1 for an end, 0 for a begin),
  /// which is also the index of its value in `bounds_[axis]`.
  struct Endpoint {
    Real value;
    std::uint32_t key;
  };

  /// The overlapping pairs of handles: open addressing, linear probing,
  /// backward-shift deletion, plus a dense list of the keys for output and
  /// each handle's number of pairs (an erase of a pair with a handle in no
  /// pair, the common case, costs no lookup).
  class PairSet {
   public:
    void clear();
    void insert(std::uint32_t a, std::uint32_t b);
    void erase(std::uint32_t a, std::uint32_t b);
    /// Keeps only the keys for which `keep(key)` holds.
    template <typename Keep>
    void filter(Keep keep);
    const std::vector<std::uint64_t>& keys() const { return dense_; }

   private:
    static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};
    struct Slot {
      std::uint64_t key = kEmpty;
      std::uint32_t index = 0;  ///< position of the key in dense_
    };
    std::size_t home(std::uint64_t key) const {
      return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> shift_);
    }
    void grow();

    std::vector<Slot> slots_;
    std::size_t mask_ = 0;
    int shift_ = 64;
    std::vector<std::uint64_t> dense_;
    std::vector<std::uint32_t> degree_;  ///< per handle: pairs in the set that hold it
  };

  std::uint32_t new_handle();
  void remove_dead();
  void rebuild();
  void merge_added();
  void sort_axis(int axis);
  bool overlap_on(int axis, std::uint32_t a, std::uint32_t b) const {
    const std::vector<Real>& v = bounds_[axis];
    return v[2 * a] <= v[2 * b + 1] && v[2 * b] <= v[2 * a + 1];
  }

  // Per id.
  std::vector<std::uint32_t> handle_of_;
  // Per handle: the box as [min, max] pairs per axis, owner id, state.
  std::array<std::vector<Real>, 3> bounds_;
  std::vector<ProxyId> id_of_;
  std::vector<char> alive_;
  std::vector<char> sorted_in_;  ///< endpoints are in the arrays
  std::vector<std::uint32_t> free_handles_;

  std::array<std::vector<Endpoint>, 3> axes_;
  std::vector<std::uint32_t> added_;  ///< handles added since the last pairs()
  std::size_t dead_in_arrays_ = 0;
  std::size_t count_ = 0;
  bool moved_ = false;
  PairSet overlapping_;

  std::vector<std::uint32_t> active_;     ///< scratch of rebuild()
  std::vector<Endpoint> fresh_, merged_;  ///< scratch of merge_added()
  BroadphaseStats stats_, last_stats_;
};

}  // namespace dovetail::collision
