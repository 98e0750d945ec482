// The exact triangle-triangle test (collision::triangles_intersect) against
// an independent exact oracle: the separating axis test in __int128 on
// integer coordinates. The doubles handed to the tested function are those
// integers times a power of two, so both see the same triangles exactly and
// must agree on every non-degenerate pair, touching included.
//
// Input: a mode byte, then 18 little-endian 32-bit coordinates (missing bytes
// read as zero). Mode bits 0-1 pick the coordinate range (small ranges make
// touching and coplanar pairs common), bit 2 flattens both triangles into
// z = 0, bits 3-7 the power-of-two scale.

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "dovetail/collision/tri_tri.h"
#include "fuzz_support.h"

using namespace dovetail;

namespace {

using Int = __int128;

struct IVec {
  Int x = 0, y = 0, z = 0;
};

IVec sub(const IVec& a, const IVec& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
IVec cross(const IVec& a, const IVec& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
Int dot(const IVec& a, const IVec& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
bool is_zero(const IVec& a) { return a.x == 0 && a.y == 0 && a.z == 0; }

using ITriangle = std::array<IVec, 3>;

/// True when the projections of closed triangles a and b on `axis` are disjoint.
bool separates(const IVec& axis, const ITriangle& a, const ITriangle& b) {
  if (is_zero(axis)) return false;
  Int a_min = dot(axis, a[0]), a_max = a_min, b_min = dot(axis, b[0]), b_max = b_min;
  for (int i = 1; i < 3; ++i) {
    const Int pa = dot(axis, a[i]), pb = dot(axis, b[i]);
    a_min = pa < a_min ? pa : a_min;
    a_max = pa > a_max ? pa : a_max;
    b_min = pb < b_min ? pb : b_min;
    b_max = pb > b_max ? pb : b_max;
  }
  return a_max < b_min || b_max < a_min;
}

/// Exact verdict for non-degenerate triangles: they share a point unless one
/// of the candidate axes separates them (both normals, the nine edge-edge
/// cross products, and the in-plane edge normals for the coplanar case).
bool oracle_intersect(const ITriangle& a, const ITriangle& b) {
  const std::array<IVec, 3> ea = {sub(a[1], a[0]), sub(a[2], a[1]), sub(a[0], a[2])};
  const std::array<IVec, 3> eb = {sub(b[1], b[0]), sub(b[2], b[1]), sub(b[0], b[2])};
  const IVec na = cross(ea[0], ea[1]), nb = cross(eb[0], eb[1]);
  if (separates(na, a, b) || separates(nb, a, b)) return false;
  for (int i = 0; i < 3; ++i) {
    if (separates(cross(na, ea[i]), a, b) || separates(cross(nb, eb[i]), a, b)) return false;
    for (int j = 0; j < 3; ++j) {
      if (separates(cross(ea[i], eb[j]), a, b)) return false;
    }
  }
  return true;
}

bool degenerate(const ITriangle& t) { return is_zero(cross(sub(t[1], t[0]), sub(t[2], t[0]))); }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::uint8_t mode = data[0];
  std::array<std::int32_t, 18> raw{};
  std::memcpy(raw.data(), data + 1, std::min(size - 1, sizeof(raw)));
  // Ranges [-r, r]: 2, 16, 1024 and 2^20 (the oracle's sums stay below 2^90).
  static constexpr std::int64_t kRanges[] = {2, 16, 1024, std::int64_t{1} << 20};
  const std::int64_t r = kRanges[mode & 3];
  const bool flat = (mode & 4) != 0;
  const int exponent = static_cast<int>(mode >> 3) * 4 - 64;  // -64 .. 60

  std::array<ITriangle, 2> tri;
  std::array<std::array<collision::Vec3, 3>, 2> real;
  for (int t = 0; t < 2; ++t) {
    for (int v = 0; v < 3; ++v) {
      std::array<std::int64_t, 3> c{};
      for (int k = 0; k < 3; ++k) {
        const std::int64_t x = raw[static_cast<std::size_t>(t * 9 + v * 3 + k)];
        c[static_cast<std::size_t>(k)] = (flat && k == 2) ? 0 : ((x % (2 * r + 1)) + (2 * r + 1)) % (2 * r + 1) - r;
      }
      tri[t][v] = {c[0], c[1], c[2]};
      real[t][v] = collision::Vec3(std::ldexp(static_cast<double>(c[0]), exponent),
                                   std::ldexp(static_cast<double>(c[1]), exponent),
                                   std::ldexp(static_cast<double>(c[2]), exponent));
    }
  }
  const bool tested = collision::triangles_intersect(real[0][0], real[0][1], real[0][2], real[1][0],
                                                     real[1][1], real[1][2]);
  // Degenerate triangles are outside the contract: the call above must only not crash.
  if (degenerate(tri[0]) || degenerate(tri[1])) return 0;
  const bool expected = oracle_intersect(tri[0], tri[1]);
  if (tested != expected) {
    std::fprintf(stderr, "triangles_intersect says %d, the exact oracle %d\n", tested, expected);
    __builtin_trap();
  }
  // The verdict does not depend on the order of the triangles.
  const bool swapped = collision::triangles_intersect(real[1][0], real[1][1], real[1][2], real[0][0],
                                                      real[0][1], real[0][2]);
  fuzz::require(swapped == tested, "the verdict does not depend on triangle order");
  return 0;
}
