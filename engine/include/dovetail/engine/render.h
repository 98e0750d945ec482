#pragma once
/// \file render.h
/// Headless rendering of a set of posed meshes to an RGBA image and to PNG.
///
/// Why: a simulator that runs without a display still has to show what it
/// did. A scene is handed over as plain data (meshes, poses, colours, the
/// triangles to highlight, named cameras), drawn off-screen in software with
/// flat Lambert shading and a depth test, and comes back as plain pixels. The
/// same input gives the same bytes; nothing of the graphics library or the
/// PNG library shows in this header.

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "dovetail/collision/mesh.h"
#include "dovetail/collision/types.h"
#include "dovetail/engine/camera.h"
#include "dovetail/engine/mesh_import.h"

namespace dovetail::engine {

/// Thrown when a scene cannot be rendered or an image not written; what()
/// says what is wrong (and names the file for write_png).
class RenderError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An RGB colour, each component in [0, 1].
using Color = std::array<float, 3>;

/// One mesh placed in the world.
struct RenderItem {
  std::shared_ptr<const collision::Mesh> mesh;  ///< required
  collision::Transform X_WP;                    ///< pose of the part P in the world W
  /// Base colour; when empty the item gets palette_color(its index in the scene).
  std::optional<Color> color;
  /// Triangle indices of `mesh` drawn in the highlight colour (for example the
  /// triangles in contact). Indices must be below the mesh's triangle count.
  std::vector<std::uint32_t> highlighted;
  std::string name;  ///< for messages
};

/// Everything that is drawn.
struct RenderScene {
  std::vector<RenderItem> items;
  std::vector<NamedCamera> cameras;  ///< named cameras, looked up by name before the built-in views
};

/// How to draw.
struct RenderSettings {
  int width = 1024;  ///< pixels, 1 to kMaxImageSize
  int height = 768;  ///< pixels, 1 to kMaxImageSize
  /// Empty or "auto": auto_camera; otherwise a camera of the scene, or a
  /// built-in view (see view_camera).
  std::string camera;
  Color background{0.93F, 0.94F, 0.96F};
  Color highlight{1.0F, 0.1F, 0.1F};
};

/// Largest accepted image width and height.
inline constexpr int kMaxImageSize = 16384;

/// Pixels, row by row from the top, four bytes (R, G, B, A) per pixel.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba;
};

/// The colour of entry `index` of the fixed part palette (cycles).
Color palette_color(std::size_t index);

/// World-frame bounds of every item's vertices; a unit cube around the origin
/// for an empty scene.
collision::Bounds scene_bounds(const RenderScene& scene);

/// A camera that shows the whole scene: it looks at the centre of the
/// scene's bounds from a fixed oblique direction (from +x, +y, +z, y up) and
/// backs off until the bounding sphere fits an image of the given aspect
/// (width / height). Deterministic.
Camera auto_camera(const RenderScene& scene, double aspect);

/// Names of the built-in views: front (from +z), back (from -z), right (from
/// +x), left (from -x), top (from +y, -z up), bottom (from -y, +z up) and iso
/// (auto_camera's oblique direction); y is up unless stated.
const std::vector<std::string>& builtin_views();

/// A built-in view framed like auto_camera: looking at the scene's centre
/// along the view's direction, backed off until everything fits an image of
/// the given aspect. Nullopt for a name that is not a built-in view.
std::optional<Camera> view_camera(const RenderScene& scene, double aspect, const std::string& view);

/// Whether `name` selects a camera for `scene`: "auto", a named camera of the
/// scene, or a built-in view.
bool has_camera(const RenderScene& scene, const std::string& name);

/// Draws the scene. Throws RenderError for bad settings (sizes, an unknown
/// camera name, a degenerate camera), an item without mesh or with an
/// out-of-range highlighted triangle, or when the off-screen context cannot be
/// created. Each call creates and destroys its own context, so calls from
/// different threads do not share state.
Image render(const RenderScene& scene, const RenderSettings& settings = {});

/// Writes `image` as an 8-bit RGBA PNG. Throws RenderError naming `path` when
/// the file cannot be written.
void write_png(const Image& image, const std::filesystem::path& path);

/// One item per imported part (posed by the part's X_RP, so the file's root
/// frame is the world; palette colours in part order; named after the
/// parts), and the file's cameras.
RenderScene scene_from_import(const ImportReport& report);

}  // namespace dovetail::engine
