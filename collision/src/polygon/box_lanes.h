#pragma once
// The OBB tree's separating-axis test, and the move of a box into the other
// tree's frame, in two forms that give the same bits: scalar code with an
// exit at the first separating axis, on every processor, and on x86-64
// processors with AVX2 the same expressions four doubles wide, three axes a
// lane group. Near contact about half the box pairs a query tests overlap,
// and an overlapping pair needs all fifteen axes; four wide, those are a few
// dozen operations.
//
// The wide form lives in a file of its own compiled for AVX2
// (box_lanes_avx2.cpp) and is chosen at run time. Both forms compute every
// value with the same IEEE operations in the same order, without fused
// multiply-adds, and report the same axis: a query's counts and its first
// hit do not depend on the processor. This header holds plain data and one
// function of internal linkage, so that the AVX2 file shares no inline code
// with the rest of the library (the scalar form is in box_lanes_scalar.h).

namespace dovetail::collision::detail {

/// Box B in A's frame, laid out for the wide test; lane 3 is zero.
struct BoxLanes {
  double row[3][4];      ///< row k: component k of B's axes b_0, b_1, b_2
  double centre[4];      ///< B's centre
  double half[4];        ///< half extents e_j
  double half_next[4];   ///< e_{(j+1) mod 3}
  double half_after[4];  ///< e_{(j+2) mod 3}
};

/// The separating-axis test of Gottschalk et al. (15 axes) of box A, given
/// as fifteen doubles from `a`: the rotation into its frame (column-major,
/// so a + 3k holds component k of its three axes), its centre and its half
/// extents, all in A's frame; the wide test reads one double past each
/// column, so the centre must follow the rotation. Each projected radius is
/// widened by `margin`. Returns the gap (> 0) on the first axis that
/// separates the boxes, in the order A's faces, B's faces, the edge pairs
/// a_i x b_j by i then j; or 0 when none does. On an edge-edge axis, whose
/// length is at most 1, the gap is scaled by that length: never more than
/// the true one. NaN separates nothing.
using BoxGapFn = double (*)(const double* a, const BoxLanes& b, double margin);

/// Box B, given as fifteen doubles in B's frame (laid out as A's above),
/// moved into A's frame by the rotation R_AB (column-major) and the
/// translation t_AB; the centre is summed as Transform::apply sums it.
using BoxMoveFn = void (*)(const double* box, const double* R_AB, const double* t_AB,
                           BoxLanes& out);

/// A triangle, in the frame of the boxes it is tested against, laid out for
/// the box-triangle test: a corner, the edges from it to the other two, and
/// the normal (their cross product, not normalized), each with a zero fourth
/// lane; the margin, and the margin times the normal's 1-norm.
struct TriangleLanes {
  double corner[4];
  double edge1[4];
  double edge2[4];
  double normal[4];
  double margin;
  double normal_margin;
};

/// Whether box A (fifteen doubles, laid out as for BoxGapFn) and a triangle
/// may meet: false when one of A's three face axes, or the triangle's
/// normal, separates them by more than the margin. Conservative: the nine
/// edge-edge axes, which could separate a few more pairs, are not tried.
/// Both forms compute every value with the same operations in the same order.
using BoxTriangleFn = bool (*)(const double* a, const TriangleLanes& t);

/// The test, the move and the box-triangle test, in one form.
struct BoxLaneOps {
  BoxGapFn gap;
  BoxMoveFn move;
  BoxTriangleFn meets_triangle;
};

/// The wide form where the processor has AVX2, else the scalar form;
/// chosen once. The environment variable DOVETAIL_SCALAR_LANES (any value)
/// asks for the scalar form.
BoxLaneOps box_lane_ops();

/// The scalar form, on every processor.
BoxLaneOps box_lane_ops_scalar();

/// The wide form, or null functions where this build or processor has none.
BoxLaneOps box_lane_ops_avx2();

/// Whether `ops` is a wide form (callers inline the scalar form instead of
/// calling it).
bool box_lanes_wide(BoxLaneOps ops);

/// The part of a move both forms share: B's centre and half extents.
/// Internal linkage: each file compiles its own copy for its own
/// instruction set.
static inline void box_move_rest(const double* box, const double* R_AB, const double* t_AB,
                                 BoxLanes& out) {
  const double* c = box + 9;
  const double* half = box + 12;
  for (int k = 0; k < 3; ++k) {
    out.centre[k] = R_AB[k] * c[0] + R_AB[3 + k] * c[1] + R_AB[6 + k] * c[2] + t_AB[k];
    out.half[k] = half[k];
    out.half_next[k] = half[(k + 1) % 3];
    out.half_after[k] = half[(k + 2) % 3];
  }
  out.centre[3] = out.half[3] = out.half_next[3] = out.half_after[3] = 0.0;
}

}  // namespace dovetail::collision::detail
