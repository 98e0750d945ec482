#include "dovetail/collision/contacts.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <random>
#include <vector>

#include "dovetail/collision/containment.h"
#include "dovetail/collision/model.h"
#include "dovetail/collision/primitives.h"
#include "proximity/tri_distance.h"

namespace dovetail::collision {
namespace {

std::shared_ptr<const CollisionModel> model(Mesh mesh) {
  return build_model(Method::kAabb, std::make_shared<const Mesh>(std::move(mesh)));
}

Transform translation(Real x, Real y, Real z) {
  Transform X;
  X.t = Vec3(x, y, z);
  return X;
}

Transform rotation_z(Real angle, const Vec3& t) {
  Transform X;
  X.R = Eigen::AngleAxis<Real>(angle, Vec3::UnitZ()).toRotationMatrix();
  // Keep the z row exact, so the rotated faces stay exactly in their planes.
  X.R(2, 0) = X.R(2, 1) = X.R(0, 2) = X.R(1, 2) = 0;
  X.R(2, 2) = 1;
  X.t = t;
  return X;
}

/// A block [-2, 2]^2 x [0, 1] with a square through-hole [-1, 1]^2 along z;
/// closed, outward normals (the hole's walls face into the hole).
Mesh housing_with_square_hole() {
  std::vector<Vec3> v;
  const Real o = 2;
  const Real h = 1;
  for (Real z : {0.0, 1.0}) {
    for (auto [x, y] : {std::pair{-o, -o}, {o, -o}, {o, o}, {-o, o}}) v.emplace_back(x, y, z);
    for (auto [x, y] : {std::pair{-h, -h}, {h, -h}, {h, h}, {-h, h}}) v.emplace_back(x, y, z);
  }
  // Outer square 0..3 (bottom), 8..11 (top); inner square 4..7, 12..15.
  std::vector<TriangleIndices> t;
  const auto quad = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
    t.push_back({a, b, c});
    t.push_back({a, c, d});
  };
  for (std::uint32_t i = 0; i < 4; ++i) {
    const std::uint32_t j = (i + 1) % 4;
    quad(8 + i, 8 + j, 12 + j, 12 + i);  // top ring, facing +z
    quad(0 + i, 4 + i, 4 + j, 0 + j);    // bottom ring, facing -z
    quad(0 + i, 0 + j, 8 + j, 8 + i);    // outer wall, facing out
    quad(4 + i, 12 + i, 12 + j, 4 + j);  // hole wall, facing into the hole
  }
  return make_mesh(std::move(v), std::move(t), "housing");
}

/// Area of the overlap of axis-aligned rectangles [lo, hi] (x, y).
Real rect_overlap(Real ax0, Real ax1, Real ay0, Real ay1, Real bx0, Real bx1, Real by0, Real by1) {
  const Real w = std::max(0.0, std::min(ax1, bx1) - std::max(ax0, bx0));
  const Real h = std::max(0.0, std::min(ay1, by1) - std::max(ay0, by0));
  return w * h;
}

void expect_near(const Vec3& actual, const Vec3& expected, Real tol) {
  EXPECT_NEAR((actual - expected).norm(), 0.0, tol)
      << actual.transpose() << " vs " << expected.transpose();
}

TEST(Contacts, EmptyPairsGiveNoPatches) {
  const Mesh box = make_box(Vec3(1, 1, 1));
  EXPECT_TRUE(compute_contacts(box, box, translation(5, 0, 0), {}).empty());
  const auto a = model(make_box(Vec3(1, 1, 1)));
  EXPECT_TRUE(compute_contacts(*a, *a, translation(2.5, 0, 0)).empty());
}

TEST(Contacts, BoxRestingOnBoxIsOneFacePatch) {
  // A: [-2, 2]^2 x [-1, 1]; B: half extents (1, 0.5, 0.5) resting on A's top.
  const auto a = model(make_box(Vec3(2, 2, 1)));
  const auto b = model(make_box(Vec3(1, 0.5, 0.5)));
  struct Offset {
    Real x, y;
  };
  for (const Offset o : {Offset{0, 0}, Offset{0.5, -0.25}, Offset{1.5, 0.25}, Offset{-2.5, 1.75},
                         Offset{2.75, -2.25}, Offset{1, 1.5}}) {
    SCOPED_TRACE(testing::Message() << "offset " << o.x << ", " << o.y);
    const std::vector<ContactPatch> patches =
        compute_contacts(*a, *b, translation(o.x, o.y, 1.5), {.touching_tolerance = 1e-9});
    ASSERT_EQ(patches.size(), 1u);
    const ContactPatch& p = patches[0];
    const Real x0 = std::max(-2.0, o.x - 1), x1 = std::min(2.0, o.x + 1);
    const Real y0 = std::max(-2.0, o.y - 0.5), y1 = std::min(2.0, o.y + 0.5);
    const Real area = rect_overlap(-2, 2, -2, 2, o.x - 1, o.x + 1, o.y - 0.5, o.y + 0.5);
    EXPECT_EQ(p.kind, ContactKind::kFace);
    EXPECT_NEAR(p.area, area, 1e-12);
    expect_near(p.normal, Vec3(0, 0, 1), 1e-12);
    expect_near(p.point, Vec3(0.5 * (x0 + x1), 0.5 * (y0 + y1), 1), 1e-12);
    EXPECT_EQ(p.depth, 0.0);
    EXPECT_FALSE(p.penetrating);
    EXPECT_GE(p.pairs.size(), 4u);
  }
}

TEST(Contacts, LargerBoxOnSmallerBoxCoversTheWholeTop) {
  const auto a = model(make_box(Vec3(1, 1, 1)));
  const auto b = model(make_box(Vec3(3, 2, 0.5)));
  const std::vector<ContactPatch> patches = compute_contacts(*a, *b, translation(0.5, 0, 1.5));
  ASSERT_EQ(patches.size(), 1u);
  EXPECT_NEAR(patches[0].area, 4.0, 1e-12);
  expect_near(patches[0].normal, Vec3(0, 0, 1), 1e-12);
  expect_near(patches[0].point, Vec3(0, 0, 1), 1e-12);
}

TEST(Contacts, BoxRotatedAboutZGivesTheOverlapPolygonArea) {
  // B: a 2 x 2 square footprint rotated about z; A's top is [-2, 2]^2 at z = 1.
  const auto a = model(make_box(Vec3(2, 2, 1)));
  const auto b = model(make_box(Vec3(1, 1, 0.5)));
  struct Case {
    Real angle, x, y, area;
  };
  const Real pi = std::numbers::pi;
  // Inside: the whole square. Centre on an edge: a line through the centre of a
  // centrally symmetric shape halves it. Centre on a corner, rotated 45 degrees:
  // the diamond's quarter.
  for (const Case c : {Case{0.3, 0, 0, 4}, Case{pi / 6, 0.4, -0.2, 4}, Case{pi / 4, 2, 0, 2},
                       Case{pi / 6, 0, -2, 2}, Case{1.1, -2, 0.3, 2}, Case{pi / 4, 2, 2, 1}}) {
    SCOPED_TRACE(testing::Message() << "angle " << c.angle << " at " << c.x << ", " << c.y);
    const std::vector<ContactPatch> patches =
        compute_contacts(*a, *b, rotation_z(c.angle, Vec3(c.x, c.y, 1.5)));
    ASSERT_EQ(patches.size(), 1u);
    EXPECT_EQ(patches[0].kind, ContactKind::kFace);
    EXPECT_NEAR(patches[0].area, c.area, 1e-12);
    expect_near(patches[0].normal, Vec3(0, 0, 1), 1e-12);
    EXPECT_NEAR(patches[0].point.z(), 1.0, 1e-12);
    EXPECT_FALSE(patches[0].penetrating);
  }
}

TEST(Contacts, SquarePegAgainstHoleWallIsAFacePatchAcrossTheAxis) {
  const auto housing = model(housing_with_square_hole());
  // Peg [0, 1] x [-0.5, 0.5] x [-0.5, 1.5]: its +x face lies on the wall x = 1.
  const auto peg = model(make_box(Vec3(0.5, 0.5, 1)));
  const std::vector<ContactPatch> patches =
      compute_contacts(*housing, *peg, translation(0.5, 0, 0.5));
  ASSERT_EQ(patches.size(), 1u);
  EXPECT_EQ(patches[0].kind, ContactKind::kFace);
  EXPECT_NEAR(patches[0].area, 1.0, 1e-12);  // y in [-0.5, 0.5], z in [0, 1]
  expect_near(patches[0].normal, Vec3(-1, 0, 0), 1e-12);
  expect_near(patches[0].point, Vec3(1, 0, 0.5), 1e-12);
  EXPECT_FALSE(patches[0].penetrating);
}

TEST(Contacts, CylinderPegTouchingOneSideOfTheHole) {
  const auto housing = model(housing_with_square_hole());
  // Radius 0.5, 16 facets, vertex 0 at (0.5, 0): moved by 0.5 it touches x = 1 along a line.
  const auto peg = model(make_cylinder(0.5, 2, 16));
  const std::vector<ContactPatch> patches =
      compute_contacts(*housing, *peg, translation(0.5, 0, -0.5));
  ASSERT_EQ(patches.size(), 1u);
  const ContactPatch& p = patches[0];
  EXPECT_EQ(p.kind, ContactKind::kCurve);
  EXPECT_EQ(p.area, 0.0);
  EXPECT_NEAR(p.length, 1.0, 1e-12);  // the housing's height
  expect_near(p.normal, Vec3(-1, 0, 0), 1e-12);
  EXPECT_NEAR(p.normal.z(), 0.0, 1e-15);  // perpendicular to the hole's axis
  expect_near(p.point, Vec3(1, 0, 0.5), 1e-12);
  EXPECT_NEAR(p.depth, 0.0, 1e-15);
  EXPECT_FALSE(p.penetrating);
}

TEST(Contacts, CylinderPegTouchingFourSidesGivesFourPatches) {
  const auto housing = model(housing_with_square_hole());
  // Radius 1: vertices at angles 0, 90, 180, 270 degrees touch the four walls.
  const auto peg = model(make_cylinder(1, 2, 16));
  const std::vector<ContactPatch> patches =
      compute_contacts(*housing, *peg, translation(0, 0, -0.5));
  ASSERT_EQ(patches.size(), 4u);
  for (const ContactPatch& p : patches) {
    EXPECT_NEAR(p.normal.z(), 0.0, 1e-12);
    // Each normal points across the axis, from the wall towards the hole's centre.
    const Vec3 to_axis = Vec3(-p.point.x(), -p.point.y(), 0).normalized();
    expect_near(p.normal, to_axis, 1e-9);
    EXPECT_NEAR(Vec3(p.point.x(), p.point.y(), 0).norm(), 1.0, 1e-9);
    EXPECT_FALSE(p.penetrating);
  }
}

/// Patches of (b, a) at X_AB's inverse, mapped back into A's frame, match (a, b)'s
/// with the normals flipped.
void expect_swap_symmetric(const CollisionModel& a, const CollisionModel& b,
                           const Transform& X_AB) {
  const std::vector<ContactPatch> ab = compute_contacts(a, b, X_AB);
  const std::vector<ContactPatch> ba = compute_contacts(b, a, X_AB.inverse());
  ASSERT_EQ(ab.size(), ba.size());
  ASSERT_FALSE(ab.empty());
  for (const ContactPatch& q : ba) {
    const Vec3 point_A = X_AB.apply(q.point);
    const Vec3 normal_A = X_AB.R * q.normal;
    const ContactPatch* match = nullptr;
    for (const ContactPatch& p : ab) {
      if ((p.point - point_A).norm() < 1e-9) match = &p;
    }
    ASSERT_NE(match, nullptr) << "no patch at " << point_A.transpose();
    expect_near(normal_A, -match->normal, 1e-9);
    EXPECT_NEAR(q.area, match->area, 1e-12);
    EXPECT_NEAR(q.length, match->length, 1e-12);
    EXPECT_NEAR(q.depth, match->depth, 1e-12);
    EXPECT_EQ(q.kind, match->kind);
    EXPECT_EQ(q.pairs.size(), match->pairs.size());
  }
}

TEST(Contacts, SwappingAAndBFlipsTheNormals) {
  const auto big = model(make_box(Vec3(2, 2, 1)));
  const auto small = model(make_box(Vec3(1, 0.5, 0.5)));
  expect_swap_symmetric(*big, *small, translation(1.5, 0.25, 1.5));
  const auto square = model(make_box(Vec3(1, 1, 0.5)));
  expect_swap_symmetric(*big, *square, rotation_z(std::numbers::pi / 6, Vec3(0, -2, 1.5)));
  expect_swap_symmetric(*big, *square, translation(0.5, 0.5, 1.4));  // penetrating
  const auto housing = model(housing_with_square_hole());
  expect_swap_symmetric(*housing, *model(make_cylinder(0.5, 2, 16)), translation(0.5, 0, -0.5));
  expect_swap_symmetric(*housing, *model(make_cylinder(1, 2, 16)), translation(0, 0, -0.5));
  expect_swap_symmetric(*housing, *model(make_box(Vec3(0.5, 0.5, 1))), translation(0.5, 0, 0.5));
}

TEST(Contacts, TouchingAndPenetratingAreToldApart) {
  const auto a = model(make_box(Vec3(2, 2, 1)));
  const auto b = model(make_box(Vec3(1, 1, 0.5)));
  struct Case {
    Real z;  // B's centre; 1.5 is exact touching
    Real tolerance;
    Real depth;
    bool penetrating;
  };
  for (const Case c :
       {Case{1.5, 1e-6, 0, false}, Case{1.5, 0, 0, false}, Case{1.4, 1e-6, 0.1, true},
        Case{1.4, 0.2, 0.1, false}, Case{1.5 - 1e-4, 1e-3, 1e-4, false},
        Case{1.5 - 1e-4, 1e-5, 1e-4, true}, Case{1.25, 1e-6, 0.25, true}}) {
    SCOPED_TRACE(testing::Message() << "z " << c.z << " tolerance " << c.tolerance);
    const std::vector<ContactPatch> patches =
        compute_contacts(*a, *b, translation(0.5, -0.25, c.z), {.touching_tolerance = c.tolerance});
    ASSERT_EQ(patches.size(), 1u);
    EXPECT_NEAR(patches[0].depth, c.depth, 1e-12);
    EXPECT_EQ(patches[0].penetrating, c.penetrating);
    expect_near(patches[0].normal, Vec3(0, 0, 1), 1e-12);
  }
  // Sunk boxes cross along a curve around B's footprint.
  const std::vector<ContactPatch> sunk = compute_contacts(*a, *b, translation(0.5, -0.25, 1.4));
  EXPECT_EQ(sunk[0].kind, ContactKind::kCurve);
  EXPECT_NEAR(sunk[0].length, 8.0, 1e-12);
  expect_near(sunk[0].point, Vec3(0.5, -0.25, 1), 1e-12);
}

/// Two closed boxes as one mesh (two shells), the second offset by `offset`.
Mesh two_boxes(const Vec3& half_1, const Vec3& offset_1, const Vec3& half_2, const Vec3& offset_2) {
  std::vector<Vec3> v;
  std::vector<TriangleIndices> t;
  for (const auto& [half, offset] : {std::pair{half_1, offset_1}, std::pair{half_2, offset_2}}) {
    const Mesh box = make_box(half);
    const auto base = static_cast<std::uint32_t>(v.size());
    for (const Vec3& p : box.vertices) v.push_back(p + offset);
    for (const TriangleIndices& f : box.triangles)
      t.push_back({f[0] + base, f[1] + base, f[2] + base});
  }
  return make_mesh(std::move(v), std::move(t), "two boxes");
}

TEST(Contacts, DepthOfCurvedAndShallowOverlaps) {
  // Curved overlaps, whose deepest vertices belong to triangles that cross
  // nothing: the deepest vertex inside the other part counts.
  const auto sphere = model(make_sphere(1.0, 3));
  const auto box = model(make_box(Vec3(2, 2, 1)));
  for (const Real d : {0.1, 0.5, 1.0}) {
    const std::vector<ContactPatch> spheres =
        compute_contacts(*sphere, *sphere, translation(2 - d, 0, 0));
    ASSERT_EQ(spheres.size(), 1u) << d;
    // The pole's distance to the other's faceted surface: just under d.
    EXPECT_LE(spheres[0].depth, d + 1e-12) << d;
    EXPECT_GE(spheres[0].depth, 0.99 * d) << d;
    const std::vector<ContactPatch> sunk =
        compute_contacts(*box, *sphere, translation(0.1, 0.2, 2 - d));
    ASSERT_EQ(sunk.size(), 1u) << d;
    EXPECT_NEAR(sunk[0].depth, d, 1e-12) << d;
  }
  // Shallow overlaps with parts of a mesh past the contact that are not
  // inside the other part, which must not count: a box sunk 0.01 while
  // overhanging an edge (a tilted patch normal); a T pressed 0.01 into a
  // housing with its pin hanging free in the hole; a sphere of radius 1.05
  // in the square hole of half-width 1 (0.05 into each wall).
  const std::vector<ContactPatch> overhang =
      compute_contacts(*box, *model(make_box(Vec3(1, 1, 0.5))), translation(1.5, 0, 1.49));
  ASSERT_EQ(overhang.size(), 1u);
  EXPECT_NEAR(overhang[0].depth, 0.01, 1e-12);
  const auto housing = model(housing_with_square_hole());
  const auto tee =
      model(two_boxes(Vec3(1.5, 1.5, 0.1), Vec3(0, 0, 1.09), Vec3(0.5, 0.5, 0.6), Vec3(0, 0, 0.6)));
  const std::vector<ContactPatch> pressed = compute_contacts(*housing, *tee, Transform());
  ASSERT_FALSE(pressed.empty());
  for (const ContactPatch& p : pressed) EXPECT_NEAR(p.depth, 0.01, 1e-12);
  const std::vector<ContactPatch> seated =
      compute_contacts(*housing, *model(make_sphere(1.05, 3)), translation(0, 0, 0.5));
  ASSERT_EQ(seated.size(), 4u);
  for (const ContactPatch& p : seated) EXPECT_NEAR(p.depth, 0.05, 1e-9);
  // Exactly touching stays at 0.
  const std::vector<ContactPatch> resting =
      compute_contacts(*box, *model(make_box(Vec3(0.5, 0.5, 0.5))), translation(0, 0, 1.5));
  ASSERT_EQ(resting.size(), 1u);
  EXPECT_EQ(resting[0].depth, 0);
}

/// Independent reference for the depth of closed parts: the largest distance
/// to the other's surface of a point of either part's edges inside the other
/// (every vertex, and points every `spacing` along every edge, located
/// exactly; every triangle measured), in A's frame. 0 spacing: vertices only.
Real deepest_edge_point_inside(const Mesh& a, const Mesh& b, const Transform& X_AB,
                               Real spacing = 0) {
  const auto one_way = [spacing](const Mesh& part, const Transform& X_AP, const Mesh& other,
                                 const Transform& X_AO) {
    const PointLocator locator(other, X_AO);
    Vec3 lo = Vec3::Constant(std::numeric_limits<Real>::infinity()), hi = -lo;
    std::vector<detail::TriangleVertices> surface;
    for (const TriangleIndices& f : other.triangles) {
      surface.push_back({X_AO.apply(other.vertices[f[0]]), X_AO.apply(other.vertices[f[1]]),
                         X_AO.apply(other.vertices[f[2]])});
      for (const Vec3& v : surface.back()) {
        lo = lo.cwiseMin(v);
        hi = hi.cwiseMax(v);
      }
    }
    Real best = 0;
    const auto measure = [&](const Vec3& p) {
      if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any()) return;
      if (locator.locate(p) != PointLocation::kInside) return;
      Real nearest = std::numeric_limits<Real>::infinity();
      for (const detail::TriangleVertices& t : surface) {
        nearest = std::min(nearest, (p - detail::closest_point_on_triangle(p, t)).norm());
      }
      best = std::max(best, nearest);
    };
    for (const Vec3& v : part.vertices) measure(X_AP.apply(v));
    if (spacing == 0) return best;
    for (const TriangleIndices& f : part.triangles) {
      for (int k = 0; k < 3; ++k) {
        const Vec3 p = X_AP.apply(part.vertices[f[k]]);
        const Vec3 q = X_AP.apply(part.vertices[f[(k + 1) % 3]]);
        const int n = static_cast<int>(std::ceil((q - p).norm() / spacing));
        for (int i = 1; i < n; ++i) measure(p + (q - p) * (Real(i) / n));
      }
    }
    return best;
  };
  return std::max(one_way(b, X_AB, a, Transform()), one_way(a, Transform(), b, X_AB));
}

TEST(Contacts, DepthEqualsTheDeepestPointInsideOnTurnedBoxes) {
  // A unit box at random rotations with one corner on a slab's top face and
  // the lowest corner inside, the others out or nearly on the face (or
  // through the slab's bottom): the depth must be the independent
  // reference's (a corner within rounding of the face once read as the
  // whole box's height). Vertices are located exactly; the deepest point of
  // an edge is searched to a thousandth of the depth and sampled by the
  // reference every 0.001.
  const Mesh box = make_box(Vec3(0.5, 0.5, 0.5));
  const Mesh slab = make_box(Vec3(5, 5, 0.5));
  const auto box_model = model(box), slab_model = model(slab);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<Real> u(-1, 1);
  int compared = 0;
  for (int i = 0; i < 150; ++i) {
    Transform X_AB;  // the slab in the box's frame
    const Vec3 axis = Vec3(u(rng), u(rng), u(rng)).normalized();
    X_AB.R = Eigen::AngleAxisd(std::numbers::pi * u(rng), axis).toRotationMatrix();
    std::vector<std::pair<Real, int>> heights;  // the box's corners over the slab
    for (int k = 0; k < 8; ++k) heights.push_back({(X_AB.R.transpose() * box.vertices[k]).z(), k});
    std::sort(heights.begin(), heights.end());
    X_AB.t = box.vertices[heights[1].second] - X_AB.R * Vec3(0.1 * u(rng), 0.1 * u(rng), 0.5);
    const std::vector<ContactPatch> patches = compute_contacts(*box_model, *slab_model, X_AB);
    if (patches.empty()) continue;
    Real depth = 0;
    for (const ContactPatch& p : patches) depth = std::max(depth, p.depth);
    // Never less than the deepest vertex, located and measured exactly.
    EXPECT_GE(depth, deepest_edge_point_inside(box, slab, X_AB) - 1e-9) << "case " << i;
    const Real reference = deepest_edge_point_inside(box, slab, X_AB, 1e-3);
    EXPECT_LE(depth, reference + 1e-3 / 2 + 1e-9) << "case " << i;
    EXPECT_GE(depth, reference - 1e-3 * reference - 1e-9) << "case " << i;
    ++compared;
  }
  EXPECT_GT(compared, 100);
  // A corner one ulp below the other's face: the same depth both ways round.
  const Real face = -0.5 + 0.7;
  Mesh tetra = make_mesh({Vec3(0, 0, std::nextafter(face, -1.0)), Vec3(0.5, 0, 0.21),
                          Vec3(-0.5, 0.5, -0.8), Vec3(-0.5, -0.5, -0.8)},
                         {{0, 2, 1}, {0, 3, 2}, {0, 1, 3}, {1, 2, 3}}, "tetra");
  ASSERT_TRUE(is_closed(tetra));
  const auto t_model = model(tetra);
  const auto top = model(make_box(Vec3(2, 2, 0.5)));
  const std::vector<ContactPatch> one = compute_contacts(*t_model, *top, translation(0, 0, 0.7));
  const std::vector<ContactPatch> other = compute_contacts(*top, *t_model, translation(0, 0, -0.7));
  ASSERT_EQ(one.size(), 1u);
  ASSERT_EQ(other.size(), 1u);
  EXPECT_NEAR(one[0].depth, 0.01, 1e-12);
  EXPECT_NEAR(other[0].depth, 0.01, 1e-12);
}

TEST(Contacts, PartsThatCrossWithNoVertexInsideHaveTheDepthOfTheirEdges) {
  // A square rod (0.2 across, 4 long) through a slab 1 thick, turned 30
  // degrees about y and shifted off the slab's triangle diagonals: no vertex
  // of either is inside the other, yet the rod's long edges cross the slab,
  // and their deepest points are at its mid-plane, 0.5 from both faces.
  const auto slab = model(make_box(Vec3(3, 3, 0.5)));
  const auto rod = model(make_box(Vec3(0.1, 0.1, 2)));
  Transform X_AB;
  X_AB.R = Eigen::AngleAxisd(std::numbers::pi / 6, Vec3::UnitY()).toRotationMatrix();
  X_AB.t = Vec3(0.3, 0.7, 0);
  const std::vector<ContactPatch> crossing = compute_contacts(*slab, *rod, X_AB);
  ASSERT_EQ(crossing.size(), 2u);  // where the rod enters the top face and leaves the bottom
  EXPECT_EQ(deepest_edge_point_inside(slab->mesh(), rod->mesh(), X_AB), 0) << "no vertex inside";
  for (const ContactPatch& p : crossing) {
    EXPECT_TRUE(p.penetrating);
    EXPECT_NEAR(p.depth, 0.5, 1e-3 * 0.5);
    EXPECT_LE(p.depth, 0.5 + 1e-12);
  }
  // The same both ways round.
  for (const ContactPatch& p : compute_contacts(*rod, *slab, X_AB.inverse())) {
    EXPECT_NEAR(p.depth, 0.5, 1e-3 * 0.5);
  }
  // A rod that only touches the slab's top face with one long edge, lying
  // on it (up to the rounding of its turn), is touching.
  Transform lying;
  lying.R = Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitY()).toRotationMatrix();
  lying.t = Vec3(0.3, 0.7, 0.6);
  const std::vector<ContactPatch> resting = compute_contacts(*slab, *rod, lying);
  ASSERT_FALSE(resting.empty());
  for (const ContactPatch& p : resting) {
    EXPECT_FALSE(p.penetrating);
    EXPECT_LT(p.depth, 1e-12);
  }
}

TEST(Contacts, DepthIntoBodiesThatTouchIsMeasuredToTheirSurface) {
  // A cabinet's side wall and top panel exported as one mesh, touching
  // along the wall's top face (welded at the shared edge), and a drawer 1
  // deeper than the opening pushed in by 30: the depth is the 1 of the
  // side, as with the wall alone, not the 30 of the push.
  const Mesh wall = make_box(Vec3(9, 51, 160));
  const Mesh panel = make_box(Vec3(219, 9, 160));
  std::vector<Vec3> v;
  std::vector<TriangleIndices> t;
  const auto add = [&](const Mesh& m, const Vec3& at) {
    const auto base = static_cast<std::uint32_t>(v.size());
    for (const Vec3& p : m.vertices) v.push_back(p + at);
    for (const TriangleIndices& f : m.triangles)
      t.push_back({f[0] + base, f[1] + base, f[2] + base});
  };
  add(wall, Vec3(210, 0, -160));
  add(panel, Vec3(0, 60, -160));
  const Mesh cabinet = make_mesh(std::move(v), std::move(t), "wall and top");
  ASSERT_TRUE(is_closed(cabinet));
  const auto cabinet_model = model(cabinet);
  const auto wall_model = model([&] {
    Mesh m = make_box(Vec3(9, 51, 160));
    for (Vec3& p : m.vertices) p += Vec3(210, 0, -160);
    return m;
  }());
  const auto drawer = model(make_box(Vec3(202, 50, 150)));
  for (const Real push : {10.0, 30.0, 60.0}) {
    for (const auto* a : {cabinet_model.get(), wall_model.get()}) {
      const std::vector<ContactPatch> patches =
          compute_contacts(*a, *drawer, translation(0, 0, 150 - push));
      ASSERT_FALSE(patches.empty()) << push;
      Real depth = 0;
      for (const ContactPatch& p : patches) depth = std::max(depth, p.depth);
      EXPECT_NEAR(depth, 1.0, 1e-9) << "push " << push;
    }
  }
}

TEST(Contacts, VertexOnFaceIsAPointPatch) {
  // An octahedron standing on one vertex on A's top face.
  std::vector<Vec3> v = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  std::vector<TriangleIndices> t = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                                    {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  const auto a = model(make_box(Vec3(2, 2, 1)));
  const auto b = model(make_mesh(std::move(v), std::move(t), "octahedron"));
  const std::vector<ContactPatch> patches = compute_contacts(*a, *b, translation(0.25, -0.75, 2));
  ASSERT_EQ(patches.size(), 1u);
  EXPECT_EQ(patches[0].kind, ContactKind::kPoint);
  expect_near(patches[0].point, Vec3(0.25, -0.75, 1), 1e-15);
  expect_near(patches[0].normal, Vec3(0, 0, 1), 1e-12);
  EXPECT_EQ(patches[0].pairs.size(), 4u);
  EXPECT_FALSE(patches[0].penetrating);
}

TEST(Contacts, SeparateRegionsAreSeparatePatchesInPairOrder) {
  // B bridges two blocks: two face patches, ordered by their smallest pair.
  std::vector<Vec3> v;
  std::vector<TriangleIndices> t;
  for (Real cx : {-3.0, 3.0}) {
    const Mesh block = make_box(Vec3(1, 1, 1));
    const auto base = static_cast<std::uint32_t>(v.size());
    for (const Vec3& p : block.vertices) v.push_back(p + Vec3(cx, 0, 0));
    for (const TriangleIndices& f : block.triangles)
      t.push_back({f[0] + base, f[1] + base, f[2] + base});
  }
  const Mesh two = make_mesh(std::move(v), std::move(t), "two blocks");
  const Mesh plank = make_box(Vec3(4, 0.5, 0.25));
  const auto a = model(two);
  const auto b = model(plank);
  const std::vector<ContactPatch> patches = compute_contacts(*a, *b, translation(0, 0, 1.25));
  ASSERT_EQ(patches.size(), 2u);
  EXPECT_LT(patches[0].pairs.front(), patches[1].pairs.front());
  for (const ContactPatch& p : patches) {
    EXPECT_NEAR(p.area, 2.0, 1e-12);  // x in [2, 4] (or [-4, -2]) times y in [-0.5, 0.5]
    expect_near(p.normal, Vec3(0, 0, 1), 1e-12);
  }
  EXPECT_NEAR(patches[0].point.x(), -3.0, 1e-12);
  EXPECT_NEAR(patches[1].point.x(), 3.0, 1e-12);

  // The same through the span overload, pairs given shuffled and duplicated.
  CollideResult hits = a->collide(*b, translation(0, 0, 1.25), {.all_pairs = true});
  std::vector<TrianglePair> shuffled(hits.pairs.rbegin(), hits.pairs.rend());
  shuffled.push_back(hits.pairs.front());
  const std::vector<ContactPatch> again =
      compute_contacts(two, plank, translation(0, 0, 1.25), shuffled);
  ASSERT_EQ(again.size(), 2u);
  EXPECT_EQ(again[0].pairs, patches[0].pairs);
  EXPECT_EQ(again[1].pairs, patches[1].pairs);
}

TEST(Contacts, NearlyCoplanarFacesInARotatedFrame) {
  // Both boxes turned by one general rotation Q: B's bottom lies on A's top up
  // to rounding, so the faces are coplanar only within the tolerance.
  const Mat3 Q = Eigen::AngleAxis<Real>(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Mesh box_a = make_box(Vec3(2, 2, 1));
  std::vector<Vec3> va;
  for (const Vec3& p : box_a.vertices) va.push_back(Q * p);
  const auto a = model(make_mesh(va, box_a.triangles, "rotated box"));
  const auto b = model(make_box(Vec3(1, 0.5, 0.5)));
  // X_AB = Q * translation(0.5, 0, 1.5 - push): B pushed into A by up to 1e-12,
  // then rotated. The bottom faces are found within the coplanar tolerance
  // even where the exact test sees a gap of a few ulps.
  for (const Real push : {0.0, 1e-15, 1e-12}) {
    SCOPED_TRACE(testing::Message() << "push " << push);
    Transform X;
    X.R = Q;
    X.t = Q * Vec3(0.5, 0, 1.5 - push);
    const std::vector<ContactPatch> patches = compute_contacts(*a, *b, X);
    ASSERT_EQ(patches.size(), 1u);
    EXPECT_EQ(patches[0].kind, ContactKind::kFace);
    EXPECT_NEAR(patches[0].area, 2.0, 1e-9);
    expect_near(patches[0].normal, Q * Vec3(0, 0, 1), 1e-9);
    EXPECT_LT(patches[0].depth, 1e-9);
    EXPECT_FALSE(patches[0].penetrating);
    expect_near(patches[0].point, Q * Vec3(0.5, 0, 1), 1e-9);
  }
  // Beyond the coplanar tolerance the bottom faces do not count: B sunk by 1e-6
  // crosses A's top along its footprint's rim.
  Transform X;
  X.R = Q;
  X.t = Q * Vec3(0.5, 0, 1.5 - 1e-6);
  const std::vector<ContactPatch> sunk = compute_contacts(*a, *b, X, {.touching_tolerance = 1e-7});
  ASSERT_EQ(sunk.size(), 1u);
  EXPECT_EQ(sunk[0].kind, ContactKind::kCurve);
  EXPECT_NEAR(sunk[0].depth, 1e-6, 1e-12);
  EXPECT_TRUE(sunk[0].penetrating);
}

TEST(Contacts, FannedCapRestingInARotatedFrameIsOneFacePatchOnlyWithTheCoplanarSearch) {
  // A cylinder whose caps are fans of 64 slivers stands on a box, both turned
  // by one general rotation: the cap lies on the top up to rounding. The
  // search for nearly coplanar pairs finds the whole cap (the exact test sees
  // only some of its slivers touching); without it, the patch is made of the
  // intersecting pairs alone, a subset.
  const Mat3 Q = Eigen::AngleAxis<Real>(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Mesh box_a = make_box(Vec3(2, 2, 1));
  std::vector<Vec3> va;
  for (const Vec3& p : box_a.vertices) va.push_back(Q * p);
  const auto a = model(make_mesh(va, box_a.triangles, "rotated box"));
  constexpr int kSides = 64;
  constexpr Real kRadius = 0.4;
  const Mesh cylinder = make_cylinder(kRadius, 0.5, kSides);
  Real bottom = std::numeric_limits<Real>::infinity();
  for (const Vec3& p : cylinder.vertices) bottom = std::min(bottom, p.z());
  const auto b = model(cylinder);
  Transform X;
  X.R = Q;
  X.t = Q * Vec3(0.3, -0.2, 1 - bottom);
  const std::vector<ContactPatch> searched = compute_contacts(*a, *b, X);
  const std::vector<ContactPatch> exact_only =
      compute_contacts(*a, *b, X, {.nearly_coplanar_pairs = false});
  ASSERT_EQ(searched.size(), 1u);
  EXPECT_EQ(searched[0].kind, ContactKind::kFace);
  const Real cap_area = 0.5 * kSides * kRadius * kRadius * std::sin(2 * std::numbers::pi / kSides);
  EXPECT_NEAR(searched[0].area, cap_area, 1e-9);
  expect_near(searched[0].normal, Q * Vec3(0, 0, 1), 1e-9);
  std::vector<TrianglePair> exact_pairs;
  for (const ContactPatch& patch : exact_only) {
    exact_pairs.insert(exact_pairs.end(), patch.pairs.begin(), patch.pairs.end());
  }
  std::sort(exact_pairs.begin(), exact_pairs.end());
  EXPECT_LT(exact_pairs.size(), searched[0].pairs.size());
  EXPECT_TRUE(std::includes(searched[0].pairs.begin(), searched[0].pairs.end(), exact_pairs.begin(),
                            exact_pairs.end()));
  // The search's result does not depend on where it starts: from the
  // intersecting pairs given in reverse order, the same patch to the bit.
  const CollideResult hits = a->collide(*b, X, {.all_pairs = true});
  std::vector<TrianglePair> reversed(hits.pairs.rbegin(), hits.pairs.rend());
  const std::vector<ContactPatch> again = compute_contacts(a->mesh(), b->mesh(), X, reversed);
  ASSERT_EQ(again.size(), 1u);
  EXPECT_EQ(again[0].pairs, searched[0].pairs);
  EXPECT_EQ(again[0].area, searched[0].area);
  EXPECT_EQ(again[0].point, searched[0].point);
}

}  // namespace
}  // namespace dovetail::collision
