#include "dovetail/collision/containment.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <random>
#include <tuple>
#include <vector>

#include "dovetail/collision/model.h"
#include "dovetail/collision/primitives.h"

namespace dovetail::collision {
namespace {

Transform translation(Real x, Real y, Real z) {
  Transform X;
  X.t = Vec3(x, y, z);
  return X;
}

/// A box with half extents `outer` and a cavity with half extents `inner`:
/// the inner box's triangles reversed so its faces point into the cavity.
Mesh hollow_box(const Vec3& outer, const Vec3& inner) {
  const Mesh a = make_box(outer);
  const Mesh b = make_box(inner);
  std::vector<Vec3> v = a.vertices;
  std::vector<TriangleIndices> t = a.triangles;
  const auto base = static_cast<std::uint32_t>(v.size());
  v.insert(v.end(), b.vertices.begin(), b.vertices.end());
  for (const TriangleIndices& f : b.triangles) t.push_back({f[0] + base, f[2] + base, f[1] + base});
  return make_mesh(std::move(v), std::move(t), "hollow box");
}

TEST(Containment, IsClosed) {
  EXPECT_TRUE(is_closed(make_box(Vec3(1, 2, 3))));
  EXPECT_TRUE(is_closed(make_sphere(1, 2)));
  EXPECT_TRUE(is_closed(make_torus(2, 0.5, 16, 8)));
  EXPECT_TRUE(is_closed(make_cylinder(1, 2, 12)));
  EXPECT_TRUE(is_closed(hollow_box(Vec3(2, 2, 2), Vec3(1, 1, 1))));
  EXPECT_FALSE(is_closed(make_wavy_sheet(1, 0.1, 3, 5)));

  // A box with one triangle removed is open; with one triangle flipped it is inconsistent.
  Mesh box = make_box(Vec3(1, 1, 1));
  Mesh open = box;
  open.triangles.pop_back();
  EXPECT_FALSE(is_closed(open));
  Mesh flipped = box;
  std::swap(flipped.triangles[3][1], flipped.triangles[3][2]);
  EXPECT_FALSE(is_closed(flipped));

  // Split vertices (every triangle with its own copies) are welded by position.
  std::vector<Vec3> v;
  std::vector<TriangleIndices> t;
  for (const TriangleIndices& f : box.triangles) {
    const auto base = static_cast<std::uint32_t>(v.size());
    for (std::uint32_t i : f) v.push_back(box.vertices[i]);
    t.push_back({base, base + 1, base + 2});
  }
  EXPECT_TRUE(is_closed(make_mesh(std::move(v), std::move(t), "split box")));
}

TEST(Containment, SurfaceEdgesCountWhatKeepsAMeshOpen) {
  const Mesh box = make_box(Vec3(1, 1, 1));
  EXPECT_TRUE(surface_edges(box).closed());
  EXPECT_TRUE(surface_edges(make_torus(2, 0.5, 16, 8)).closed());

  // One triangle removed: its three edges are each left on one triangle.
  Mesh open = box;
  open.triangles.pop_back();
  EXPECT_EQ(surface_edges(open).open, 3u);
  EXPECT_EQ(surface_edges(open).misoriented, 0u);

  // One triangle flipped: its three edges run the same way as its
  // neighbours'; nothing is missing.
  Mesh flipped = box;
  std::swap(flipped.triangles[3][1], flipped.triangles[3][2]);
  EXPECT_EQ(surface_edges(flipped).open, 0u);
  EXPECT_EQ(surface_edges(flipped).misoriented, 3u);

  // Both at once, on two different triangles.
  Mesh both = flipped;
  both.triangles.erase(both.triangles.begin() + 8);
  const SurfaceEdges counts = surface_edges(both);
  EXPECT_GT(counts.open, 0u);
  EXPECT_GT(counts.misoriented, 0u);

  // The same verdict as is_closed on every mesh of the tests above.
  for (const Mesh& mesh : {box, open, flipped, both, make_wavy_sheet(1, 0.1, 3, 5)}) {
    EXPECT_EQ(surface_edges(mesh).closed(), is_closed(mesh));
  }
}

/// Two boxes in one mesh, as a CAD export writes an assembly of bodies: the
/// second box's vertices moved by `offset`; no welding but by position.
Mesh two_boxes(const Vec3& half_a, const Vec3& half_b, const Vec3& offset) {
  const Mesh a = make_box(half_a);
  const Mesh b = make_box(half_b);
  std::vector<Vec3> v = a.vertices;
  std::vector<TriangleIndices> t = a.triangles;
  const auto base = static_cast<std::uint32_t>(v.size());
  for (const Vec3& p : b.vertices) v.push_back(p + offset);
  for (const TriangleIndices& f : b.triangles) t.push_back({f[0] + base, f[1] + base, f[2] + base});
  return make_mesh(std::move(v), std::move(t), "two boxes");
}

TEST(Containment, BodiesThatTouchAreClosedTogether) {
  // Sharing an edge (welded vertices: four triangles at the edge), sharing
  // a whole face (two opposed faces), and a box standing on another's face
  // (a face inside the other's face) are closed, and a point is inside
  // exactly where it is inside one of the boxes.
  const Vec3 half(1, 1, 1);
  for (const Vec3& offset : {Vec3(2, 2, 0), Vec3(2, 0, 0), Vec3(0, 0, 1.5)}) {
    const Mesh bodies = offset.z() > 0 ? two_boxes(half, Vec3(0.5, 0.5, 0.5), offset)
                                       : two_boxes(half, half, offset);
    EXPECT_TRUE(is_closed(bodies)) << offset.transpose();
    EXPECT_EQ(locate_point(bodies, Vec3(0.5, 0.5, 0.5)), PointLocation::kInside);
    EXPECT_EQ(locate_point(bodies, offset + Vec3(0.2, -0.3, 0.1)), PointLocation::kInside);
    EXPECT_EQ(locate_point(bodies, Vec3(0, 0, 5)), PointLocation::kOutside);
  }
  EXPECT_EQ(locate_point(two_boxes(half, half, Vec3(2, 2, 0)), Vec3(1.5, 0.5, 0)),
            PointLocation::kOutside);
  // Every face written twice, and two boxes that overlap: inside where the
  // surfaces wind around the point, not by the parity of the crossings
  // (two crossings where one would do).
  Mesh twice = make_box(half);
  const std::vector<TriangleIndices> faces = twice.triangles;
  twice.triangles.insert(twice.triangles.end(), faces.begin(), faces.end());
  EXPECT_TRUE(is_closed(twice));
  EXPECT_EQ(locate_point(twice, Vec3(0.2, 0.1, 0.3)), PointLocation::kInside);
  EXPECT_EQ(locate_point(twice, Vec3(3, 0, 0)), PointLocation::kOutside);
  const Mesh overlapping = two_boxes(half, half, Vec3(1, 0.5, 0.25));
  EXPECT_EQ(locate_point(overlapping, Vec3(0.5, 0.5, 0.5)), PointLocation::kInside);
  EXPECT_EQ(locate_point(overlapping, Vec3(1.5, 1.2, 1)), PointLocation::kInside);
  EXPECT_EQ(locate_point(overlapping, Vec3(-0.5, 1.2, 0)), PointLocation::kOutside);
  // Still open with a triangle missing, still inconsistent with one flipped.
  Mesh open = two_boxes(half, half, Vec3(2, 2, 0));
  open.triangles.pop_back();
  EXPECT_FALSE(is_closed(open));
  Mesh flipped = two_boxes(half, half, Vec3(2, 0, 0));
  std::swap(flipped.triangles[15][1], flipped.triangles[15][2]);
  EXPECT_FALSE(is_closed(flipped));
}

TEST(Containment, PointInsideBoxSphereAndTorus) {
  const Mesh box = make_box(Vec3(1, 1, 1));
  EXPECT_EQ(locate_point(box, Vec3(0, 0, 0)), PointLocation::kInside);
  EXPECT_EQ(locate_point(box, Vec3(0.999, -0.999, 0.5)), PointLocation::kInside);
  EXPECT_EQ(locate_point(box, Vec3(1.001, 0, 0)), PointLocation::kOutside);
  EXPECT_EQ(locate_point(box, Vec3(5, 5, 5)), PointLocation::kOutside);
  // On a face, an edge, a vertex, and on a face diagonal: exactly on the surface.
  for (const Vec3& p :
       {Vec3(1, 0.3, -0.2), Vec3(1, 1, 0.5), Vec3(-1, -1, 1), Vec3(0.5, 0.5, 1), Vec3(0, 0, -1)}) {
    EXPECT_EQ(locate_point(box, p), PointLocation::kOnSurface) << p.transpose();
    EXPECT_TRUE(point_inside(box, p));
  }
  // One ulp off the face, either way.
  EXPECT_EQ(locate_point(box, Vec3(std::nextafter(1.0, 2.0), 0.3, 0.2)), PointLocation::kOutside);
  EXPECT_EQ(locate_point(box, Vec3(std::nextafter(1.0, 0.0), 0.3, 0.2)), PointLocation::kInside);
  // Points in line with edges and vertices along the axes (degenerate for axis rays).
  EXPECT_EQ(locate_point(box, Vec3(0, 0, 0.5)), PointLocation::kInside);
  EXPECT_EQ(locate_point(box, Vec3(-3, 1, 1)), PointLocation::kOutside);

  const Mesh sphere = make_sphere(1, 3);
  EXPECT_TRUE(point_inside(sphere, Vec3(0, 0, 0)));
  EXPECT_TRUE(point_inside(sphere, Vec3(0.5, 0.5, 0.5)));
  EXPECT_FALSE(point_inside(sphere, Vec3(0.8, 0.8, 0.1)));

  const Mesh torus = make_torus(2, 0.5, 32, 16);
  EXPECT_FALSE(point_inside(torus, Vec3(0, 0, 0)));  // the hole
  EXPECT_TRUE(point_inside(torus, Vec3(2, 0, 0)));   // the tube
  EXPECT_TRUE(point_inside(torus, Vec3(0, -2, 0.2)));
  EXPECT_FALSE(point_inside(torus, Vec3(2, 0, 0.6)));
}

TEST(Containment, ALocatorAgreesWithEveryTriangleTestedOnItsHardestPoints) {
  // PointLocator's rays skip the triangles whose boxes they miss; the
  // location must be the one a ray tested against every triangle gives
  // (locate_point), also for points on the surface, on the planes of far
  // faces, on edges and vertices, and one ulp off them, in a turned frame.
  std::mt19937 random(7);
  std::uniform_real_distribution<Real> unit(-1, 1);
  Transform X;
  X.R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  X.t = Vec3(0.3, -12, 40);
  int checked = 0, on_surface = 0, inside = 0;
  for (const Mesh& mesh : {make_block_with_hole(Vec3(1, 0.5, 1), 0.4, 0.5, 16),
                           make_torus(2, 0.5, 32, 16), make_box(Vec3(1, 2, 3))}) {
    const PointLocator locator(mesh, X);
    Mesh placed = mesh;
    for (Vec3& v : placed.vertices) v = X.apply(v);
    std::vector<Vec3> points;
    for (const Vec3& v : placed.vertices) {
      points.push_back(v);
      points.push_back(Vec3(std::nextafter(v.x(), 1e9), v.y(), v.z()));
    }
    for (const TriangleIndices& f : placed.triangles) {
      const Vec3 a = placed.vertices[f[0]], b = placed.vertices[f[1]], c = placed.vertices[f[2]];
      points.push_back((a + b) / 2);                // on an edge (rounded: near it)
      points.push_back((a + b + c) / 3);            // on the face (rounded: near it)
      points.push_back(a + 3 * (b - a));            // on the edge's line, far along it
      points.push_back(a + 2 * (b - a) + (c - a));  // on the face's plane, outside it
    }
    for (int i = 0; i < 300; ++i)
      points.push_back(X.apply(3 * Vec3(unit(random), unit(random), unit(random))));
    for (const Vec3& p : points) {
      const PointLocation expected = locate_point(placed, p);
      ASSERT_EQ(locator.locate(p), expected) << p.transpose();
      ++checked;
      on_surface += expected == PointLocation::kOnSurface;
      inside += expected == PointLocation::kInside;
    }
  }
  std::printf("[ locate   ] %d points, %d on the surface, %d inside\n", checked, on_surface,
              inside);
  EXPECT_GT(on_surface, 100);
  EXPECT_GT(inside, 100);
}

TEST(Containment, SmallSphereInsideLargeSphere) {
  const Mesh big = make_sphere(2, 3);
  const Mesh small = make_sphere(0.5, 2);
  const ContainmentResult inside = contains(big, small, translation(0.3, -0.4, 0.5));
  EXPECT_FALSE(inside.surfaces_intersect);
  EXPECT_EQ(inside.inner_in_outer, Inside::kYes);
  EXPECT_EQ(inside.inner_enclosed_by_outer, Inside::kYes);
  EXPECT_EQ(inside.outer_in_inner, Inside::kNo);
  EXPECT_EQ(inside.outer_enclosed_by_inner, Inside::kNo);

  // Swapped roles: the large sphere is inside nothing, the small one is inside it.
  const ContainmentResult swapped = contains(small, big, translation(-0.3, 0.4, -0.5));
  EXPECT_EQ(swapped.inner_in_outer, Inside::kNo);
  EXPECT_EQ(swapped.outer_in_inner, Inside::kYes);

  // Moved apart: neither. Moved through the surface: intersecting, neither.
  const ContainmentResult apart = contains(big, small, translation(4, 0, 0));
  EXPECT_FALSE(apart.surfaces_intersect);
  EXPECT_EQ(apart.inner_in_outer, Inside::kNo);
  EXPECT_EQ(apart.outer_in_inner, Inside::kNo);
  const ContainmentResult crossing = contains(big, small, translation(1.8, 0, 0));
  EXPECT_TRUE(crossing.surfaces_intersect);
  EXPECT_EQ(crossing.inner_in_outer, Inside::kNo);
  EXPECT_EQ(crossing.outer_in_inner, Inside::kNo);
}

TEST(Containment, EveryShellOfAPartMustBeInside) {
  // Inner is two separate boxes in one mesh (as a merged file gives): it is
  // inside the sphere only when both are, whichever comes first in the mesh.
  const Mesh sphere = make_sphere(2, 3);
  const auto two_boxes = [](const Vec3& first, const Vec3& second) {
    const Mesh box = make_box(Vec3(0.2, 0.2, 0.2));
    std::vector<Vec3> v;
    std::vector<TriangleIndices> t;
    for (const Vec3& offset : {first, second}) {
      const auto base = static_cast<std::uint32_t>(v.size());
      for (const Vec3& p : box.vertices) v.push_back(p + offset);
      for (const TriangleIndices& f : box.triangles)
        t.push_back({f[0] + base, f[1] + base, f[2] + base});
    }
    return make_mesh(std::move(v), std::move(t), "two boxes");
  };
  const Vec3 in(0.5, 0, 0), in_too(0.5, 0.8, 0), out(5, 0, 0);
  for (const auto& [first, second, expected] :
       {std::tuple{in, in_too, Inside::kYes}, std::tuple{in, out, Inside::kNo},
        std::tuple{out, in, Inside::kNo}}) {
    const ContainmentResult r = contains(sphere, two_boxes(first, second), Transform());
    EXPECT_FALSE(r.surfaces_intersect);
    EXPECT_EQ(r.inner_in_outer, expected) << first.transpose() << " / " << second.transpose();
    EXPECT_EQ(r.inner_enclosed_by_outer, expected);
  }
  // And the other way round: the sphere is not inside two small boxes.
  const ContainmentResult swapped = contains(two_boxes(in, out), sphere, Transform());
  EXPECT_EQ(swapped.outer_in_inner, Inside::kNo);
}

TEST(Containment, PartInsideAHollowHousing) {
  // Walls 1 thick around a 2 x 2 x 2 cavity.
  const Mesh housing = hollow_box(Vec3(2, 2, 2), Vec3(1, 1, 1));
  const Mesh part = make_box(Vec3(0.25, 0.25, 0.25));
  const auto outer = build_model(Method::kObb, std::make_shared<const Mesh>(housing));
  const auto inner = build_model(Method::kObb, std::make_shared<const Mesh>(part));

  // In the cavity: enclosed by the housing, but not in its material.
  const ContainmentResult cavity = contains(*outer, *inner, translation(0.5, -0.5, 0.25));
  EXPECT_FALSE(cavity.surfaces_intersect);
  EXPECT_EQ(cavity.inner_enclosed_by_outer, Inside::kYes);
  EXPECT_EQ(cavity.inner_in_outer, Inside::kNo);
  EXPECT_EQ(cavity.outer_in_inner, Inside::kNo);

  // Inside a wall: in the material, and enclosed.
  const ContainmentResult wall = contains(*outer, *inner, translation(1.5, 0, 0));
  EXPECT_FALSE(wall.surfaces_intersect);
  EXPECT_EQ(wall.inner_in_outer, Inside::kYes);
  EXPECT_EQ(wall.inner_enclosed_by_outer, Inside::kYes);

  // Moved out: neither. Touching the cavity's wall from inside: the surfaces meet.
  const ContainmentResult out = contains(*outer, *inner, translation(5, 0, 0));
  EXPECT_EQ(out.inner_in_outer, Inside::kNo);
  EXPECT_EQ(out.inner_enclosed_by_outer, Inside::kNo);
  const ContainmentResult touching = contains(*outer, *inner, translation(0.75, 0, 0));
  EXPECT_TRUE(touching.surfaces_intersect);
  EXPECT_EQ(touching.inner_enclosed_by_outer, Inside::kNo);
  // Through a wall.
  const ContainmentResult through = contains(*outer, *inner, translation(1, 0, 0));
  EXPECT_TRUE(through.surfaces_intersect);
  EXPECT_EQ(through.inner_in_outer, Inside::kNo);

  // A box inside a large sphere, and the same box moved out of it.
  const Mesh sphere = make_sphere(3, 3);
  EXPECT_EQ(contains(sphere, part, translation(2.1, 0.2, -0.1)).inner_in_outer, Inside::kYes);
  EXPECT_EQ(contains(sphere, part, translation(10, 0.2, -0.1)).inner_in_outer, Inside::kNo);
}

TEST(Containment, OpenMeshesAreUnknown) {
  const Mesh sheet = make_wavy_sheet(2, 0.1, 3, 6);
  const Mesh box = make_box(Vec3(0.25, 0.25, 0.25));
  // The sheet has no inside: whether the box is in it is unknown; the box is
  // closed, so whether the sheet is in the box is decided.
  const ContainmentResult r = contains(sheet, box, translation(0, 0, 1));
  EXPECT_FALSE(r.surfaces_intersect);
  EXPECT_EQ(r.inner_in_outer, Inside::kUnknown);
  EXPECT_EQ(r.inner_enclosed_by_outer, Inside::kUnknown);
  EXPECT_EQ(r.outer_in_inner, Inside::kNo);
  const Mesh big = make_box(Vec3(5, 5, 5));
  EXPECT_EQ(contains(big, sheet, Transform::identity()).inner_in_outer, Inside::kYes);
  EXPECT_EQ(contains(big, sheet, Transform::identity()).outer_in_inner, Inside::kUnknown);
}

}  // namespace
}  // namespace dovetail::collision
