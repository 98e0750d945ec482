// The OBB tree's box frames (box_fit.h): orthonormal, and tighter than the
// covariance frame where that frame is known to be poor.

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

/// An L-shaped plate as a soup of two boxes, 4 x 1 and 1 x 4 in the plane,
/// 1 thick, turned by `turn`. Its covariance frame lies along the L's
/// diagonals (it is symmetric about one), where the box is 3.54 x 5.66 x 1
/// (volume 20); the tightest box lies along the legs (4 x 4 x 1, volume 16).
Mesh l_plate(const Mat3& turn) {
  Mesh out;
  const auto add = [&](const Vec3& half, const Vec3& centre) {
    const Mesh box = make_box(half);
    const auto base = static_cast<std::uint32_t>(out.vertices.size());
    for (const Vec3& v : box.vertices) out.vertices.push_back(turn * (v + centre));
    for (TriangleIndices t : box.triangles) {
      for (std::uint32_t& i : t) i += base;
      out.triangles.push_back(t);
    }
  };
  add(Vec3(2, 0.5, 0.5), Vec3(2, 0.5, 0.5));
  add(Vec3(0.5, 2, 0.5), Vec3(0.5, 2, 0.5));
  out.source = "L plate";
  return out;
}

Real box_volume(const Mesh& mesh, const Mat3& axes) {
  Vec3 lo = Vec3::Constant(std::numeric_limits<Real>::infinity());
  Vec3 hi = -lo;
  for (const Vec3& v : mesh.vertices) {
    const Vec3 p = axes.transpose() * v;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return (hi - lo).prod();
}

TEST(BoxFit, FindsTheTightBoxWhereTheCovarianceFrameIsPoor) {
  const Mat3 turn = Eigen::AngleAxis<Real>(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Mesh mesh = l_plate(turn);
  const detail::BinaryLayout layout = detail::build_binary_layout(mesh, 2);
  const std::vector<Mat3> axes = detail::fit_box_axes(layout, mesh);
  ASSERT_EQ(axes.size(), layout.nodes.size());

  const Real covariance =
      box_volume(mesh, detail::covariance_axes(detail::node_moments(layout, mesh)[0]));
  EXPECT_NEAR(covariance, 20.0, 0.1);
  // The search's finest turn is 0.01 rad: within 2% of the optimum.
  EXPECT_LT(box_volume(mesh, axes[0]), 16.0 * 1.02);
  EXPECT_GE(box_volume(mesh, axes[0]), 16.0 * (1 - 1e-9));
}

TEST(BoxFit, EveryFrameIsOrthonormalAndRightHanded) {
  const Mat3 turn = Eigen::AngleAxis<Real>(1.1, Vec3(-2, 1, 0.5).normalized()).toRotationMatrix();
  Mesh mesh = make_torus(3, 1, 40, 20);
  for (Vec3& v : mesh.vertices) v = turn * v + Vec3(100, -50, 7);
  const detail::BinaryLayout layout = detail::build_binary_layout(mesh, 2);
  const std::vector<Mat3> axes = detail::fit_box_axes(layout, mesh);
  ASSERT_EQ(axes.size(), layout.nodes.size());
  for (const Mat3& a : axes) {
    EXPECT_LT((a.transpose() * a - Mat3::Identity()).cwiseAbs().maxCoeff(), 1e-14);
    EXPECT_NEAR(a.determinant(), 1.0, 1e-14);
  }
}

TEST(BoxFit, SearchedBoxesAreNoLargerInTotalThanCovarianceBoxes) {
  const Mesh mesh = make_torus(3, 1, 40, 20);
  const detail::BinaryLayout layout = detail::build_binary_layout(mesh, 2);
  const std::vector<Mat3> axes = detail::fit_box_axes(layout, mesh);
  const std::vector<detail::Moments> moments = detail::node_moments(layout, mesh);
  Real fitted = 0, covariance = 0;
  for (std::size_t i = 0; i < layout.nodes.size(); ++i) {
    const detail::LayoutNode& node = layout.nodes[i];
    if (node.end - node.begin < 9) continue;  // kept at their covariance frame
    Mesh part;
    for (std::uint32_t s = node.begin; s < node.end; ++s) {
      for (std::uint32_t v : mesh.triangles[layout.triangles[s].index])
        part.vertices.push_back(mesh.vertices[v]);
    }
    fitted += box_volume(part, axes[i]);
    covariance += box_volume(part, detail::covariance_axes(moments[i]));
  }
  EXPECT_LT(fitted, covariance);
}

}  // namespace
}  // namespace dovetail::collision
