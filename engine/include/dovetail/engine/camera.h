#pragma once
/// \file camera.h
/// A pinhole camera, as files, scenes and the renderer hand it around.
///
/// Why its own header: cameras come from three places (a model file's own
/// cameras, a scene's named cameras, the renderer's built-in views) and go to
/// one (the renderer); the importer and the scene must not depend on the
/// renderer to carry them.

#include <string>
#include <utility>
#include <vector>

#include "dovetail/collision/types.h"

namespace dovetail::engine {

/// A pinhole camera looking from `eye` at `target`.
struct Camera {
  collision::Vec3 eye = collision::Vec3(1, 1, 1);
  collision::Vec3 target = collision::Vec3::Zero();
  collision::Vec3 up = collision::Vec3::UnitY();  ///< need not be orthogonal to the view direction
  double fov_y_degrees = 35;                      ///< vertical field of view, in (0, 180)
  friend bool operator==(const Camera&, const Camera&) = default;
};

/// A camera with the name it is looked up by.
using NamedCamera = std::pair<std::string, Camera>;

}  // namespace dovetail::engine
