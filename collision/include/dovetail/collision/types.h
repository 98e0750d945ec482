#pragma once
/// \file types.h
/// Scalar, vector and rigid-transform types used throughout the collision layer.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>

#include "dovetail/collision/fp_guard.h"

namespace dovetail::collision {

/// The one scalar type of the project (see docs/CONVENTIONS.md).
using Real = double;
using Vec3 = Eigen::Matrix<Real, 3, 1>;
using Mat3 = Eigen::Matrix<Real, 3, 3>;

/// Rigid transform X_AB: maps a point given in frame B to frame A, p_A = R * p_B + t.
struct Transform {
  Mat3 R = Mat3::Identity();  ///< rotation of B in A (orthonormal)
  Vec3 t = Vec3::Zero();      ///< origin of B in A

  /// p_A = X_AB * p_B. Every method uses this one function, so the transformed
  /// coordinates of a vertex are the same bits whichever hierarchy asks.
  Vec3 apply(const Vec3& p_B) const {
    return Vec3(R(0, 0) * p_B.x() + R(0, 1) * p_B.y() + R(0, 2) * p_B.z() + t.x(),
                R(1, 0) * p_B.x() + R(1, 1) * p_B.y() + R(1, 2) * p_B.z() + t.y(),
                R(2, 0) * p_B.x() + R(2, 1) * p_B.y() + R(2, 2) * p_B.z() + t.z());
  }

  /// X_BA, the inverse transform.
  Transform inverse() const {
    Transform X;
    X.R = R.transpose();
    X.t = -(X.R * t);
    return X;
  }

  static Transform identity() { return {}; }
};

/// Indices of one triangle's three vertices.
using TriangleIndices = std::array<std::uint32_t, 3>;

}  // namespace dovetail::collision
