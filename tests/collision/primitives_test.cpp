// Generated meshes: closed, consistently oriented, and the sizes they promise.

#include "dovetail/collision/primitives.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "dovetail/collision/model.h"

namespace dovetail::collision {
namespace {

/// Every directed edge appears exactly once and its reverse exactly once.
void expect_closed_and_oriented(const Mesh& mesh) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const TriangleIndices& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  }
  int bad = 0;
  for (const auto& [edge, count] : directed) {
    const auto reverse = directed.find({edge.second, edge.first});
    if (count != 1 || reverse == directed.end() || reverse->second != 1) {
      if (++bad <= 5) {
        ADD_FAILURE() << mesh.source << ": edge " << edge.first << "->" << edge.second << " x"
                      << count;
      }
    }
  }
  EXPECT_EQ(bad, 0) << mesh.source;
}

Real signed_volume(const Mesh& mesh) {
  Real six_v = 0;
  for (const TriangleIndices& t : mesh.triangles) {
    six_v += mesh.vertices[t[0]].dot(mesh.vertices[t[1]].cross(mesh.vertices[t[2]]));
  }
  return six_v / 6;
}

Real polygon_area(int sides, Real apothem) {
  return sides * apothem * apothem * std::tan(std::numbers::pi / sides);
}

/// Pose of make_cylinder's +z axis along +y, its base at height `base`.
Transform along_y(Real base) {
  Transform X;
  X.R << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  X.t = Vec3(0, base, 0);
  return X;
}

struct HoleCase {
  Vec3 half;
  Real radius;
  Real depth;
  int sides;
};

std::vector<HoleCase> hole_cases() {
  std::vector<HoleCase> cases;
  for (int sides : {3, 4, 5, 8, 12, 64}) {
    cases.push_back({Vec3(0.03, 0.02, 0.03), 0.01, 0.015, sides});
    // Not square, and the corners close to the narrow sides.
    cases.push_back(
        {Vec3(0.05, 0.01, 0.012), 0.0105 * std::cos(std::numbers::pi / sides), 0.0199, sides});
  }
  return cases;
}

TEST(Primitives, BlockWithHoleIsClosedOrientedAndHasTheRightVolume) {
  for (const HoleCase& c : hole_cases()) {
    SCOPED_TRACE("sides " + std::to_string(c.sides) + " hx " + std::to_string(c.half.x()));
    const Mesh mesh = make_block_with_hole(c.half, c.radius, c.depth, c.sides);
    EXPECT_NE(mesh.source.find("block with hole"), std::string::npos);
    EXPECT_EQ(mesh.triangle_count(), static_cast<std::size_t>(14 + 4 * c.sides));
    MeshValidation validation;
    make_mesh(mesh.vertices, mesh.triangles, mesh.source, {}, &validation);
    EXPECT_EQ(validation.degenerate_removed, 0u);
    EXPECT_EQ(validation.unused_vertices, 0u);
    expect_closed_and_oriented(mesh);

    const Real box = 8 * c.half.x() * c.half.y() * c.half.z();
    const Real expected = box - polygon_area(c.sides, c.radius) * c.depth;
    EXPECT_GT(signed_volume(mesh), 0);
    EXPECT_NEAR(signed_volume(mesh), expected, 1e-12 * expected);

    const Bounds b = mesh_bounds(mesh);
    EXPECT_EQ(b.min, Vec3(-c.half));
    EXPECT_EQ(b.max, c.half);

    // The top face's triangles face up and tile the square minus the polygon exactly once.
    Real top_area = 0;
    for (const TriangleIndices& t : mesh.triangles) {
      const Vec3& p = mesh.vertices[t[0]];
      const Vec3& q = mesh.vertices[t[1]];
      const Vec3& r = mesh.vertices[t[2]];
      if (p.y() != c.half.y() || q.y() != c.half.y() || r.y() != c.half.y()) continue;
      const Vec3 n = (q - p).cross(r - p);
      EXPECT_GT(n.y(), 0);
      top_area += n.norm() / 2;
    }
    const Real face = 4 * c.half.x() * c.half.z() - polygon_area(c.sides, c.radius);
    EXPECT_NEAR(top_area, face, 1e-12 * face);

    // The wall's flats lie at the radius: every wall vertex is a corner at radius / cos(pi / n).
    const Real corner = c.radius / std::cos(std::numbers::pi / c.sides);
    for (const Vec3& p : mesh.vertices) {
      const Real rho = std::hypot(p.x(), p.z());
      if (rho < c.half.x() && rho < c.half.z() && rho > 0) {
        EXPECT_NEAR(rho, corner, 1e-15);
      }
    }
  }
}

TEST(Primitives, PegFitsTheHoleOnlyWhenNoWiderThanItsRadius) {
  const Vec3 half(0.03, 0.02, 0.03);
  const Real radius = 0.01, depth = 0.015;
  for (int sides : {8, 12, 64}) {
    SCOPED_TRACE("sides " + std::to_string(sides));
    const auto block =
        build_model(Method::kObb,
                    std::make_shared<const Mesh>(make_block_with_hole(half, radius, depth, sides)));
    // From just above the hole's floor to well above the top face.
    const Transform X = along_y(half.y() - depth + 0.001);
    for (const auto& [scale, colliding] : {std::pair{0.999, false}, std::pair{1.01, true}}) {
      const auto peg = build_model(
          Method::kObb, std::make_shared<const Mesh>(make_cylinder(scale * radius, 0.03, 256)));
      EXPECT_EQ(block->collide(*peg, X).colliding, colliding) << "peg radius x" << scale;
      EXPECT_EQ(block->collide(*peg, X, {.all_pairs = true}).colliding, colliding)
          << "peg radius x" << scale;
    }
  }
}

TEST(Primitives, AShaftFitsATubesBoreOnlyWhenNoWiderThanItsRadius) {
  // A hexagon socket too: the bore's flats, not its corners, are on the radius.
  const Real outer = 0.019, inner = 0.01225, height = 0.012;
  for (int sides : {6, 8, 64}) {
    SCOPED_TRACE("sides " + std::to_string(sides));
    const auto tube = build_model(
        Method::kObb, std::make_shared<const Mesh>(make_tube(outer, inner, height, sides)));
    Transform X;
    X.t = Vec3(0, 0, -0.01);  // the shaft runs through the whole tube
    for (const auto& [scale, colliding] : {std::pair{0.999, false}, std::pair{1.01, true}}) {
      const auto shaft = build_model(
          Method::kObb, std::make_shared<const Mesh>(make_cylinder(scale * inner, 0.04, 256)));
      EXPECT_EQ(tube->collide(*shaft, X).colliding, colliding) << "shaft radius x" << scale;
    }
  }
  EXPECT_THROW(make_tube(0.0101, 0.01, 0.01, 6), std::invalid_argument);  // corners reach out
}

TEST(Primitives, BlockWithHoleRejectsHolesThatDoNotFit) {
  const Vec3 half(0.01, 0.02, 0.01);
  EXPECT_NO_THROW(make_block_with_hole(half, 0.009, 0.01, 8));
  // The flats would fit (0.0095 < 0.01) but the corners, at 0.0095 / cos(pi / 8), do not.
  EXPECT_THROW(make_block_with_hole(half, 0.0095, 0.01, 8), std::invalid_argument);
  EXPECT_THROW(make_block_with_hole(half, 0.01, 0.01, 64), std::invalid_argument);
  EXPECT_THROW(make_block_with_hole(Vec3(0.01, 0.02, 0.005), 0.006, 0.01, 64),
               std::invalid_argument);
  EXPECT_THROW(make_block_with_hole(half, 0.005, 0.04, 8), std::invalid_argument);
  EXPECT_THROW(make_block_with_hole(half, 0.005, 0.05, 8), std::invalid_argument);
  EXPECT_NO_THROW(make_block_with_hole(half, 0.005, 0.0399, 8));
  EXPECT_THROW(make_block_with_hole(half, 0.005, 0.01, 2), std::invalid_argument);
  EXPECT_THROW(make_block_with_hole(half, 0.005, 0.01, 0), std::invalid_argument);
  EXPECT_THROW(make_block_with_hole(half, 0.005, 0.01, -3), std::invalid_argument);
  EXPECT_NO_THROW(make_block_with_hole(half, 0.005, 0.01, 3));
  EXPECT_THROW(make_block_with_hole(half, 0, 0.01, 8), std::invalid_argument);
  EXPECT_THROW(make_block_with_hole(half, -0.005, 0.01, 8), std::invalid_argument);
  EXPECT_THROW(make_block_with_hole(half, 0.005, 0, 8), std::invalid_argument);
  const Real nan = std::numeric_limits<Real>::quiet_NaN();
  const Real inf = std::numeric_limits<Real>::infinity();
  EXPECT_THROW(make_block_with_hole(half, nan, 0.01, 8), std::invalid_argument);
  EXPECT_THROW(make_block_with_hole(half, 0.005, nan, 8), std::invalid_argument);
  EXPECT_THROW(make_block_with_hole(Vec3(inf, 0.02, inf), 0.005, 0.01, 8), std::invalid_argument);
  EXPECT_THROW(make_block_with_hole(Vec3(0.01, -0.02, 0.01), 0.005, 0.01, 8),
               std::invalid_argument);
  EXPECT_THROW(make_block_with_hole(Vec3(0, 0.02, 0.01), 0.005, 0.01, 8), std::invalid_argument);
}

TEST(Primitives, CylinderRunsAlongZWithItsVerticesOnTheRadius) {
  const Mesh mesh = make_cylinder(0.01, 0.03, 32);
  expect_closed_and_oriented(mesh);
  EXPECT_GT(signed_volume(mesh), 0);
  const Bounds b = mesh_bounds(mesh);
  EXPECT_DOUBLE_EQ(b.min.z(), 0);
  EXPECT_DOUBLE_EQ(b.max.z(), 0.03);
  for (const Vec3& p : mesh.vertices) {
    const Real rho = std::hypot(p.x(), p.y());
    if (rho > 0) {
      EXPECT_NEAR(rho, 0.01, 1e-15);
    }
  }
}

}  // namespace
}  // namespace dovetail::collision
