#pragma once
// Hashed uniform grid: boxes register in the cells their box covers.

#include <array>
#include <cstdint>
#include <vector>

#include "broadphase/proxy_pairs.h"
#include "dovetail/collision/broadphase.h"

namespace dovetail::collision {

/// Why: when boxes are of similar size, a grid with cells about twice that
/// size puts each box in a few cells, and only boxes sharing a cell can
/// overlap. Cells live in a hash table, so the grid is unbounded and costs
/// memory only where boxes are. It is incremental: a box re-registers only
/// when the range of cells it covers changes, and then only in the cells it
/// enters or leaves; the cells holding two or more boxes are kept in a list,
/// so a frame costs O(n) cheap range checks plus the tests in those cells.
///
/// Exactly once: two overlapping boxes share every cell of the intersection of
/// their ranges, and the pair is reported only from the cell holding the lower
/// corner of the two boxes' intersection. The map from coordinate to cell
/// index is monotone (floor of x times the inverse cell size, clamped to
/// +-kCellLimit), which is all that argument needs, so it also holds for far
/// outliers in the clamped border cells.
///
/// Boxes covering more than kMaxCells cells are kept out of the grid and
/// tested against every box.
class UniformGrid final : public Broadphase {
 public:
  /// `cell` > 0 fixes the cell edge; 0 chooses it from the boxes (twice the
  /// median box size, re-chosen when the mean box size drifts by more than 2x).
  explicit UniformGrid(Real cell = 0);

  void add(ProxyId id, const Aabb& box) override;
  void remove(ProxyId id) override;
  void move(ProxyId id, const Aabb& box) override;
  void pairs(std::vector<ProxyPair>& out) override;

  std::size_t size() const override { return present_.size(); }
  BroadphaseStats stats() const override { return last_stats_; }

  /// The cell edge in use (0 before the first pairs() when chosen automatically).
  Real cell_size() const { return cell_; }

  /// Cell indices are clamped to +-kCellLimit on each axis.
  static constexpr std::int32_t kCellLimit = (1 << 20) - 1;
  /// A box covering more cells than this is tested against every box instead.
  static constexpr std::uint64_t kMaxCells = 4096;

 private:
  detail::PairSortScratch sort_keys_;  ///< scratch of pairs()
  static constexpr std::uint32_t kNone = 0xffffffffu;
  using CellIndex = std::array<std::int32_t, 3>;
  struct Range {
    CellIndex lo{}, hi{};
    friend bool operator==(const Range&, const Range&) = default;
  };
  struct Entry {
    Range range;
    std::uint32_t slot = kNone;      ///< position in present_, kNone when absent
    std::uint32_t big_slot = kNone;  ///< position in big_, kNone when in the grid
  };
  struct Cell {
    std::uint64_t key = 0;
    CellIndex at{};
    std::vector<ProxyId> ids;
    std::uint32_t crowded_slot = kNone;
  };
  struct Slot {
    std::uint64_t key = 0;  ///< 0: empty
    std::uint32_t cell = 0;
  };

  std::int32_t index_of(Real x) const;
  Range range_of(const Aabb& box) const;
  static std::uint64_t cell_key(const CellIndex& c);
  std::size_t home(std::uint64_t key) const {
    // Neighbouring cells differ in few bits: mix them all before taking the top bits.
    key ^= key >> 31;
    key *= 0xBF58476D1CE4E5B9ull;
    key ^= key >> 29;
    return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> shift_);
  }

  void choose_cell();
  void register_all();
  void register_box(ProxyId id);
  void unregister_box(ProxyId id);
  void update_box(ProxyId id, const Range& range);
  void enter(const CellIndex& c, ProxyId id);
  void leave(const CellIndex& c, ProxyId id);
  void grow_table();

  Real fixed_cell_ = 0;
  Real cell_ = 0;
  Real inverse_cell_ = 0;
  Real chosen_mean_size_ = 0;
  bool ready_ = false;  ///< boxes are registered (cell size known)

  std::vector<Aabb> boxes_;     ///< by id
  std::vector<Entry> entries_;  ///< by id
  std::vector<ProxyId> present_;
  std::vector<ProxyId> big_;
  Real size_sum_ = 0;  ///< sum of box sizes (mean edge) of present boxes

  std::vector<Slot> table_;
  std::size_t mask_ = 0;
  int shift_ = 64;
  std::size_t table_count_ = 0;
  std::vector<Cell> cells_;
  std::vector<std::uint32_t> free_cells_;
  std::vector<std::uint32_t> crowded_;  ///< cells with two or more boxes

  std::vector<Real> scratch_;
  BroadphaseStats stats_, last_stats_;
};

}  // namespace dovetail::collision
