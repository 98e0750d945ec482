#pragma once
// The OBB tree's separating-axis test, written over lanes: three of the
// fifteen axes at a time, one axis a lane. Near contact about half the box
// pairs a query tests overlap, and an overlapping pair needs every axis; the
// scalar test spends most of its time there, in long dependent chains. In
// lanes the test is a few dozen wide operations.
//
// The test is written once (box_lanes_kernel.h), over a lane type: scalar
// lanes run everywhere; on x86-64 processors with AVX2 the same steps run
// four doubles wide, from a file of their own compiled for AVX2. Both do the
// same IEEE operations in the same order, without fused multiply-adds, so
// they give the same bits: a query's counts and its first hit do not depend
// on the processor. This header holds plain data only, so that the AVX2
// file shares no inline code with the rest of the library.

namespace dovetail::collision::detail {

/// Box B in A's frame, laid out for the lane test; lane 3 is zero.
struct alignas(32) BoxLanes {
  double row[3][4];      ///< row k: component k of B's axes b_0, b_1, b_2
  double centre[4];      ///< B's centre
  double half[4];        ///< half extents e_j
  double half_next[4];   ///< e_{(j+1) mod 3}
  double half_after[4];  ///< e_{(j+2) mod 3}
};

/// B's box (fifteen doubles laid out as A's below, in B's frame) moved
/// into A's frame by the rotation R_AB (column-major) and translation t_AB.
/// The centre is R_AB c + t_AB summed as Transform::apply sums it.
using BoxMoveFn = void (*)(const double* box, const double* R_AB, const double* t_AB,
                           BoxLanes& out);

/// Box A as the lane test reads it: fifteen doubles from `a`, the rows of
/// its axes matrix (column-major: a + 3k holds component k of the three
/// axes), then its centre, then its half extents, all in A's frame. The
/// test reads a fourth double after each row, so a + 9 (the centre) must
/// follow the rows.
///
/// The separating-axis test of Gottschalk et al. (15 axes), each projected
/// radius widened by `margin`: the largest gap (> 0) on the axes tried,
/// when one separates the boxes, or 0 when they overlap. A's face axes are
/// tried first, and alone when one of them separates; then B's face axes
/// and the nine edge-edge axes, whose gap is scaled by the axis length (at
/// most 1), so never more than the true one. NaN separates nothing.
using BoxGapFn = double (*)(const double* a, const BoxLanes& b, double margin);

/// The test and the move, in one lane type.
struct BoxLaneOps {
  BoxGapFn gap;
  BoxMoveFn move;
};

/// Four doubles wide where the processor has AVX2, else the scalar lanes;
/// chosen once. The environment variable DOVETAIL_SCALAR_LANES (any value)
/// asks for the scalar lanes.
BoxLaneOps box_lane_ops();

/// The scalar lanes, on every processor.
BoxLaneOps box_lane_ops_scalar();

/// The AVX2 lanes, or null functions where this build or processor has none.
BoxLaneOps box_lane_ops_avx2();

}  // namespace dovetail::collision::detail
