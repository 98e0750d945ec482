#pragma once
// FCL as a peer in the benchmarks (Debian's libfcl-dev, bench-only): its
// fastest mesh hierarchy, OBBRSS, built from a Dovetail mesh.

#ifdef DOVETAIL_HAVE_FCL
#include <fcl/fcl.h>

#include <memory>
#include <vector>

#include "dovetail/collision/mesh.h"

namespace dovetail::bench {

inline std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>> fcl_model(const collision::Mesh& mesh) {
  auto model = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
  std::vector<fcl::Vector3d> v(mesh.vertices.begin(), mesh.vertices.end());
  std::vector<fcl::Triangle> t;
  for (const auto& tri : mesh.triangles) t.emplace_back(tri[0], tri[1], tri[2]);
  model->beginModel(static_cast<int>(t.size()), static_cast<int>(v.size()));
  model->addSubModel(v, t);
  model->endModel();
  return model;
}

inline fcl::Transform3d fcl_transform(const collision::Transform& X) {
  fcl::Transform3d T = fcl::Transform3d::Identity();
  T.linear() = X.R;
  T.translation() = X.t;
  return T;
}

/// FCL's first-hit collision query of B at X_AB against A.
inline bool fcl_collide(const fcl::BVHModel<fcl::OBBRSSd>& a, const fcl::BVHModel<fcl::OBBRSSd>& b,
                        const collision::Transform& X_AB) {
  fcl::CollisionRequestd request;
  fcl::CollisionResultd result;
  fcl::collide(&a, fcl::Transform3d::Identity(), &b, fcl_transform(X_AB), request, result);
  return result.isCollision();
}

}  // namespace dovetail::bench
#endif
