#pragma once
// Principal axes of sets of triangles: the area-weighted moments and the
// covariance frame fitted by the OBB tree, shared with the RSS tree of the
// distance queries.

#include <Eigen/Eigenvalues>
#include <cstdint>
#include <vector>

#include "dovetail/collision/mesh.h"
#include "polygon/binary_layout.h"

namespace dovetail::collision::detail {

/// Area-weighted first and second moments of a set of triangles; the moments
/// of a node are the sums of its children's.
struct Moments {
  Real area = 0;
  Vec3 first = Vec3::Zero();   ///< sum of area * centroid
  Mat3 second = Mat3::Zero();  ///< sum of area * second moment per unit area
  void add(const Moments& m) {
    area += m.area;
    first += m.first;
    second += m.second;
  }
};

inline Moments triangle_moments(const Vec3& p, const Vec3& q, const Vec3& r) {
  Moments m;
  m.area = 0.5 * (q - p).cross(r - p).norm();
  const Vec3 c = (p + q + r) / 3.0;
  m.first = m.area * c;
  m.second = m.area / 12.0 *
             (9.0 * c * c.transpose() + p * p.transpose() + q * q.transpose() + r * r.transpose());
  return m;
}

/// Box axes: eigenvectors of the covariance, made right-handed.
inline Mat3 covariance_axes(const Moments& m) {
  if (!(m.area > 0)) return Mat3::Identity();
  const Vec3 mean = m.first / m.area;
  const Mat3 covariance = m.second / m.area - mean * mean.transpose();
  Eigen::SelfAdjointEigenSolver<Mat3> solver;
  solver.computeDirect(covariance);
  Mat3 axes = solver.eigenvectors();
  axes.col(0).normalize();
  axes.col(1) = (axes.col(1) - axes.col(1).dot(axes.col(0)) * axes.col(0)).normalized();
  axes.col(2) = axes.col(0).cross(axes.col(1));
  if (!axes.allFinite()) return Mat3::Identity();
  return axes;
}

/// Axes of a single triangle: its longest edge, the in-plane normal to it and
/// the face normal (the tightest box of a triangle has a face in its plane).
inline Mat3 triangle_axes(const Mesh& mesh, std::uint32_t triangle) {
  const TriangleIndices& t = mesh.triangles[triangle];
  const Vec3 e[3] = {mesh.vertices[t[1]] - mesh.vertices[t[0]],
                     mesh.vertices[t[2]] - mesh.vertices[t[1]],
                     mesh.vertices[t[0]] - mesh.vertices[t[2]]};
  int longest = 0;
  for (int k = 1; k < 3; ++k)
    if (e[k].squaredNorm() > e[longest].squaredNorm()) longest = k;
  Mat3 axes;
  axes.col(0) = e[longest].normalized();
  axes.col(2) = e[0].cross(e[1]).normalized();
  axes.col(1) = axes.col(2).cross(axes.col(0));
  if (!axes.allFinite()) return Mat3::Identity();
  return axes;
}

/// Moments of every node of a layout, bottom-up (children follow their
/// parent in the layout).
inline std::vector<Moments> node_moments(const BinaryLayout& layout, const Mesh& mesh) {
  const std::size_t n = layout.nodes.size();
  std::vector<Moments> moments(n);
  for (std::size_t i = n; i-- > 0;) {
    const LayoutNode& node = layout.nodes[i];
    if (node.is_leaf()) {
      for (std::uint32_t s = node.begin; s < node.end; ++s) {
        const TriangleIndices& t = mesh.triangles[layout.triangles[s].index];
        moments[i].add(
            triangle_moments(mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]));
      }
    } else {
      moments[i] = moments[node.first_child];
      moments[i].add(moments[node.first_child + 1]);
    }
  }
  return moments;
}

}  // namespace dovetail::collision::detail
