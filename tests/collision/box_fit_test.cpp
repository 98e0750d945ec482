// The OBB tree's boxes (box_fit.h): orthonormal frames, boxes that hold their
// nodes, never larger than the covariance frame's, and tight where that
// frame is known to be poor.

#include "polygon/box_fit.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <limits>
#include <vector>

#include "dovetail/collision/primitives.h"
#include "polygon/binary_layout.h"
#include "polygon/principal_axes.h"

namespace dovetail::collision {
namespace {

/// Appends `part` moved by (turn, shift) to `out`.
void append(Mesh& out, const Mesh& part, const Mat3& turn, const Vec3& shift) {
  const auto base = static_cast<std::uint32_t>(out.vertices.size());
  for (const Vec3& v : part.vertices) out.vertices.push_back(turn * v + shift);
  for (TriangleIndices t : part.triangles) {
    for (std::uint32_t& i : t) i += base;
    out.triangles.push_back(t);
  }
}

/// A tiny triangle with one corner at p, the others inside the box
/// |x| <= 2, |y| <= 1, |z| <= 0.5 when p is in it.
Mesh corner_triangle(const Vec3& p) {
  Mesh m;
  const Vec3 in = -0.01 * p.cwiseSign();
  m.vertices = {p, p + Vec3(in.x(), 0, 0), p + Vec3(0, in.y(), in.z())};
  m.triangles = {{0, 1, 2}};
  return m;
}

/// The cost box_fit minimises (volume and a little of the area), over all
/// of a node's vertices.
Real box_cost(const Mesh& mesh, const detail::BinaryLayout& layout, const detail::LayoutNode& node,
              const Mat3& axes) {
  Vec3 lo = Vec3::Constant(std::numeric_limits<Real>::infinity());
  Vec3 hi = -lo;
  for (std::uint32_t s = node.begin; s < node.end; ++s) {
    for (std::uint32_t v : mesh.triangles[layout.triangles[s].index]) {
      const Vec3 p = axes.transpose() * mesh.vertices[v];
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  const Vec3 e = hi - lo;
  return e.prod() + 0.01 * (e.x() * e.y() + e.y() * e.z() + e.z() * e.x()) * e.sum();
}

Real root_volume(const Mesh& mesh, const Mat3& axes) {
  Vec3 lo = Vec3::Constant(std::numeric_limits<Real>::infinity());
  Vec3 hi = -lo;
  for (const Vec3& v : mesh.vertices) {
    const Vec3 p = axes.transpose() * v;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return (hi - lo).prod();
}

TEST(BoxFit, TheTurnsFindTheTightBoxWhereNoFrameTriedIsNear) {
  // Twenty tiny triangles: one in each corner of a 4 x 2 x 1 box and twelve
  // along its diagonal in the xy-plane, the whole turned. The diagonal ones
  // tilt the covariance frame; the root's children (too small to be
  // searched) keep their covariance frames, tilted too, and the mesh's
  // frame is the turned one: only the turns reach the box's own frame
  // (volume 8).
  const Mat3 turn = Eigen::AngleAxis<Real>(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  Mesh mesh;
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner((c & 1) ? 2 : -2, (c & 2) ? 1 : -1, (c & 4) ? 0.5 : -0.5);
    append(mesh, corner_triangle(corner), turn, Vec3::Zero());
  }
  for (const Real t : {-0.9, -0.75, -0.6, -0.45, -0.3, -0.15, 0.15, 0.3, 0.45, 0.6, 0.75, 0.9}) {
    append(mesh, corner_triangle(Vec3(2 * t, t, 0)), turn, Vec3::Zero());
  }
  const detail::BinaryLayout layout = detail::build_binary_layout(mesh, 2);
  ASSERT_GE(layout.nodes[0].end - layout.nodes[0].begin, detail::kBoxSearchMinTriangles);
  const std::vector<detail::FittedBox> boxes = detail::fit_boxes(layout, mesh);
  ASSERT_EQ(boxes.size(), layout.nodes.size());

  const Real covariance =
      root_volume(mesh, detail::covariance_axes(detail::node_moments(layout, mesh)[0]));
  const detail::LayoutNode& root = layout.nodes[0];
  for (const std::uint32_t c : {root.first_child, root.first_child + 1}) {
    ASSERT_LT(layout.nodes[c].end - layout.nodes[c].begin, detail::kBoxSearchMinTriangles);
  }
  const Real children = std::min(root_volume(mesh, boxes[root.first_child].axes),
                                 root_volume(mesh, boxes[root.first_child + 1].axes));
  EXPECT_GT(covariance, 8.0 * 1.1);
  EXPECT_GT(children, 8.0 * 1.1);
  EXPECT_GT(root_volume(mesh, Mat3::Identity()), 8.0 * 1.1);
  // The finest turn is 0.01 rad: within 2% of the box's own frame.
  EXPECT_LT(root_volume(mesh, boxes[0].axes), 8.0 * 1.02);
  EXPECT_GE(root_volume(mesh, boxes[0].axes), 8.0 * (1 - 1e-9));
}

TEST(BoxFit, EveryBoxHoldsItsNodeInAnOrthonormalFrameNoLargerThanTheCovarianceBox) {
  // A torus (where the support sets are reduced to extremes and miss
  // vertices) turned and moved away from the origin.
  const Mat3 turn = Eigen::AngleAxis<Real>(1.1, Vec3(-2, 1, 0.5).normalized()).toRotationMatrix();
  Mesh mesh;
  append(mesh, make_torus(3, 1, 40, 20), turn, Vec3(100, -50, 7));
  const detail::BinaryLayout layout = detail::build_binary_layout(mesh, 2);
  const std::vector<detail::FittedBox> boxes = detail::fit_boxes(layout, mesh);
  const std::vector<detail::Moments> moments = detail::node_moments(layout, mesh);
  ASSERT_EQ(boxes.size(), layout.nodes.size());
  int searched = 0, tighter = 0;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const detail::FittedBox& box = boxes[i];
    const detail::LayoutNode& node = layout.nodes[i];
    EXPECT_LT((box.axes.transpose() * box.axes - Mat3::Identity()).cwiseAbs().maxCoeff(), 1e-14);
    EXPECT_NEAR(box.axes.determinant(), 1.0, 1e-14);
    const Mat3 to_box = box.axes.transpose();  // as the fit rounds it
    for (std::uint32_t s = node.begin; s < node.end; ++s) {
      for (std::uint32_t v : mesh.triangles[layout.triangles[s].index]) {
        const Vec3 p = to_box * mesh.vertices[v];
        EXPECT_TRUE((p.array() >= box.lo.array()).all() && (p.array() <= box.hi.array()).all());
      }
    }
    if (node.end - node.begin < detail::kBoxSearchMinTriangles) continue;
    ++searched;
    const Real fitted = box_cost(mesh, layout, node, box.axes);
    const Real covariance = box_cost(mesh, layout, node, detail::covariance_axes(moments[i]));
    EXPECT_LE(fitted, covariance) << "node " << i;
    tighter += fitted < 0.99 * covariance;
  }
  // The search pays off: a good part of the searched nodes got boxes at
  // least 1% smaller.
  EXPECT_GT(searched, 100);
  EXPECT_GT(tighter, searched / 4);
}

}  // namespace
}  // namespace dovetail::collision
