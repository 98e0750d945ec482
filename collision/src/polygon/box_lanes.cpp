#include "polygon/box_lanes.h"

#include <cstdlib>

#include "polygon/box_lanes_scalar.h"

namespace dovetail::collision::detail {

BoxLaneOps box_lane_ops_scalar() {
  return {box_gap_scalar, box_move_scalar, box_meets_triangle_scalar};
}

bool box_lanes_wide(BoxLaneOps ops) { return ops.gap != box_gap_scalar; }

BoxLaneOps box_lane_ops() {
  static const BoxLaneOps chosen = [] {
    // For comparing the two forms on one machine; both give the same bits.
    if (std::getenv("DOVETAIL_SCALAR_LANES")) return box_lane_ops_scalar();
    const BoxLaneOps wide = box_lane_ops_avx2();
    return wide.gap ? wide : box_lane_ops_scalar();
  }();
  return chosen;
}

#ifndef DOVETAIL_BOX_LANES_AVX2
BoxLaneOps box_lane_ops_avx2() { return {nullptr, nullptr, nullptr}; }
#endif

}  // namespace dovetail::collision::detail
