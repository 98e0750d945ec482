#include "dovetail/engine/scene_render.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <map>
#include <numeric>
#include <utility>
#include <vector>

#include "dovetail/engine/simulation.h"

namespace dovetail::engine {

namespace {

/// What a part's item takes from the contacts.
struct Highlight {
  std::size_t item = 0;
  bool triangles_usable = false;  ///< the render mesh is the collision mesh
  bool whole = false;             ///< a contact without triangles
};

void add_contact_side(std::map<collision::PartId, Highlight>& by_id, collision::PartId id,
                      std::uint32_t triangle, std::vector<RenderItem>& items) {
  const auto found = by_id.find(id);
  if (found == by_id.end()) return;  // no render mesh, or no longer in the scene
  Highlight& highlight = found->second;
  if (triangle == collision::kNoTriangle) {
    highlight.whole = true;
  } else if (highlight.triangles_usable) {
    items[highlight.item].highlighted.push_back(triangle);
  }
}

}  // namespace

RenderScene render_scene(const Scene& scene, const collision::StepResult* step,
                         const CollisionIdOf& collision_id) {
  if (step != nullptr && !collision_id) {
    throw RenderError("render_scene: a collision step needs the map from parts to collision ids");
  }
  RenderScene out;
  out.cameras = scene.cameras();
  std::map<collision::PartId, Highlight> by_id;
  std::size_t palette_index = 0;  // parts with a colour of their own take none
  for (const PartId part : scene.parts()) {
    const auto& mesh = scene.render_mesh(part);
    if (!mesh) continue;  // a group node
    // Hidden or highlighted parts keep their palette place, so the others keep their colours.
    const auto& own = scene.color(part);
    const Color palette =
        own ? Color{(*own)[0], (*own)[1], (*own)[2]} : palette_color(palette_index++);
    if (!scene.visible(part)) continue;
    RenderItem item;
    item.mesh = mesh;
    item.X_WP = scene.world_pose(part);
    const auto& highlight = scene.highlight(part);
    item.color = highlight ? Color{(*highlight)[0], (*highlight)[1], (*highlight)[2]} : palette;
    item.name = scene.name(part);
    if (step != nullptr) {
      const collision::PartId id = collision_id(part);
      if (id.valid()) {
        by_id[id] = Highlight{.item = out.items.size(),
                              .triangles_usable = scene.collision_mesh(part) == mesh};
      }
    }
    out.items.push_back(std::move(item));
  }
  if (step == nullptr) return out;

  for (const collision::Contact& contact : step->contacts) {
    add_contact_side(by_id, contact.a, contact.triangle_a, out.items);
    add_contact_side(by_id, contact.b, contact.triangle_b, out.items);
  }
  for (const auto& [id, highlight] : by_id) {
    std::vector<std::uint32_t>& triangles = out.items[highlight.item].highlighted;
    if (highlight.whole) {
      triangles.resize(out.items[highlight.item].mesh->triangles.size());
      std::iota(triangles.begin(), triangles.end(), std::uint32_t{0});
    } else {
      std::sort(triangles.begin(), triangles.end());
      triangles.erase(std::unique(triangles.begin(), triangles.end()), triangles.end());
    }
  }
  return out;
}

RenderScene render_scene(const Simulation& simulation) {
  if (simulation.frame() == 0) return render_scene(simulation.scene());
  return render_scene(simulation.scene(), &simulation.collision_world().last_step(),
                      [&simulation](PartId part) { return simulation.collision_id(part); });
}

}  // namespace dovetail::engine
