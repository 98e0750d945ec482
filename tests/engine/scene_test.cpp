#include "dovetail/engine/scene.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "dovetail/collision/pose_sampling.h"
#include "dovetail/collision/primitives.h"

namespace dovetail::engine {
namespace {

namespace fs = std::filesystem;
using collision::Vec3;

const fs::path kModels = DOVETAIL_ASSIMP_MODELS;
const fs::path kData = DOVETAIL_TEST_DATA;
const fs::path kEngine = kModels / "glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";

Transform translation(double x, double y, double z) {
  Transform X;
  X.t = Vec3(x, y, z);
  return X;
}

Transform rotation_z(double angle) {
  Transform X;
  X.R = Eigen::AngleAxisd(angle, Vec3::UnitZ()).toRotationMatrix();
  return X;
}

std::shared_ptr<const collision::Mesh> box(double half) {
  return std::make_shared<const collision::Mesh>(collision::make_box(Vec3::Constant(half)));
}

/// Writes `text` to a fresh file under the temp folder; removed by the caller.
fs::path write_temp(const std::string& file_name, const std::string& text) {
  const fs::path dir =
      fs::temp_directory_path() / ("dovetail_scene_" + std::to_string(static_cast<long>(getpid())));
  fs::create_directories(dir);
  const fs::path path = dir / file_name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error";
  return {};
}

TEST(Scene, NamesAreUniqueAndLookedUp) {
  Scene scene;
  const PartId a = scene.add_part({.name = "peg", .tags = {"fastener"}, .render_mesh = box(1)});
  const PartId b = scene.add_part({.name = "block", .render_mesh = box(1)});
  EXPECT_EQ(scene.get("peg"), a);
  EXPECT_EQ(scene.find("block"), b);
  EXPECT_FALSE(scene.find("nothing").valid());
  EXPECT_EQ(scene.part_count(), 2u);
  EXPECT_TRUE(scene.has_tag(a, "fastener"));
  ASSERT_EQ(scene.parts_with_tag("fastener").size(), 1u);
  // Name order, not insertion order.
  ASSERT_EQ(scene.parts().size(), 2u);
  EXPECT_EQ(scene.name(scene.parts()[0]), "block");
  // The collision mesh defaults to the render mesh.
  EXPECT_EQ(scene.collision_mesh(a), scene.render_mesh(a));

  EXPECT_NE(error_of([&] { scene.add_part({.name = "peg"}); }).find("duplicate part name 'peg'"),
            std::string::npos);
  EXPECT_NE(error_of([&] { scene.get("bolt"); }).find("no part named 'bolt'"), std::string::npos);
  EXPECT_NE(error_of([&] {
              scene.add_part({.name = "x", .parent = "frame"});
            }).find("unknown parent 'frame'"),
            std::string::npos);
  EXPECT_THROW(scene.add_part({.name = ""}), SceneError);

  scene.remove_part(a);
  EXPECT_FALSE(scene.contains(a));
  EXPECT_THROW(scene.name(a), SceneError);
  const PartId again = scene.add_part({.name = "peg"});
  EXPECT_EQ(again.index, a.index);
  EXPECT_NE(again.generation, a.generation);
}

TEST(Scene, MovingAParentMovesItsChildren) {
  Scene scene;
  scene.add_part({.name = "frame", .X_QP = translation(1, 0, 0)});
  scene.add_part({.name = "arm", .parent = "frame", .X_QP = translation(0, 2, 0)});
  scene.add_part(
      {.name = "gripper", .parent = "arm", .X_QP = translation(0, 0, 3), .render_mesh = box(1)});
  EXPECT_TRUE(scene.world_pose("gripper").t.isApprox(Vec3(1, 2, 3)));

  scene.set_local_pose("frame", compose(translation(10, 0, 0), rotation_z(M_PI / 2)));
  const Transform X_WG = scene.world_pose("gripper");
  // arm's offset (0, 2, 0) rotated by 90 degrees about z is (-2, 0, 0).
  EXPECT_TRUE(X_WG.t.isApprox(Vec3(8, 0, 3), 1e-12)) << X_WG.t.transpose();
  EXPECT_TRUE(X_WG.R.isApprox(rotation_z(M_PI / 2).R));
  // The sibling's pose is untouched; the parent's local pose equals its world pose.
  EXPECT_TRUE(scene.world_pose("frame").t.isApprox(Vec3(10, 0, 0)));

  // Re-parenting keeps the world pose by default.
  const PartId gripper = scene.get("gripper");
  scene.set_parent(gripper, PartId{});
  EXPECT_TRUE(scene.world_pose(gripper).t.isApprox(X_WG.t, 1e-12));
  EXPECT_THROW(scene.set_parent(scene.get("frame"), scene.get("arm")), SceneError);

  // Removing a middle part keeps its children where they are.
  scene.set_parent(gripper, scene.get("arm"));
  scene.remove_part(scene.get("arm"));
  EXPECT_EQ(scene.parent(gripper), scene.get("frame"));
  EXPECT_TRUE(scene.world_pose(gripper).t.isApprox(X_WG.t, 1e-12));
}

TEST(Scene, RevisionChangesWithPartsParentsAndPoses) {
  Scene scene;
  std::set<std::uint64_t> seen{scene.revision()};
  // Each of these changes names or poses: a new stamp every time.
  const auto changed = [&](const char* what) {
    EXPECT_TRUE(seen.insert(scene.revision()).second) << what;
  };
  scene.add_part({.name = "frame", .X_QP = translation(1, 0, 0)});
  changed("add_part");
  const PartId arm = scene.add_part({.name = "arm", .X_QP = translation(0, 2, 0)});
  changed("add_part");
  scene.set_local_pose(arm, translation(0, 3, 0));
  changed("set_local_pose");
  scene.set_local_pose(arm, translation(0, 3, 0));
  changed("set_local_pose, the same pose");
  scene.set_world_pose(arm, translation(0, 4, 0));
  changed("set_world_pose");
  scene.set_parent(arm, scene.get("frame"), false);
  changed("set_parent");
  // Tags, highlights and visibility are not in the state hash: no new stamp.
  const std::uint64_t before = scene.revision();
  scene.add_tag(arm, "grip");
  scene.set_highlight(arm, std::array<float, 3>{1, 0, 0});
  scene.set_visible(arm, false);
  scene.set_movable(arm, false);
  EXPECT_EQ(scene.revision(), before);
  // A copy keeps the stamp until one of the two changes.
  Scene copy = scene;
  EXPECT_EQ(copy.revision(), scene.revision());
  copy.set_local_pose(copy.get("arm"), translation(0, 5, 0));
  EXPECT_NE(copy.revision(), scene.revision());
  scene.set_local_pose(arm, translation(0, 5, 0));
  EXPECT_NE(copy.revision(), scene.revision());  // the same poses, but stamped apart
  scene.remove_part(arm);
  changed("remove_part");
}

TEST(Scene, WorldPosesOfLongChainsComposeRootFirst) {
  // Chains shorter and longer than the 16 parts world_pose keeps without an
  // allocation: the pose is X_Q0 * X_Q1 * ... * X_QP composed from the root,
  // bit for bit.
  const std::vector<Transform> locals = collision::random_poses(40, 1.0, 11);
  Scene scene;
  std::string parent;
  Transform expected;
  for (std::size_t k = 0; k < locals.size(); ++k) {
    const std::string name = "link" + std::to_string(k);
    scene.add_part({.name = name, .parent = parent, .X_QP = locals[k]});
    expected = k == 0 ? locals[0] : compose(expected, locals[k]);
    const Transform X_WP = scene.world_pose(name);
    EXPECT_EQ(X_WP.R, expected.R) << name;
    EXPECT_EQ(X_WP.t, expected.t) << name;
    parent = name;
  }
}

TEST(Assembly, FileCamerasBecomeSceneCamerasInMetres) {
  AssemblyReport report;
  const Scene scene = load_assembly(kEngine, {}, &report);
  ASSERT_DOUBLE_EQ(report.units, 0.001);
  ASSERT_EQ(scene.cameras().size(), 1u);
  const Camera& camera = scene.cameras()[0].second;
  // The camera node's matrix places the eye at (1005.99, 766.32, 953.35) mm
  // looking along the node's -z axis.
  EXPECT_NEAR(camera.eye.x(), 1.00599, 1e-5);
  EXPECT_NEAR(camera.eye.y(), 0.76632, 1e-5);
  EXPECT_NEAR(camera.eye.z(), 0.95335, 1e-5);
  const Vec3 look = (camera.target - camera.eye).normalized();
  EXPECT_NEAR(look.x(), -0.6246951818466187, 1e-6);
  EXPECT_NEAR(look.y(), -0.4685211479663849, 1e-6);
  EXPECT_NEAR(look.z(), -0.6246950030326843, 1e-6);
  Scene copy = scene;
  EXPECT_THROW(copy.add_camera("nodes[81]", camera), SceneError);
  EXPECT_THROW(copy.add_camera("", camera), SceneError);
  copy.add_camera("overview", camera);
  EXPECT_EQ(copy.cameras().back().first, "overview");
}

TEST(Assembly, EngineLoadsAsSeparateNamedParts) {
  AssemblyReport report;
  const Scene scene = load_assembly(kEngine, {}, &report);
  // One part per mesh instance of every node, as the importer lists them.
  ImportOptions per_part;
  per_part.merge = false;
  const ImportReport imported = import_file(kEngine, per_part);
  EXPECT_EQ(scene.part_count(), imported.parts.size());
  EXPECT_EQ(report.parts, scene.part_count());
  EXPECT_EQ(scene.part_count(), 115u);  // 67 mesh nodes place 34 primitives 115 times
  std::set<std::string> names;
  std::set<const collision::Mesh*> distinct;
  std::size_t triangles = 0;
  std::size_t distinct_triangles = 0;
  for (const PartId part : scene.parts()) {
    names.insert(scene.name(part));
    ASSERT_TRUE(scene.collision_mesh(part));
    triangles += scene.collision_mesh(part)->triangle_count();
    if (distinct.insert(scene.collision_mesh(part).get()).second) {
      distinct_triangles += scene.collision_mesh(part)->triangle_count();
    }
  }
  EXPECT_EQ(names.size(), scene.part_count());
  EXPECT_EQ(triangles, report.triangles);
  // Instanced meshes are shared: the distinct geometry is the file's ~76k
  // triangles, placed ~110k times.
  EXPECT_GT(report.shared_meshes, 0u);
  EXPECT_EQ(distinct.size() + report.shared_meshes, scene.part_count());
  EXPECT_NEAR(static_cast<double>(distinct_triangles), 76000.0, 2500.0);
  EXPECT_NEAR(static_cast<double>(triangles), 110000.0, 2500.0);
  // The file is in millimetres (an engine some hundreds of units long).
  EXPECT_TRUE(report.units_inferred);
  EXPECT_EQ(report.units, 0.001);

  // Parts keep their node poses: the meshes in part frames placed by their
  // poses give the same world bounds as the merged file scaled to metres.
  const collision::Mesh merged = import_mesh(kEngine);
  const collision::Bounds expected = collision::mesh_bounds(merged);
  Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
  for (const PartId part : scene.parts()) {
    const Transform X_WP = scene.world_pose(part);
    for (const Vec3& p : scene.collision_mesh(part)->vertices) {
      lo = lo.cwiseMin(X_WP.apply(p));
      hi = hi.cwiseMax(X_WP.apply(p));
    }
  }
  EXPECT_TRUE(lo.isApprox(expected.min * 0.001, 1e-9)) << lo.transpose();
  EXPECT_TRUE(hi.isApprox(expected.max * 0.001, 1e-9)) << hi.transpose();
}

TEST(Assembly, PartsGroupedIntoASubAssemblyMoveTogether) {
  Scene scene = load_assembly(kEngine);
  const std::vector<PartId> parts = scene.parts();
  const PartId group = scene.add_part({.name = "crank_assembly"});
  std::vector<Transform> before;
  for (std::size_t k = 0; k < 3; ++k) {
    before.push_back(scene.world_pose(parts[k]));
    scene.set_parent(parts[k], group);  // keeps the world pose
    EXPECT_TRUE(scene.world_pose(parts[k]).t.isApprox(before[k].t, 1e-12));
  }
  EXPECT_EQ(scene.children(group).size(), 3u);
  const Transform X_WG = compose(translation(0.1, 0, 0), rotation_z(0.3));
  scene.set_local_pose(group, X_WG);
  for (std::size_t k = 0; k < 3; ++k) {
    const Transform expected = compose(X_WG, before[k]);
    EXPECT_TRUE(scene.world_pose(parts[k]).t.isApprox(expected.t, 1e-12));
    EXPECT_TRUE(scene.world_pose(parts[k]).R.isApprox(expected.R, 1e-12));
  }
  // Parts outside the group stay.
  EXPECT_EQ(scene.world_pose(parts[3]).t, scene.local_pose(parts[3]).t);
}

TEST(Assembly, DeclaredUnitsAndSmallFilesInMetres) {
  AssemblyReport report;
  const Scene scene = load_assembly(kData / "cube.obj", {}, &report);
  EXPECT_EQ(scene.part_count(), 1u);
  EXPECT_EQ(report.units, 1.0);
  AssemblyOptions options;
  options.units = 0.01;
  options.movable = false;
  options.tags = {"fixture"};
  const Scene scaled = load_assembly(kData / "cube.obj", options, &report);
  EXPECT_FALSE(report.units_inferred);
  const PartId part = scaled.parts().front();
  EXPECT_FALSE(scaled.movable(part));
  EXPECT_TRUE(scaled.has_tag(part, "fixture"));
  const collision::Bounds a = collision::mesh_bounds(*scene.collision_mesh(scene.parts()[0]));
  const collision::Bounds b = collision::mesh_bounds(*scaled.collision_mesh(part));
  EXPECT_TRUE(b.max.isApprox(a.max * 0.01));
}

TEST(Assembly, LinePrimitivesAreNotedNotFatal) {
  const fs::path path = write_temp("with_lines.obj",
                                   "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                   "o face\nf 1 2 3\no wire\nl 1 4\n");
  AssemblyReport report;
  const Scene scene = load_assembly(path, {}, &report);
  fs::remove_all(path.parent_path());
  EXPECT_EQ(scene.part_count(), 1u);
  EXPECT_EQ(report.skipped_line_or_point_primitives, 1u);
  bool noted = false;
  for (const std::string& note : report.notes) noted |= note.find("line") != std::string::npos;
  EXPECT_TRUE(noted);
}

TEST(Assembly, HostileInputNamesTheFile) {
  const fs::path missing = kData / "no_such_assembly.glb";
  EXPECT_NE(error_of([&] { load_assembly(missing); }).find(missing.string()), std::string::npos);
  const fs::path broken = write_temp("broken.glb", "glTF this is not a binary glTF file");
  const std::string message = error_of([&] { load_assembly(broken); });
  fs::remove_all(broken.parent_path());
  EXPECT_NE(message.find(broken.string()), std::string::npos) << message;
  const fs::path nan = kData / "nan_vertex.obj";
  EXPECT_NE(error_of([&] { load_assembly(nan); }).find(nan.string()), std::string::npos);
}

}  // namespace
}  // namespace dovetail::engine
