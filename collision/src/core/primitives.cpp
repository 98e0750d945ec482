#include "dovetail/collision/primitives.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

namespace dovetail::collision {

namespace {

using Triangles = std::vector<TriangleIndices>;

TriangleIndices tri(std::size_t a, std::size_t b, std::size_t c) {
  return {static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b),
          static_cast<std::uint32_t>(c)};
}

std::string describe(const char* what, int a, int b = -1) {
  std::string s = "generated ";
  s.append(what).append("(").append(std::to_string(a));
  if (b >= 0) s.append(",").append(std::to_string(b));
  s.append(")");
  return s;
}

}  // namespace

Mesh make_box(const Vec3& h) {
  std::vector<Vec3> v;
  for (int i = 0; i < 8; ++i) {
    v.emplace_back((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(), (i & 4) ? h.z() : -h.z());
  }
  // Two triangles per face, outward counter-clockwise.
  const Triangles t = {tri(0, 2, 3), tri(0, 3, 1), tri(4, 5, 7), tri(4, 7, 6),
                       tri(0, 1, 5), tri(0, 5, 4), tri(2, 6, 7), tri(2, 7, 3),
                       tri(0, 4, 6), tri(0, 6, 2), tri(1, 3, 7), tri(1, 7, 5)};
  return make_mesh(std::move(v), t, "generated box");
}

Mesh make_sphere(Real radius, int subdivisions) {
  const Real g = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3> v = {{-1, g, 0},  {1, g, 0},  {-1, -g, 0}, {1, -g, 0}, {0, -1, g},  {0, 1, g},
                         {0, -1, -g}, {0, 1, -g}, {g, 0, -1},  {g, 0, 1},  {-g, 0, -1}, {-g, 0, 1}};
  for (Vec3& p : v) p.normalize();
  Triangles t = {tri(0, 11, 5), tri(0, 5, 1),  tri(0, 1, 7),   tri(0, 7, 10), tri(0, 10, 11),
                 tri(1, 5, 9),  tri(5, 11, 4), tri(11, 10, 2), tri(10, 7, 6), tri(7, 1, 8),
                 tri(3, 9, 4),  tri(3, 4, 2),  tri(3, 2, 6),   tri(3, 6, 8),  tri(3, 8, 9),
                 tri(4, 9, 5),  tri(2, 4, 11), tri(6, 2, 10),  tri(8, 6, 7),  tri(9, 8, 1)};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> midpoints;
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::minmax(a, b);
      auto [it, inserted] = midpoints.try_emplace(key, static_cast<std::uint32_t>(v.size()));
      if (inserted) v.push_back((v[a] + v[b]).normalized());
      return it->second;
    };
    Triangles next;
    next.reserve(t.size() * 4);
    for (const TriangleIndices& f : t) {
      const std::uint32_t ab = midpoint(f[0], f[1]);
      const std::uint32_t bc = midpoint(f[1], f[2]);
      const std::uint32_t ca = midpoint(f[2], f[0]);
      next.push_back({f[0], ab, ca});
      next.push_back({f[1], bc, ab});
      next.push_back({f[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    t = std::move(next);
  }
  for (Vec3& p : v) p *= radius;
  return make_mesh(std::move(v), std::move(t), describe("sphere", subdivisions));
}

Mesh make_torus(Real major, Real minor, int rings, int sides) {
  std::vector<Vec3> v;
  Triangles t;
  for (int i = 0; i < rings; ++i) {
    const Real u = 2 * std::numbers::pi * i / rings;
    for (int j = 0; j < sides; ++j) {
      const Real w = 2 * std::numbers::pi * j / sides;
      const Real r = major + minor * std::cos(w);
      v.emplace_back(r * std::cos(u), r * std::sin(u), minor * std::sin(w));
    }
  }
  auto at = [&](int i, int j) { return ((i % rings) * sides) + (j % sides); };
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < sides; ++j) {
      t.push_back(tri(at(i, j), at(i + 1, j), at(i + 1, j + 1)));
      t.push_back(tri(at(i, j), at(i + 1, j + 1), at(i, j + 1)));
    }
  }
  return make_mesh(std::move(v), std::move(t), describe("torus", rings, sides));
}

Mesh make_cylinder(Real radius, Real height, int sides) {
  std::vector<Vec3> v;
  Triangles t;
  for (int j = 0; j < sides; ++j) {
    const Real w = 2 * std::numbers::pi * j / sides;
    v.emplace_back(radius * std::cos(w), radius * std::sin(w), 0);
    v.emplace_back(radius * std::cos(w), radius * std::sin(w), height);
  }
  const std::size_t bottom = v.size();
  v.emplace_back(0, 0, 0);
  const std::size_t top = v.size();
  v.emplace_back(0, 0, height);
  for (int j = 0; j < sides; ++j) {
    const std::size_t a0 = 2 * j, a1 = 2 * j + 1;
    const std::size_t b0 = 2 * ((j + 1) % sides), b1 = b0 + 1;
    t.push_back(tri(a0, b0, b1));
    t.push_back(tri(a0, b1, a1));
    t.push_back(tri(bottom, b0, a0));
    t.push_back(tri(top, a1, b1));
  }
  return make_mesh(std::move(v), std::move(t), describe("cylinder", sides));
}

Mesh make_tube(Real outer_radius, Real inner_radius, Real height, int sides) {
  if (!(inner_radius > 0 && inner_radius < outer_radius && std::isfinite(outer_radius) &&
        height > 0 && std::isfinite(height))) {
    throw std::invalid_argument("make_tube: need 0 < inner < outer and a positive height");
  }
  if (sides < 3) throw std::invalid_argument("make_tube: sides must be at least 3");
  // The bore's flats, not its corners, on the inner radius: a shaft of that
  // radius fits any bore (six sides make a hexagon socket, not a smaller hole).
  const Real bore = inner_radius / std::cos(std::numbers::pi / sides);
  if (!(bore < outer_radius)) {
    throw std::invalid_argument("make_tube: the bore's corners reach the outer wall");
  }
  std::vector<Vec3> v;
  Triangles t;
  // Per side j: outer bottom, outer top, inner bottom, inner top.
  for (int j = 0; j < sides; ++j) {
    const Real w = 2 * std::numbers::pi * j / sides;
    const Real c = std::cos(w), s = std::sin(w);
    v.emplace_back(outer_radius * c, outer_radius * s, 0);
    v.emplace_back(outer_radius * c, outer_radius * s, height);
    v.emplace_back(bore * c, bore * s, 0);
    v.emplace_back(bore * c, bore * s, height);
  }
  for (int j = 0; j < sides; ++j) {
    const std::size_t a = 4 * j, b = 4 * ((j + 1) % sides);
    t.push_back(tri(a, b, b + 1));  // outer wall, facing out
    t.push_back(tri(a, b + 1, a + 1));
    t.push_back(tri(a + 2, a + 3, b + 3));  // inner wall, facing the axis
    t.push_back(tri(a + 2, b + 3, b + 2));
    t.push_back(tri(a + 1, b + 1, b + 3));  // top ring, facing +z
    t.push_back(tri(a + 1, b + 3, a + 3));
    t.push_back(tri(a, a + 2, b + 2));  // bottom ring, facing -z
    t.push_back(tri(a, b + 2, b));
  }
  return make_mesh(std::move(v), std::move(t), describe("tube", sides));
}

Mesh make_block_with_hole(const Vec3& half_extents, Real hole_radius, Real hole_depth, int sides) {
  auto positive = [](Real x) { return std::isfinite(x) && x > 0; };
  if (!positive(half_extents.x()) || !positive(half_extents.y()) || !positive(half_extents.z()) ||
      !positive(hole_radius) || !positive(hole_depth)) {
    throw std::invalid_argument("make_block_with_hole: sizes must be positive and finite");
  }
  if (sides < 3) throw std::invalid_argument("make_block_with_hole: sides must be at least 3");
  const Real hx = half_extents.x(), hy = half_extents.y(), hz = half_extents.z();
  if (hole_depth >= 2 * hy) {
    throw std::invalid_argument("make_block_with_hole: the hole is deeper than the box");
  }
  const Real corner_radius = hole_radius / std::cos(std::numbers::pi / sides);
  if (!(corner_radius < std::min(hx, hz))) {
    throw std::invalid_argument("make_block_with_hole: the hole does not fit in the top face");
  }
  const std::size_t n = static_cast<std::size_t>(sides);
  const Real bottom_y = hy - hole_depth;
  // Plan coordinates (x, -z): counter-clockwise in the plan is counter-clockwise seen from +y.
  auto at = [](Real px, Real y, Real py) { return Vec3(px, y, -py); };
  std::vector<Vec3> v;
  // Square corners s_j counter-clockwise from (hx, -hz); side j runs from s_j to s_(j+1)
  // and faces the plan direction j * 90 degrees. Lower ring 0..3, upper ring 4..7.
  const Real square[4][2] = {{hx, -hz}, {hx, hz}, {-hx, hz}, {-hx, -hz}};
  for (Real y : {-hy, hy}) {
    for (const auto& s : square) v.push_back(at(s[0], y, s[1]));
  }
  auto lower = [](std::size_t j) { return j % 4; };
  auto upper = [](std::size_t j) { return 4 + j % 4; };
  // Polygon corner k at plan angle 2 pi (k + 1/2) / n: the flat of edge k (corner k to k + 1)
  // faces 2 pi (k + 1) / n. Rim ring at the top, floor ring at the hole's bottom.
  const std::size_t rim = v.size();
  for (Real y : {hy, bottom_y}) {
    for (std::size_t k = 0; k < n; ++k) {
      const Real w = 2 * std::numbers::pi * (static_cast<Real>(k) + 0.5) / sides;
      v.push_back(at(corner_radius * std::cos(w), y, corner_radius * std::sin(w)));
    }
  }
  const std::size_t floor_ring = rim + n;
  const std::size_t floor_centre = v.size();
  v.emplace_back(0, bottom_y, 0);
  auto top = [&](std::size_t k) { return rim + k % n; };
  auto bot = [&](std::size_t k) { return floor_ring + k % n; };

  Triangles t;
  t.push_back(tri(lower(0), lower(2), lower(1)));
  t.push_back(tri(lower(0), lower(3), lower(2)));
  for (std::size_t j = 0; j < 4; ++j) {
    t.push_back(tri(lower(j), lower(j + 1), upper(j + 1)));
    t.push_back(tri(lower(j), upper(j + 1), upper(j)));
  }
  // Top face: polygon corner m_j = floor(j n / 4) is (one of) the nearest to side j; the
  // triangle (s_j, s_(j+1), corner m_j) lies between them, and each square corner s_j fans
  // to the polygon edges m_(j-1) .. m_j - 1, whose flats face between sides j - 1 and j.
  auto nearest = [&](std::size_t j) { return j * n / 4; };
  for (std::size_t j = 0; j < 4; ++j) t.push_back(tri(upper(j), upper(j + 1), top(nearest(j))));
  for (std::size_t j = 1; j <= 4; ++j) {
    for (std::size_t k = nearest(j - 1); k < nearest(j); ++k) {
      t.push_back(tri(upper(j), top(k + 1), top(k)));
    }
  }
  for (std::size_t k = 0; k < n; ++k) {
    t.push_back(tri(bot(k), top(k), top(k + 1)));
    t.push_back(tri(bot(k), top(k + 1), bot(k + 1)));
    t.push_back(tri(floor_centre, bot(k), bot(k + 1)));
  }
  return make_mesh(std::move(v), std::move(t), describe("block with hole", sides));
}

Mesh make_wavy_sheet(Real half, Real amplitude, Real freq, int n) {
  std::vector<Vec3> v;
  Triangles t;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const Real x = -half + 2 * half * i / (n - 1);
      const Real y = -half + 2 * half * j / (n - 1);
      v.emplace_back(x, y, amplitude * std::sin(x * freq) * std::cos(y * freq));
    }
  }
  for (int i = 0; i + 1 < n; ++i) {
    for (int j = 0; j + 1 < n; ++j) {
      const int a = i * n + j;
      t.push_back(tri(a, a + n, a + n + 1));
      t.push_back(tri(a, a + n + 1, a + 1));
    }
  }
  return make_mesh(std::move(v), std::move(t), describe("wavy sheet", n));
}

}  // namespace dovetail::collision
