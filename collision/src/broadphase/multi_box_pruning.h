#pragma once
// Multi-box pruning: columns across two axes, a sweep along the third in each.

#include <cstdint>
#include <vector>

#include "broadphase/proxy_pairs.h"
#include "dovetail/collision/broadphase.h"

namespace dovetail::collision {

/// Why: in a crowded scene (parts packed together, each touching several
/// others) the work is the pairs themselves, and what counts is how few box
/// tests a method spends per pair found and how cheap each is. Sweeping the
/// boxes sorted along one axis (Terdiman's box pruning) tests only pairs that
/// overlap on that axis, in order through one array; alone, it tests every
/// box against all the boxes of the scene that share its slab. Cutting the
/// scene into columns across the other two axes first (multi-box pruning, as
/// in PhysX's MBP) leaves each sweep only the boxes of one column: in a
/// cluster of touching parts about two tests per pair, in a sparse scene
/// almost none beyond the pairs.
///
/// A frame rebuilds the columns from scratch: each box goes into every column
/// its box covers (counting sort by column), each column is sorted along the
/// sweep axis by insertion sort, which is nearly linear because the boxes are
/// visited in last frame's sweep order, and swept. No state but that order
/// carries over, so adds, removes and moves cost O(1).
///
/// Exactly once: two overlapping boxes share every column of the intersection
/// of their column ranges, and the pair is reported only from the column of
/// its intersection's lower corner, which is (max of the two first columns)
/// on each axis because the map from coordinate to column is monotone (floor,
/// clamped to the grid), so it holds for far outliers in the border columns.
///
/// Layout: the sweep axis is the one along which the box centres spread most;
/// the column edge is kColumnFactor times the median box extent across it,
/// widened until there are at most max(16, n) columns. It is re-chosen when
/// the number of boxes or their mean extent drifts by more than 2x, or when
/// more than an eighth of the boxes fall outside the columns' range.
/// Boxes covering more than kMaxColumnsPerBox columns are tested against
/// every box instead.
class MultiBoxPruning final : public Broadphase {
 public:
  /// `column` > 0 fixes the column edge; 0 chooses it from the boxes.
  explicit MultiBoxPruning(Real column = 0);

  void add(ProxyId id, const Aabb& box) override;
  void remove(ProxyId id) override;
  void move(ProxyId id, const Aabb& box) override;
  void pairs(std::vector<ProxyPair>& out) override;

  std::size_t size() const override { return present_.size(); }
  BroadphaseStats stats() const override { return last_stats_; }

  /// The column edge in use (0 before the first pairs() when chosen automatically).
  Real column_size() const { return column_; }
  /// The sweep axis in use (0, 1, 2 for x, y, z).
  int sweep_axis() const { return s_; }

  /// Column edge over the median box extent across the sweep axis.
  static constexpr Real kColumnFactor = 8;
  /// A box covering more columns than this is tested against every box instead.
  static constexpr std::uint32_t kMaxColumnsPerBox = 16;
  /// Columns per axis at most.
  static constexpr std::uint32_t kMaxColumnsPerAxis = 4096;

 private:
  static constexpr std::uint32_t kNone = 0xffffffffu;
  /// One box in one column: its bounds along the sweep axis s and across it
  /// (u, v), its id, and the first column it covers on u and v.
  struct Entry {
    Real lo_s, hi_s, lo_u, hi_u, lo_v, hi_v;
    ProxyId id;
    std::uint16_t u0, v0;
  };
  /// The columns a box covers this frame; u0 == kBig marks a big box.
  struct Span {
    std::uint16_t u0, u1, v0, v1;
  };
  static constexpr std::uint16_t kBig = 0xffff;

  void choose_layout();
  /// The column of coordinate x on an axis whose columns start at `origin`.
  std::uint16_t column_of(Real x, Real origin, std::uint32_t columns) const;
  /// A box's mean edge across the sweep axis.
  Real extent_across(const Aabb& b) const;
  /// Spans of every box in sequence_; false when the layout has drifted.
  bool span_all(bool allow_drift);
  void fill_columns();
  void sort_columns();
  /// Writes the pairs found as keys (a << bits) | b into `keys`; returns how many.
  template <typename Key>
  std::size_t sweep_columns(std::vector<Key>& keys, int bits);
  template <typename Key>
  std::size_t test_big_boxes(std::vector<Key>& keys, std::size_t found, int bits);
  template <typename Key>
  void find_pairs(std::vector<Key>& keys, int bits, std::vector<ProxyPair>& out);

  Real fixed_column_ = 0;
  Real column_ = 0;
  Real inverse_column_ = 0;
  int s_ = 0, u_ = 1, v_ = 2;
  Real origin_u_ = 0, origin_v_ = 0;
  std::uint32_t columns_u_ = 1, columns_v_ = 1;
  Real chosen_mean_extent_ = 0;
  std::size_t chosen_count_ = 0;
  bool ready_ = false;

  std::vector<Aabb> boxes_;           ///< by id
  std::vector<std::uint32_t> slot_;   ///< by id: position in present_, kNone when absent
  std::vector<std::uint32_t> stamp_;  ///< by id: the frame that last put it in sequence_
  std::uint32_t frame_ = 0;
  std::vector<ProxyId> present_;
  std::vector<ProxyId> order_;     ///< last frame's sweep order (may hold absent ids)
  std::vector<ProxyId> sequence_;  ///< this frame's boxes: order_'s present ones, then new ones
  std::vector<Span> spans_;        ///< by position in sequence_
  std::vector<std::uint32_t> offsets_;  ///< per column, its first entry; one past the end last
  std::vector<std::uint32_t> cursor_;   ///< scratch of fill_columns()
  std::vector<Entry> entries_;
  std::vector<ProxyId> big_;
  detail::PairSortScratch sort_keys_;  ///< pairs found, as keys, and the sort's counts
  std::vector<Real> scratch_;
  BroadphaseStats stats_, last_stats_;
};

}  // namespace dovetail::collision
