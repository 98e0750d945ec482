#pragma once
// The engine scene of the benchmarks: the 2-cylinder engine assembly
// (Debian's assimp-testmodels) with its four largest parts sweeping back and
// forth through it, turning, and the rest fixed. engine_bench simulates it;
// pipeline_bench writes it as a `dovetail pipeline` scene.

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "dovetail/collision/mesh.h"
#include "dovetail/engine/scene.h"

namespace dovetail::bench {

inline constexpr const char* kEngineAssembly =
    "/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";

struct EngineSweep {
  engine::Scene scene{};
  std::vector<engine::PartId> with_mesh{};  ///< the parts that collide, largest first
  std::vector<engine::PartId> moving{};     ///< the four largest
  std::vector<collision::Transform> start{};
  collision::Real size = 0;  ///< diagonal of the assembly's box

  /// The moving parts of `scene` (this one, or the simulation's it was moved
  /// into) at time t (s): each sweeps along its own axis by ±30% of the
  /// assembly's size, turning by up to ±0.5 rad about z.
  void pose_at(engine::Scene& target, double t) const {
    for (std::size_t i = 0; i < moving.size(); ++i) {
      collision::Transform X = start[i];
      const collision::Real phase =
          2 * std::numbers::pi * (0.2 * t + 0.25 * static_cast<double>(i));
      X.t[static_cast<int>(i % 3)] += 0.3 * size * std::sin(phase);
      X.R = Eigen::AngleAxisd(0.5 * std::sin(phase), collision::Vec3::UnitZ()).toRotationMatrix() *
            X.R;
      target.set_local_pose(moving[i], X);
    }
  }
};

inline EngineSweep load_engine_sweep(const std::string& path) {
  engine::AssemblyOptions options;
  options.movable = false;
  EngineSweep s{.scene = engine::load_assembly(path, options)};
  engine::Scene& scene = s.scene;
  for (engine::PartId p : scene.parts()) {
    if (scene.collision_mesh(p)) s.with_mesh.push_back(p);
  }
  std::stable_sort(s.with_mesh.begin(), s.with_mesh.end(), [&](auto x, auto y) {
    return scene.collision_mesh(x)->triangle_count() > scene.collision_mesh(y)->triangle_count();
  });
  collision::Vec3 lo = collision::Vec3::Constant(1e300), hi = collision::Vec3::Constant(-1e300);
  for (engine::PartId p : s.with_mesh) {
    const collision::Bounds b = collision::mesh_bounds(*scene.collision_mesh(p));
    const collision::Transform X = scene.world_pose(p);
    lo = lo.cwiseMin(X.apply(b.min)).cwiseMin(X.apply(b.max));
    hi = hi.cwiseMax(X.apply(b.min)).cwiseMax(X.apply(b.max));
  }
  s.size = (hi - lo).norm();
  s.moving.assign(s.with_mesh.begin(),
                  s.with_mesh.begin() + std::min<std::size_t>(4, s.with_mesh.size()));
  for (engine::PartId p : s.moving) {
    scene.set_movable(p, true);
    s.start.push_back(scene.local_pose(p));
  }
  return s;
}

}  // namespace dovetail::bench
