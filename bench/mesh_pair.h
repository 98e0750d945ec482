#pragma once
// The pair of meshes a two-object benchmark runs on: two files (one mesh
// shared when both name the same file) or, without files, the generated
// sphere and torus of the built-in scene. `FILE#PART` names one part of an
// assembly file (a part name as `dovetail inspect FILE --parts` lists it), in
// its own frame, so that two parts of one assembly make a pair.

#include <cstdio>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>

#include "dovetail/collision/mesh.h"
#include "dovetail/collision/primitives.h"
#include "dovetail/engine/mesh_import.h"
#include "dovetail/engine/scene.h"

namespace dovetail::bench {

/// The mesh of `path`, or of one part of an assembly for `FILE#PART`.
inline collision::Mesh load_mesh_or_part(const std::string& path) {
  const std::size_t hash = path.rfind('#');
  if (hash == std::string::npos) return engine::import_mesh(path);
  const engine::Scene scene = engine::load_assembly(path.substr(0, hash), {});
  const auto mesh = scene.collision_mesh(scene.get(path.substr(hash + 1)));
  if (!mesh) throw std::runtime_error(path + ": the part has no triangles");
  collision::Mesh part = *mesh;
  part.source = path;
  return part;
}

struct MeshPair {
  std::shared_ptr<const collision::Mesh> a, b;
};

/// The meshes of `path_a` and `path_b` (both empty: the built-in pair), each
/// passed through `prepare` once, then printed as `A: ...` and `B: ...`.
inline MeshPair mesh_pair(
    const std::string& path_a, const std::string& path_b,
    const std::function<collision::Mesh(collision::Mesh)>& prepare = [](collision::Mesh m) {
      return m;
    }) {
  const auto make = [&](collision::Mesh m) {
    return std::make_shared<const collision::Mesh>(prepare(std::move(m)));
  };
  MeshPair pair;
  if (path_a.empty()) {
    pair.a = make(collision::make_sphere(0.6, 5));
    pair.b = make(collision::make_torus(0.7, 0.25, 128, 64));
  } else {
    pair.a = make(load_mesh_or_part(path_a));
    pair.b = path_b == path_a ? pair.a : make(load_mesh_or_part(path_b));
  }
  std::printf("A: %s (%zu triangles)\nB: %s (%zu triangles)\n", pair.a->source.c_str(),
              pair.a->triangle_count(), pair.b->source.c_str(), pair.b->triangle_count());
  return pair;
}

}  // namespace dovetail::bench
