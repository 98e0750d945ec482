#pragma once
// The peers a benchmark protocol runs side by side with Dovetail's methods,
// as harness contenders, each when its Debian package is installed
// (bench-only dependencies):
//   fcl-obbrss      FCL 0.7, BVHModel<OBBRSSd>, first-hit fcl::collide (libfcl-dev)
//   bullet-gimpact  Bullet 3.24, btGImpactMeshShape against btGImpactMeshShape,
//                   margin 0, contactPairTest: Bullet's mesh-mesh path; it
//                   finds every contact, not the first (libbullet-dev, floats)
//   libccd-gjk      libccd 2.1, ccdGJKIntersect on the convex hulls (libccd-dev),
//                   a peer of the convex level, not exact for the meshes

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "dovetail/collision/convex.h"
#include "fcl_peer.h"
#include "harness.h"

#ifdef DOVETAIL_HAVE_BULLET
#include <BulletCollision/Gimpact/btGImpactCollisionAlgorithm.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>
#include <btBulletCollisionCommon.h>
#endif
#ifdef DOVETAIL_HAVE_CCD
#include <ccd/ccd.h>
#endif

namespace dovetail::bench {

namespace peers_detail {

inline double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

#ifdef DOVETAIL_HAVE_BULLET
/// One mesh as Bullet's GImpact shape (single precision), with the arrays it points into.
struct BulletMesh {
  std::vector<btScalar> vertices;
  std::vector<int> indices;
  std::unique_ptr<btTriangleIndexVertexArray> array;
  std::unique_ptr<btGImpactMeshShape> shape;
  btCollisionObject object;

  explicit BulletMesh(const collision::Mesh& mesh) {
    for (const collision::Vec3& v : mesh.vertices) {
      for (int k = 0; k < 3; ++k) vertices.push_back(static_cast<btScalar>(v[k]));
    }
    for (const auto& t : mesh.triangles) {
      for (int k = 0; k < 3; ++k) indices.push_back(static_cast<int>(t[k]));
    }
    array = std::make_unique<btTriangleIndexVertexArray>(
        static_cast<int>(mesh.triangles.size()), indices.data(), 3 * sizeof(int),
        static_cast<int>(mesh.vertices.size()), vertices.data(), 3 * sizeof(btScalar));
    shape = std::make_unique<btGImpactMeshShape>(array.get());
    shape->setMargin(0);
    shape->updateBound();
    object.setCollisionShape(shape.get());
  }
};

/// Bullet's collision world for two GImpact meshes (not added to it: only
/// contactPairTest is used, which asks the dispatcher for the pair's algorithm).
struct BulletPair {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btCollisionWorld world{&dispatcher, &broadphase, &configuration};
  std::unique_ptr<BulletMesh> a, b;

  BulletPair(const collision::Mesh& mesh_a, const collision::Mesh& mesh_b) {
    // contactPairTest asks for the closest-points algorithm, which
    // registerAlgorithm leaves out: register GImpact's for that too.
    btGImpactCollisionAlgorithm::registerAlgorithm(&dispatcher);
    static btGImpactCollisionAlgorithm::CreateFunc gimpact;
    dispatcher.registerClosestPointsCreateFunc(GIMPACT_SHAPE_PROXYTYPE, GIMPACT_SHAPE_PROXYTYPE,
                                               &gimpact);
    a = std::make_unique<BulletMesh>(mesh_a);
    b = std::make_unique<BulletMesh>(mesh_b);
  }

  bool collide(const collision::Transform& X_AB) {
    btMatrix3x3 basis;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) basis[r][c] = static_cast<btScalar>(X_AB.R(r, c));
    }
    const btVector3 origin(static_cast<btScalar>(X_AB.t.x()), static_cast<btScalar>(X_AB.t.y()),
                           static_cast<btScalar>(X_AB.t.z()));
    b->object.setWorldTransform(btTransform(basis, origin));
    struct Touch : btCollisionWorld::ContactResultCallback {
      bool hit = false;
      btScalar addSingleResult(btManifoldPoint& point, const btCollisionObjectWrapper*, int, int,
                               const btCollisionObjectWrapper*, int, int) override {
        hit = hit || point.getDistance() <= 0;
        return 0;
      }
    } touch;
    world.contactPairTest(&a->object, &b->object, touch);
    return touch.hit;
  }
};
#endif

#ifdef DOVETAIL_HAVE_CCD
/// A hull at a pose in A's frame, for libccd's support callback (warm-started hill climb).
struct CcdHull {
  const collision::ConvexHull* hull = nullptr;
  collision::Transform X;
  mutable std::uint32_t last = 0;
};

inline void ccd_hull_support(const void* object, const ccd_vec3_t* dir, ccd_vec3_t* out) {
  const auto* o = static_cast<const CcdHull*>(object);
  const collision::Vec3 d(dir->v[0], dir->v[1], dir->v[2]);
  o->last = o->hull->support(o->X.R.transpose() * d, o->last);
  const collision::Vec3 p = o->X.apply(o->hull->vertices[o->last]);
  ccdVec3Set(out, p.x(), p.y(), p.z());
}

inline void ccd_hull_first_direction(const void* a, const void* b, ccd_vec3_t* dir) {
  const auto* oa = static_cast<const CcdHull*>(a);
  const auto* ob = static_cast<const CcdHull*>(b);
  const collision::Vec3 d = ob->X.apply(ob->hull->center) - oa->X.apply(oa->hull->center);
  ccdVec3Set(dir, d.x(), d.y(), d.z());
}
#endif

}  // namespace peers_detail

/// The installed peers as contenders on A and B (`b` may be `a`). With
/// `convex`, libccd's GJK on the hulls is among them (an approximation of
/// the meshes, family "hull-peer").
inline std::vector<Contender> peer_contenders(const MeshPtr& a, const MeshPtr& b, bool convex) {
  using collision::CollideStats;
  using collision::Transform;
  std::vector<Contender> peers;
#ifdef DOVETAIL_HAVE_FCL
  {
    Contender c;
    c.name = "fcl-obbrss";
    c.family = "peer";
    const auto start = std::chrono::steady_clock::now();
    const auto fa = fcl_model(*a);
    const auto fb = a == b ? fa : fcl_model(*b);
    c.build_ms = peers_detail::ms_since(start);
    c.bytes_per_triangle = 256.0 * 2 + 4;  // OBBRSS nodes (2 per triangle) and the primitive order
    c.query = [fa, fb](const Transform& X, CollideStats&) { return fcl_collide(*fa, *fb, X); };
    peers.push_back(std::move(c));
  }
#endif
#ifdef DOVETAIL_HAVE_BULLET
  {
    Contender c;
    c.name = "bullet-gimpact";
    c.family = "peer";
    const auto start = std::chrono::steady_clock::now();
    auto pair = std::make_shared<peers_detail::BulletPair>(*a, *b);
    c.build_ms = peers_detail::ms_since(start);
    c.query = [pair](const Transform& X, CollideStats&) { return pair->collide(X); };
    peers.push_back(std::move(c));
  }
#endif
#ifdef DOVETAIL_HAVE_CCD
  if (convex) {
    Contender c;
    c.name = "libccd-gjk";
    c.family = "hull-peer";
    c.exact = false;
    const auto start = std::chrono::steady_clock::now();
    const auto ha = std::make_shared<const collision::ConvexHull>(
        collision::compute_convex_hull(a->vertices, a->source));
    const auto hb = a == b ? ha
                           : std::make_shared<const collision::ConvexHull>(
                                 collision::compute_convex_hull(b->vertices, b->source));
    c.build_ms = peers_detail::ms_since(start);
    c.query = [ha, hb](const Transform& X, CollideStats&) {
      peers_detail::CcdHull oa{ha.get(), Transform::identity()}, ob{hb.get(), X};
      ccd_t ccd;
      CCD_INIT(&ccd);
      ccd.support1 = peers_detail::ccd_hull_support;
      ccd.support2 = peers_detail::ccd_hull_support;
      ccd.first_dir = peers_detail::ccd_hull_first_direction;
      ccd.max_iterations = 128;
      return ccdGJKIntersect(&oa, &ob, &ccd) != 0;
    };
    peers.push_back(std::move(c));
  }
#else
  (void)convex;
#endif
  return peers;
}

/// The peers this build lacks, with their packages ("" when none is missing).
inline std::string missing_peers() {
  std::string missing;
  const auto add = [&missing](const char* what) {
    missing += (missing.empty() ? "" : ", ") + std::string(what);
  };
#ifndef DOVETAIL_HAVE_FCL
  add("FCL (libfcl-dev)");
#endif
#ifndef DOVETAIL_HAVE_BULLET
  add("Bullet (libbullet-dev)");
#endif
#ifndef DOVETAIL_HAVE_CCD
  add("libccd (libccd-dev)");
#endif
  (void)add;
  return missing;
}

}  // namespace dovetail::bench
