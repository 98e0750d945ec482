#include "dovetail/engine/render.h"

#include <GL/osmesa.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <span>
#include <string>

#include "png_writer.h"

namespace dovetail::engine {

namespace {

using collision::Mat3;
using collision::Vec3;

/// Part colours: distinct, medium-saturated hues that stay readable when
/// shaded and none of which looks like the default red highlight.
constexpr std::array<Color, 10> kPalette = {{
    {0.30F, 0.55F, 0.85F},  // blue
    {0.95F, 0.65F, 0.20F},  // orange
    {0.35F, 0.75F, 0.45F},  // green
    {0.65F, 0.45F, 0.80F},  // violet
    {0.25F, 0.75F, 0.78F},  // teal
    {0.88F, 0.80F, 0.30F},  // yellow
    {0.60F, 0.62F, 0.66F},  // steel grey
    {0.85F, 0.50F, 0.65F},  // pink
    {0.55F, 0.70F, 0.25F},  // olive
    {0.75F, 0.55F, 0.40F},  // tan
}};

/// Light: a constant ambient part plus a Lambert part from a light fixed to
/// the camera, a little above and right of the eye so that faces turned to
/// the viewer are not all equally bright. Both sides of a face are lit alike,
/// so meshes with inconsistent winding are not drawn inside out.
constexpr double kAmbient = 0.28;
constexpr double kDiffuse = 0.72;
const Vec3 kLightDirection_C = Vec3(0.35, 0.55, 1.0).normalized();

/// Vertices per glDrawArrays call (a multiple of 3).
constexpr int kBatchVertices = 3 * 65536;

/// The view: camera frame C has x right, y up and looks down -z (OpenGL's
/// eye space); p_C = R_CW * (p_W - eye).
struct View {
  Vec3 eye;
  Mat3 R_CW;
  double tan_half_fov_y = 0;
};

View make_view(const Camera& camera) {
  const double fov = camera.fov_y_degrees;
  if (!std::isfinite(fov) || fov <= 0 || fov >= 180) {
    throw RenderError("camera field of view must be in (0, 180) degrees, got " +
                      std::to_string(fov));
  }
  if (!camera.eye.allFinite() || !camera.target.allFinite() || !camera.up.allFinite()) {
    throw RenderError("camera eye, target and up must be finite");
  }
  const Vec3 forward = camera.target - camera.eye;
  if (forward.norm() == 0) throw RenderError("camera eye and target coincide");
  const Vec3 f = forward.normalized();
  const Vec3 side = f.cross(camera.up);
  if (side.norm() <= 1e-12 * camera.up.norm() || camera.up.norm() == 0) {
    throw RenderError("camera up direction is zero or parallel to the view direction");
  }
  const Vec3 r = side.normalized();
  const Vec3 u = r.cross(f);
  View view;
  view.eye = camera.eye;
  view.R_CW.row(0) = r.transpose();
  view.R_CW.row(1) = u.transpose();
  view.R_CW.row(2) = -f.transpose();
  view.tan_half_fov_y = std::tan(fov * std::numbers::pi / 360.0);
  return view;
}

std::uint8_t to_byte(double value) {
  return static_cast<std::uint8_t>(std::lround(std::clamp(value, 0.0, 1.0) * 255.0));
}

/// Vertex arrays for GL: camera-frame positions (computed in double, stored
/// as float) and one flat colour per triangle, repeated on its three corners.
struct Geometry {
  std::vector<float> positions;      ///< 9 per triangle
  std::vector<std::uint8_t> colors;  ///< 12 per triangle (RGBA)
  double min_depth = std::numeric_limits<double>::infinity();
  double max_depth = 0;
};

void check_items(const RenderScene& scene) {
  for (std::size_t i = 0; i < scene.items.size(); ++i) {
    const RenderItem& item = scene.items[i];
    const std::string label = "render item " + std::to_string(i) +
                              (item.name.empty() ? std::string() : " '" + item.name + "'");
    if (!item.mesh) throw RenderError(label + " has no mesh");
    const std::size_t count = item.mesh->triangle_count();
    for (std::uint32_t t : item.highlighted) {
      if (t >= count) {
        throw RenderError(label + ": highlighted triangle " + std::to_string(t) +
                          " is out of range (the mesh has " + std::to_string(count) +
                          " triangles)");
      }
    }
  }
}

Geometry build_geometry(const RenderScene& scene, const View& view, const Color& highlight) {
  std::size_t triangles = 0;
  for (const RenderItem& item : scene.items) triangles += item.mesh->triangle_count();
  Geometry geometry;
  geometry.positions.reserve(9 * triangles);
  geometry.colors.reserve(12 * triangles);

  std::vector<Vec3> p_C;
  std::vector<std::uint8_t> is_highlighted;
  for (std::size_t i = 0; i < scene.items.size(); ++i) {
    const RenderItem& item = scene.items[i];
    const collision::Mesh& mesh = *item.mesh;
    const Color base = item.color.value_or(palette_color(i));
    is_highlighted.assign(mesh.triangle_count(), 0);
    for (std::uint32_t t : item.highlighted) is_highlighted[t] = 1;

    p_C.resize(mesh.vertex_count());
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
      p_C[v] = view.R_CW * (item.X_WP.apply(mesh.vertices[v]) - view.eye);
      const double depth = -p_C[v].z();
      if (depth > 0) geometry.min_depth = std::min(geometry.min_depth, depth);
      geometry.max_depth = std::max(geometry.max_depth, depth);
    }

    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
      const collision::TriangleIndices& tri = mesh.triangles[t];
      const Vec3& a = p_C[tri[0]];
      const Vec3& b = p_C[tri[1]];
      const Vec3& c = p_C[tri[2]];
      // Flat Lambert shading, two-sided.
      const Vec3 n = (b - a).cross(c - a);
      const double length = n.norm();
      const double lambert = length > 0 ? std::abs(n.dot(kLightDirection_C)) / length : 0.0;
      const double shade = kAmbient + kDiffuse * lambert;
      const Color& color = is_highlighted[t] != 0 ? highlight : base;
      const std::uint8_t rgba[4] = {to_byte(color[0] * shade), to_byte(color[1] * shade),
                                    to_byte(color[2] * shade), 255};
      for (const Vec3* p : {&a, &b, &c}) {
        geometry.positions.push_back(static_cast<float>(p->x()));
        geometry.positions.push_back(static_cast<float>(p->y()));
        geometry.positions.push_back(static_cast<float>(p->z()));
        geometry.colors.insert(geometry.colors.end(), rgba, rgba + 4);
      }
    }
  }
  return geometry;
}

/// An OSMesa context bound to a caller-owned colour buffer for its lifetime.
class OffscreenContext {
 public:
  OffscreenContext(int width, int height, std::vector<std::uint8_t>& buffer) {
    context_ = OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, nullptr);
    if (context_ == nullptr) throw RenderError("cannot create the off-screen OpenGL context");
    buffer.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4, 0);
    if (OSMesaMakeCurrent(context_, buffer.data(), GL_UNSIGNED_BYTE, width, height) == 0) {
      OSMesaDestroyContext(context_);
      throw RenderError("cannot render an image of " + std::to_string(width) + "x" +
                        std::to_string(height) + " pixels (too large for the renderer)");
    }
  }
  ~OffscreenContext() {
    OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);
    OSMesaDestroyContext(context_);
  }
  OffscreenContext(const OffscreenContext&) = delete;
  OffscreenContext& operator=(const OffscreenContext&) = delete;

 private:
  OSMesaContext context_ = nullptr;
};

void check_gl(const char* what) {
  const GLenum error = glGetError();
  if (error != GL_NO_ERROR) {
    char code[16];
    std::snprintf(code, sizeof code, "0x%04x", static_cast<unsigned>(error));
    throw RenderError(std::string("OpenGL error ") + code + " while " + what);
  }
}

void draw(const Geometry& geometry, const View& view, const RenderSettings& settings) {
  glViewport(0, 0, settings.width, settings.height);
  glClearColor(settings.background[0], settings.background[1], settings.background[2], 1.0F);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  const std::size_t vertex_count = geometry.positions.size() / 3;
  if (vertex_count == 0 || !(geometry.max_depth > 0)) return;  // nothing in front of the camera

  // Depth range from what is actually in front of the camera, with a margin;
  // the near plane is kept at a sane fraction of the far one for precision.
  const double far_plane = geometry.max_depth * 1.01;
  const double near_plane = std::max(geometry.min_depth * 0.99, far_plane * 1e-4);
  const double half_h = near_plane * view.tan_half_fov_y;
  const double half_w = half_h * static_cast<double>(settings.width) / settings.height;
  glMatrixMode(GL_PROJECTION);
  glLoadIdentity();
  glFrustum(-half_w, half_w, -half_h, half_h, near_plane, far_plane);
  glMatrixMode(GL_MODELVIEW);
  glLoadIdentity();

  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_LIGHTING);
  glDisable(GL_CULL_FACE);
  glDisable(GL_DITHER);
  glDisable(GL_BLEND);
  glShadeModel(GL_FLAT);

  glEnableClientState(GL_VERTEX_ARRAY);
  glEnableClientState(GL_COLOR_ARRAY);
  for (std::size_t first = 0; first < vertex_count; first += kBatchVertices) {
    const std::size_t count = std::min<std::size_t>(kBatchVertices, vertex_count - first);
    glVertexPointer(3, GL_FLOAT, 0, geometry.positions.data() + 3 * first);
    glColorPointer(4, GL_UNSIGNED_BYTE, 0, geometry.colors.data() + 4 * first);
    glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(count));
  }
  glDisableClientState(GL_COLOR_ARRAY);
  glDisableClientState(GL_VERTEX_ARRAY);
  check_gl("drawing");
}

Camera find_camera(const RenderScene& scene, const std::string& name, double aspect) {
  for (const auto& [camera_name, camera] : scene.cameras) {
    if (camera_name == name) return camera;
  }
  if (std::optional<Camera> view = view_camera(scene, aspect, name)) return *view;
  std::string known;
  for (const auto& entry : scene.cameras) known += (known.empty() ? "" : ", ") + entry.first;
  std::string views;
  for (const std::string& v : builtin_views()) views += (views.empty() ? "" : ", ") + v;
  throw RenderError("no camera named '" + name +
                    "' (cameras of the scene: " + (known.empty() ? std::string("none") : known) +
                    "; views: " + views + "; or 'auto')");
}

}  // namespace

Color palette_color(std::size_t index) { return kPalette[index % kPalette.size()]; }

collision::Bounds scene_bounds(const RenderScene& scene) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  collision::Bounds bounds{Vec3::Constant(kInf), Vec3::Constant(-kInf)};
  for (const RenderItem& item : scene.items) {
    if (!item.mesh) continue;
    for (const Vec3& p_P : item.mesh->vertices) {
      const Vec3 p_W = item.X_WP.apply(p_P);
      bounds.min = bounds.min.cwiseMin(p_W);
      bounds.max = bounds.max.cwiseMax(p_W);
    }
  }
  if (!(bounds.min.x() <= bounds.max.x())) {
    bounds = {Vec3::Constant(-0.5), Vec3::Constant(0.5)};
  }
  return bounds;
}

namespace {

struct BuiltinView {
  const char* name;
  Vec3 direction;  ///< from the target towards the eye
  Vec3 up;
};

const std::array<BuiltinView, 7> kViews = {{
    {"front", Vec3::UnitZ(), Vec3::UnitY()},
    {"back", -Vec3::UnitZ(), Vec3::UnitY()},
    {"right", Vec3::UnitX(), Vec3::UnitY()},
    {"left", -Vec3::UnitX(), Vec3::UnitY()},
    {"top", Vec3::UnitY(), -Vec3::UnitZ()},
    {"bottom", -Vec3::UnitY(), Vec3::UnitZ()},
    {"iso", Vec3(1.0, 0.75, 1.4).normalized(), Vec3::UnitY()},
}};

/// The camera looking along -d (d: from the target towards the eye) with
/// `up`, framed to hold the whole scene.
Camera framed_camera(const RenderScene& scene, double aspect, const Vec3& d, const Vec3& up);

}  // namespace

const std::vector<std::string>& builtin_views() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const BuiltinView& v : kViews) out.emplace_back(v.name);
    return out;
  }();
  return names;
}

std::optional<Camera> view_camera(const RenderScene& scene, double aspect,
                                  const std::string& view) {
  for (const BuiltinView& v : kViews) {
    if (view == v.name) return framed_camera(scene, aspect, v.direction, v.up);
  }
  return std::nullopt;
}

bool has_camera(const RenderScene& scene, const std::string& name) {
  if (name.empty() || name == "auto") return true;
  for (const auto& entry : scene.cameras) {
    if (entry.first == name) return true;
  }
  for (const BuiltinView& v : kViews) {
    if (name == v.name) return true;
  }
  return false;
}

Camera auto_camera(const RenderScene& scene, double aspect) {
  return framed_camera(scene, aspect, kViews.back().direction, kViews.back().up);
}

namespace {

Camera framed_camera(const RenderScene& scene, double aspect, const Vec3& d, const Vec3& up) {
  if (!std::isfinite(aspect) || aspect <= 0) aspect = 1;
  const collision::Bounds bounds = scene_bounds(scene);
  const Vec3 center = 0.5 * (bounds.min + bounds.max);
  double radius = 0.5 * (bounds.max - bounds.min).norm();
  if (!(radius > 0) || !std::isfinite(radius)) radius = 1;

  Camera camera;
  camera.target = center;
  camera.up = up;
  const Vec3 r = camera.up.cross(d).normalized();
  const Vec3 u = d.cross(r);
  const double tan_y = std::tan(camera.fov_y_degrees * std::numbers::pi / 360.0);
  const double tan_x = tan_y * aspect;
  std::vector<Vec3> points_W;
  for (const RenderItem& item : scene.items) {
    if (!item.mesh) continue;
    for (const Vec3& p_P : item.mesh->vertices) points_W.push_back(item.X_WP.apply(p_P));
  }
  double deepest = 0;  // how far the bounds reach towards the eye
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3 p((corner & 1) != 0 ? bounds.max.x() : bounds.min.x(),
                 (corner & 2) != 0 ? bounds.max.y() : bounds.min.y(),
                 (corner & 4) != 0 ? bounds.max.z() : bounds.min.z());
    if (points_W.size() < 8 && scene.items.empty()) points_W.push_back(p);
    deepest = std::max(deepest, (p - center).dot(d));
  }

  // The eye at distance D along d from the target sees a point q (relative
  // to the target) at depth D - q.d; it is inside the view when its sideways
  // and upward offsets are within depth * tan. The smallest D that holds
  // every point, with a margin, and never inside the bounds:
  const auto fit_distance = [&](const Vec3& target) {
    double distance = 0;
    for (const Vec3& p_W : points_W) {
      const Vec3 q = p_W - target;
      const double toward = q.dot(d);
      distance = std::max(
          {distance, std::abs(q.dot(r)) / tan_x + toward, std::abs(q.dot(u)) / tan_y + toward});
    }
    return std::max(1.06 * distance, deepest + (target - center).dot(d) + 0.05 * radius);
  };
  // One centring step: move the target to the middle of where the points
  // land on the image, then fit the distance again.
  const double first = fit_distance(center);
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = -lo;
  for (const Vec3& p_W : points_W) {
    const Vec3 q = p_W - center;
    const double depth = first - q.dot(d);
    const Vec3 screen(q.dot(r) / depth, q.dot(u) / depth, 0);
    lo = lo.cwiseMin(screen);
    hi = hi.cwiseMax(screen);
  }
  camera.target = center + first * (0.5 * (lo.x() + hi.x()) * r + 0.5 * (lo.y() + hi.y()) * u);
  camera.eye = camera.target + fit_distance(camera.target) * d;
  return camera;
}

}  // namespace

Image render(const RenderScene& scene, const RenderSettings& settings) {
  for (const auto& [what, value] :
       {std::pair{"width", settings.width}, std::pair{"height", settings.height}}) {
    if (value < 1 || value > kMaxImageSize) {
      throw RenderError(std::string("image ") + what + " must be 1 to " +
                        std::to_string(kMaxImageSize) + ", got " + std::to_string(value));
    }
  }
  check_items(scene);
  const double aspect = static_cast<double>(settings.width) / settings.height;
  const Camera camera = settings.camera.empty() || settings.camera == "auto"
                            ? auto_camera(scene, aspect)
                            : find_camera(scene, settings.camera, aspect);
  const View view = make_view(camera);
  const Geometry geometry = build_geometry(scene, view, settings.highlight);

  Image image;
  image.width = settings.width;
  image.height = settings.height;
  std::vector<std::uint8_t> buffer;
  {
    OffscreenContext context(settings.width, settings.height, buffer);
    draw(geometry, view, settings);
    glFinish();
    image.rgba.resize(buffer.size());
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, settings.width, settings.height, GL_RGBA, GL_UNSIGNED_BYTE,
                 image.rgba.data());
    check_gl("reading the pixels");
  }
  // GL rows run from the bottom; Image rows from the top. Every pixel is opaque.
  const std::size_t stride = static_cast<std::size_t>(image.width) * 4;
  for (std::size_t top = 0, bottom = static_cast<std::size_t>(image.height) - 1; top < bottom;
       ++top, --bottom) {
    std::swap_ranges(image.rgba.begin() + static_cast<std::ptrdiff_t>(top * stride),
                     image.rgba.begin() + static_cast<std::ptrdiff_t>((top + 1) * stride),
                     image.rgba.begin() + static_cast<std::ptrdiff_t>(bottom * stride));
  }
  for (std::size_t i = 3; i < image.rgba.size(); i += 4) image.rgba[i] = 255;
  return image;
}

void write_png(const Image& image, const std::filesystem::path& path) {
  write_rgba_png(image.rgba, image.width, image.height, path);
}

RenderScene scene_from_import(const ImportReport& report) {
  RenderScene scene;
  scene.items.reserve(report.parts.size());
  for (std::size_t i = 0; i < report.parts.size(); ++i) {
    RenderItem item;
    item.mesh = std::make_shared<const collision::Mesh>(report.parts[i].mesh);
    item.X_WP = report.parts[i].X_RP;
    item.color = palette_color(i);
    item.name = report.parts[i].name;
    scene.items.push_back(std::move(item));
  }
  scene.cameras = report.cameras;
  return scene;
}

}  // namespace dovetail::engine
