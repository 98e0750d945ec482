#pragma once
/// \file scene_render.h
/// From a scene (and the contacts of a collision step) to a RenderScene.
///
/// Why: rendering takes plain data, the scene speaks of named parts and the
/// collision layer of PartIds and triangle indices. This adapter is the one
/// place where the three meet: one item per drawable part, at its world pose,
/// in the palette colour of its place in name order, with the triangles in
/// contact highlighted.

#include <functional>

#include "dovetail/collision/collision_world.h"
#include "dovetail/engine/render.h"
#include "dovetail/engine/scene.h"

namespace dovetail::engine {

class Simulation;

/// Maps a scene part to its id in the collision world, or an invalid id when
/// it has none (Simulation::collision_id).
using CollisionIdOf = std::function<collision::PartId(PartId)>;

/// One RenderItem per part with a render mesh, in name order, posed at the
/// part's world pose X_WP, in the part's own colour if it has one, otherwise
/// palette_color(i) for the i-th such part without one, named after the
/// part; the scene's named cameras.
///
/// With a `step`, the contacts of that step are highlighted (rules in
/// docs/rendering.md): a contact with triangles highlights those triangles of
/// both parts when a part's render mesh is its collision mesh (triangle
/// indices refer to the collision mesh; otherwise the part is not
/// highlighted); a contact without triangles (ContactDetail::kPairs, or a pair
/// decided at the box or hull level) highlights the whole of both parts.
/// `collision_id` maps parts to the step's PartIds and is required with a
/// step; throws RenderError without it.
RenderScene render_scene(const Scene& scene, const collision::StepResult* step = nullptr,
                         const CollisionIdOf& collision_id = {});

/// The simulation's scene as it is now, with the contacts of its last frame
/// highlighted (none before the first frame).
RenderScene render_scene(const Simulation& simulation);

}  // namespace dovetail::engine
