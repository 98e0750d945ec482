#include "polygon/box_lanes.h"

#include <cmath>
#include <cstdlib>

#include "polygon/box_lanes_kernel.h"

namespace dovetail::collision::detail {

namespace {

/// The lanes one double at a time: the reference the wide lanes equal bit
/// for bit. Lane 3, which no result reads, is not computed; it is zero where
/// it is stored.
struct ScalarLanes {
  struct V {
    double v[3];
  };
  static V load4(const double* p) { return {{p[0], p[1], p[2]}}; }
  static V load3(const double* p) { return {{p[0], p[1], p[2]}}; }
  static void store(double* p, const V& a) {
    for (int i = 0; i < 3; ++i) p[i] = a.v[i];
    p[3] = 0.0;
  }
  static V clear3(const V& a) { return a; }
  static V broadcast(double x) { return {{x, x, x}}; }
  template <typename F>
  static V each(const V& a, const V& b, F f) {
    return {{f(a.v[0], b.v[0]), f(a.v[1], b.v[1]), f(a.v[2], b.v[2])}};
  }
  static V add(const V& a, const V& b) {
    return each(a, b, [](double x, double y) { return x + y; });
  }
  static V sub(const V& a, const V& b) {
    return each(a, b, [](double x, double y) { return x - y; });
  }
  static V mul(const V& a, const V& b) {
    return each(a, b, [](double x, double y) { return x * y; });
  }
  static V max(const V& a, const V& b) { return each(a, b, max1); }
  static V abs(const V& a) { return {{std::abs(a.v[0]), std::abs(a.v[1]), std::abs(a.v[2])}}; }
  /// out[j] lane i = rows[i] lane j.
  static void transpose(const V (&rows)[3], V (&out)[3]) {
    for (int j = 0; j < 3; ++j) out[j] = {{rows[0].v[j], rows[1].v[j], rows[2].v[j]}};
  }
  /// Lane j takes lane (j + 1) mod 3.
  static V turn1(const V& a) { return {{a.v[1], a.v[2], a.v[0]}}; }
  /// Lane j takes lane (j + 2) mod 3.
  static V turn2(const V& a) { return {{a.v[2], a.v[0], a.v[1]}}; }
  template <int i>
  static double lane(const V& a) {
    return a.v[i];
  }
  /// Every lane takes lane i.
  template <int i>
  static V spread(const V& a) {
    return broadcast(a.v[i]);
  }
};

}  // namespace

BoxLaneOps box_lane_ops_scalar() { return {box_gap<ScalarLanes>, box_move<ScalarLanes>}; }

BoxLaneOps box_lane_ops() {
  static const BoxLaneOps chosen = [] {
    // For comparing the two on one machine; both give the same bits.
    if (std::getenv("DOVETAIL_SCALAR_LANES")) return box_lane_ops_scalar();
    const BoxLaneOps wide = box_lane_ops_avx2();
    return wide.gap ? wide : box_lane_ops_scalar();
  }();
  return chosen;
}

#ifndef DOVETAIL_BOX_LANES_AVX2
BoxLaneOps box_lane_ops_avx2() { return {nullptr, nullptr}; }
#endif

}  // namespace dovetail::collision::detail
