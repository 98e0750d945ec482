#include "polygon/box_lanes.h"

#include <cmath>

#include "polygon/box_lanes_kernel.h"

namespace dovetail::collision::detail {

namespace {

/// Four doubles, one operation at a time: the reference the wide lanes
/// equal bit for bit.
struct ScalarLanes {
  struct V {
    double v[4];
  };
  static V load4(const double* p) { return {{p[0], p[1], p[2], p[3]}}; }
  static V load3(const double* p) { return {{p[0], p[1], p[2], 0.0}}; }
  static void store(double* p, const V& a) {
    for (int i = 0; i < 4; ++i) p[i] = a.v[i];
  }
  /// Lane 3 set to zero.
  static V clear3(const V& a) { return {{a.v[0], a.v[1], a.v[2], 0.0}}; }
  static V broadcast(double x) { return {{x, x, x, x}}; }
  template <typename F>
  static V each(const V& a, const V& b, F f) {
    return {{f(a.v[0], b.v[0]), f(a.v[1], b.v[1]), f(a.v[2], b.v[2]), f(a.v[3], b.v[3])}};
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
  static V abs(const V& a) {
    return {{std::abs(a.v[0]), std::abs(a.v[1]), std::abs(a.v[2]), std::abs(a.v[3])}};
  }
  /// Lane j takes lane (j + 1) mod 3; lane 3 stays.
  static V turn1(const V& a) { return {{a.v[1], a.v[2], a.v[0], a.v[3]}}; }
  /// Lane j takes lane (j + 2) mod 3; lane 3 stays.
  static V turn2(const V& a) { return {{a.v[2], a.v[0], a.v[1], a.v[3]}}; }
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
    const BoxLaneOps wide = box_lane_ops_avx2();
    return wide.gap ? wide : box_lane_ops_scalar();
  }();
  return chosen;
}

#ifndef DOVETAIL_BOX_LANES_AVX2
BoxLaneOps box_lane_ops_avx2() { return {nullptr, nullptr}; }
#endif

}  // namespace dovetail::collision::detail
