// Polygon-level exactness on real model files (Debian's assimp-testmodels):
// every method reports what brute force reports, on random and
// contact-distance poses.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "dovetail/collision/model.h"
#include "dovetail/collision/pose_sampling.h"
#include "dovetail/engine/mesh_import.h"

namespace dovetail {
namespace {

using collision::CollideResult;
using collision::Method;
using collision::Transform;

std::shared_ptr<const collision::Mesh> load(const std::string& relative) {
  const std::filesystem::path path = std::filesystem::path(DOVETAIL_ASSIMP_MODELS) / relative;
  return std::make_shared<const collision::Mesh>(engine::import_mesh(path));
}

/// Random poses that keep B's centre near A's centre (within `spread` of the
/// larger bounding-box diagonal), plus contact-distance poses.
std::vector<Transform> poses_for(const collision::Mesh& a, const collision::Mesh& b,
                                 std::size_t count, double spread, std::uint64_t seed) {
  const collision::Bounds ba = collision::mesh_bounds(a), bb = collision::mesh_bounds(b);
  const double size = std::max((ba.max - ba.min).norm(), (bb.max - bb.min).norm());
  const collision::Vec3 ca = (ba.min + ba.max) / 2, cb = (bb.min + bb.max) / 2;
  std::vector<Transform> poses = collision::random_poses(count, spread * size, seed);
  for (Transform& X : poses) X.t += ca - X.R * cb;
  return poses;
}

void expect_all_methods_match_brute(const std::shared_ptr<const collision::Mesh>& a,
                                    const std::shared_ptr<const collision::Mesh>& b,
                                    std::vector<Transform> poses, const std::string& scene) {
  std::vector<std::shared_ptr<const collision::CollisionModel>> ma, mb;
  for (Method m : collision::all_methods()) {
    ma.push_back(collision::build_model(m, a));
    mb.push_back(collision::build_model(m, b));
  }
  collision::ContactPoseSettings settings;
  settings.directions = 60;
  settings.seed = 7;
  for (const auto& s : collision::contact_distance_poses(*ma[0], *mb[0], settings))
    poses.push_back(s.X_AB);

  int colliding = 0, disagreements = 0;
  for (std::size_t p = 0; p < poses.size(); ++p) {
    const CollideResult reference = ma.back()->collide(*mb.back(), poses[p], {.all_pairs = true});
    colliding += reference.colliding;
    for (std::size_t m = 0; m + 1 < ma.size(); ++m) {
      const bool first = ma[m]->collide(*mb[m], poses[p]).colliding;
      const CollideResult all = ma[m]->collide(*mb[m], poses[p], {.all_pairs = true});
      if (first != reference.colliding || all.pairs != reference.pairs) {
        if (++disagreements <= 5) {
          ADD_FAILURE() << scene << " pose " << p << " method "
                        << collision::method_name(ma[m]->method());
        }
      }
    }
  }
  std::printf("[ agreement ] %s: %zu poses (%d colliding) x %zu methods, %d disagreements\n",
              scene.c_str(), poses.size(), colliding, ma.size() - 1, disagreements);
  EXPECT_EQ(disagreements, 0);
  EXPECT_GT(colliding, 0) << scene;
  EXPECT_LT(colliding, static_cast<int>(poses.size())) << scene;
}

TEST(HierarchiesOnModels, SpiderAgainstItself) {
  const auto spider = load("OBJ/spider.obj");
  expect_all_methods_match_brute(spider, spider, poses_for(*spider, *spider, 1200, 0.4, 61),
                                 "spider/spider");
}

TEST(HierarchiesOnModels, SphereWithHoleAgainstSpider) {
  const auto sphere = load("STL/sphereWithHole.stl");
  const auto spider = load("OBJ/spider.obj");
  expect_all_methods_match_brute(sphere, spider, poses_for(*sphere, *spider, 1000, 0.4, 62),
                                 "sphereWithHole/spider");
}

TEST(HierarchiesOnModels, EnginePartsAgainstEachOther) {
  // Two parts of the 2-cylinder engine assembly, as separate meshes.
  engine::ImportOptions options;
  options.merge = false;
  const engine::ImportReport report =
      engine::import_file(std::filesystem::path(DOVETAIL_ASSIMP_MODELS) /
                              "glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb",
                          options);
  // The two largest parts under 2,000 triangles (keeps brute force affordable).
  std::vector<const engine::ImportedPart*> parts;
  for (const auto& part : report.parts) {
    if (part.mesh.triangle_count() < 2000) parts.push_back(&part);
  }
  ASSERT_GE(parts.size(), 2u);
  std::stable_sort(parts.begin(), parts.end(), [](const auto* x, const auto* y) {
    return x->mesh.triangle_count() > y->mesh.triangle_count();
  });
  const auto a = std::make_shared<const collision::Mesh>(parts[0]->mesh);
  const auto b = std::make_shared<const collision::Mesh>(parts[1]->mesh);
  expect_all_methods_match_brute(a, b, poses_for(*a, *b, 600, 0.3, 63),
                                 "engine " + parts[0]->name + "/" + parts[1]->name);
}

}  // namespace
}  // namespace dovetail
