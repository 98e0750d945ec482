#include "dovetail/engine/render.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "../support/temp_dir.h"
#include "dovetail/engine/mesh_import.h"

namespace dovetail::engine {
namespace {

namespace fs = std::filesystem;
using collision::Vec3;

const fs::path kEngine =
    fs::path(DOVETAIL_ASSIMP_MODELS) / "glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";

/// A fresh folder for one test.
class TempDir : public test::TempDir {
 public:
  TempDir() : test::TempDir("dovetail_render") {}
};

std::array<std::uint8_t, 3> rgb_at(const Image& image, std::size_t pixel) {
  return {image.rgba[4 * pixel], image.rgba[4 * pixel + 1], image.rgba[4 * pixel + 2]};
}

std::array<std::uint8_t, 3> to_bytes(const Color& color) {
  std::array<std::uint8_t, 3> bytes{};
  for (int c = 0; c < 3; ++c) bytes[c] = static_cast<std::uint8_t>(std::lround(color[c] * 255.0));
  return bytes;
}

/// True when the pixel is `color` scaled by some shade in (0, 1], within
/// rounding: flat shading multiplies the base colour by one factor.
bool is_shade_of(const std::array<std::uint8_t, 3>& pixel, const Color& color) {
  const double shade = pixel[0] + pixel[1] + pixel[2];
  const double base = 255.0 * (color[0] + color[1] + color[2]);
  if (shade <= 0 || base <= 0) return false;
  const double s = shade / base;
  if (s < 0.2 || s > 1.01) return false;
  for (int c = 0; c < 3; ++c) {
    if (std::abs(pixel[c] - 255.0 * color[c] * s) > 2.5) return false;
  }
  return true;
}

std::size_t count_shades_of(const Image& image, const Color& color) {
  std::size_t count = 0;
  for (std::size_t p = 0; p < image.rgba.size() / 4; ++p)
    count += is_shade_of(rgb_at(image, p), color);
  return count;
}

/// A tetrahedron in front of a large square.
RenderScene small_scene() {
  auto tetra = std::make_shared<const collision::Mesh>(
      collision::make_mesh({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)},
                           {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}, "tetra"));
  auto square = std::make_shared<const collision::Mesh>(
      collision::make_mesh({Vec3(-2, -2, -1), Vec3(2, -2, -1), Vec3(2, 2, -1), Vec3(-2, 2, -1)},
                           {{0, 1, 2}, {0, 2, 3}}, "square"));
  RenderScene scene;
  scene.items.push_back({tetra, {}, std::nullopt, {}, "tetra"});
  scene.items.push_back({square, {}, std::nullopt, {}, "square"});
  return scene;
}

class EngineRender : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    ImportOptions options;
    options.merge = false;
    scene_ = new RenderScene(scene_from_import(import_file(kEngine, options)));
  }
  static void TearDownTestSuite() {
    delete scene_;
    scene_ = nullptr;
  }
  static RenderScene* scene_;
};
RenderScene* EngineRender::scene_ = nullptr;

TEST_F(EngineRender, ImageIsShadedAndShowsTheParts) {
  RenderSettings settings;
  settings.width = 400;
  settings.height = 300;
  const Image image = render(*scene_, settings);
  ASSERT_EQ(image.width, 400);
  ASSERT_EQ(image.height, 300);
  ASSERT_EQ(image.rgba.size(), 400u * 300u * 4u);
  ASSERT_GT(scene_->items.size(), 5u);

  const auto background = to_bytes(settings.background);
  std::set<std::array<std::uint8_t, 3>> colors;
  std::size_t foreground = 0;
  for (std::size_t p = 0; p < image.rgba.size() / 4; ++p) {
    EXPECT_EQ(image.rgba[4 * p + 3], 255);
    const auto pixel = rgb_at(image, p);
    colors.insert(pixel);
    if (pixel != background) ++foreground;
  }
  // Not blank, not one colour: many shades, and the engine fills a good part
  // of the frame without covering it all.
  EXPECT_GT(colors.size(), 50u);
  const double fraction = static_cast<double>(foreground) / (400.0 * 300.0);
  EXPECT_GT(fraction, 0.15);
  EXPECT_LT(fraction, 0.95);
  // The corners show the background (the camera frames the whole engine).
  EXPECT_EQ(rgb_at(image, 0), background);
  EXPECT_EQ(rgb_at(image, 400 * 300 - 1), background);
  // Most palette colours (the parts cycle through them) are visible.
  int visible = 0;
  for (std::size_t i = 0; i < 10; ++i) {
    if (count_shades_of(image, palette_color(i)) > 20) ++visible;
  }
  EXPECT_GE(visible, 6);
}

TEST_F(EngineRender, SameSceneGivesSameBytes) {
  RenderSettings settings;
  settings.width = 320;
  settings.height = 240;
  const Image first = render(*scene_, settings);
  const Image second = render(*scene_, settings);
  EXPECT_TRUE(first.rgba == second.rgba);
}

TEST_F(EngineRender, HighlightedTrianglesTakeTheHighlightColour) {
  RenderSettings settings;
  settings.width = 320;
  settings.height = 240;
  const Image plain = render(*scene_, settings);
  EXPECT_EQ(count_shades_of(plain, settings.highlight), 0u);

  RenderScene scene = *scene_;
  // Highlight every triangle of the largest part.
  std::size_t largest = 0;
  for (std::size_t i = 0; i < scene.items.size(); ++i) {
    if (scene.items[i].mesh->triangle_count() > scene.items[largest].mesh->triangle_count()) {
      largest = i;
    }
  }
  for (std::uint32_t t = 0; t < scene.items[largest].mesh->triangle_count(); ++t) {
    scene.items[largest].highlighted.push_back(t);
  }
  const Image highlighted = render(scene, settings);
  EXPECT_GT(count_shades_of(highlighted, settings.highlight), 100u);
  EXPECT_FALSE(plain.rgba == highlighted.rgba);
}

TEST(Render, DepthTestKeepsTheNearestSurface) {
  RenderScene scene = small_scene();
  scene.cameras.push_back(
      {"front", Camera{Vec3(0.2, 0.2, 10), Vec3(0.2, 0.2, 0), Vec3::UnitY(), 30}});
  RenderSettings settings;
  settings.width = 64;
  settings.height = 64;
  settings.camera = "front";
  const Image image = render(scene, settings);
  // The centre shows the tetrahedron (in front), not the square behind it,
  // whatever the drawing order.
  const std::size_t centre = 32 * 64 + 32;
  EXPECT_TRUE(is_shade_of(rgb_at(image, centre), palette_color(0)));
  std::swap(scene.items[0], scene.items[1]);
  scene.items[0].color = palette_color(1);
  scene.items[1].color = palette_color(0);
  const Image swapped = render(scene, settings);
  EXPECT_TRUE(is_shade_of(rgb_at(swapped, centre), palette_color(0)));
}

TEST(Render, ConcurrentCallsGiveTheSameBytes) {
  const RenderScene scene = small_scene();
  RenderSettings settings;
  settings.width = 96;
  settings.height = 64;
  const Image serial = render(scene, settings);
  std::vector<Image> images(4);
  std::vector<std::thread> threads;
  for (Image& image : images) {
    threads.emplace_back([&scene, &settings, &image] { image = render(scene, settings); });
  }
  for (std::thread& thread : threads) thread.join();
  for (const Image& image : images) EXPECT_TRUE(image.rgba == serial.rgba);
}

TEST(Render, ExplicitColourAndBackground) {
  RenderScene scene = small_scene();
  scene.items[1].color = Color{0.0F, 0.0F, 1.0F};
  RenderSettings settings;
  settings.width = 80;
  settings.height = 60;
  settings.background = {0.0F, 0.0F, 0.0F};
  const Image image = render(scene, settings);
  EXPECT_GT(count_shades_of(image, Color{0.0F, 0.0F, 1.0F}), 100u);
  EXPECT_EQ(rgb_at(image, 0), (std::array<std::uint8_t, 3>{0, 0, 0}));
}

TEST(Render, EmptySceneIsBackground) {
  RenderSettings settings;
  settings.width = 8;
  settings.height = 4;
  const Image image = render(RenderScene{}, settings);
  const auto background = to_bytes(settings.background);
  for (std::size_t p = 0; p < 32; ++p) EXPECT_EQ(rgb_at(image, p), background);
}

TEST(Render, AutoCameraIsDeterministicAndSeesTheCentre) {
  const RenderScene scene = small_scene();
  const Camera a = auto_camera(scene, 4.0 / 3.0);
  const Camera b = auto_camera(scene, 4.0 / 3.0);
  EXPECT_EQ(a.eye, b.eye);
  EXPECT_EQ(a.target, b.target);
  const collision::Bounds bounds = scene_bounds(scene);
  const double radius = 0.5 * (bounds.max - bounds.min).norm();
  EXPECT_LT((a.target - 0.5 * (bounds.min + bounds.max)).norm(), radius);
  EXPECT_GT((a.eye - a.target).norm(), radius);
}

TEST_F(EngineRender, FileCameraAndBuiltInViewsShowTheEngine) {
  // The engine file carries one perspective camera; every built-in view frames
  // the whole engine, and each view is a different picture.
  ASSERT_EQ(scene_->cameras.size(), 1u);
  EXPECT_EQ(scene_->cameras[0].first, "nodes[81]");
  const Camera& file_camera = scene_->cameras[0].second;
  EXPECT_NEAR(file_camera.eye.x(), 1005.987, 1e-2);  // the node's translation, file units
  EXPECT_NEAR(file_camera.fov_y_degrees, 0.3143463730812073 * 180 / std::numbers::pi, 1e-4);
  std::vector<std::string> names = builtin_views();
  names.push_back("nodes[81]");
  std::set<std::string> pictures;  // the images' bytes
  for (const std::string& name : names) {
    RenderSettings settings;
    settings.width = 160;
    settings.height = 120;
    settings.camera = name;
    ASSERT_TRUE(has_camera(*scene_, name));
    const Image image = render(*scene_, settings);
    const auto background = to_bytes(settings.background);
    std::size_t foreground = 0;
    for (std::size_t p = 0; p < image.rgba.size() / 4; ++p)
      foreground += rgb_at(image, p) != background;
    EXPECT_GT(foreground, 160u * 120u / 10) << name;
    if (name != "nodes[81]") {
      // Framed like auto: the corners show the background.
      EXPECT_EQ(rgb_at(image, 0), background) << name;
      EXPECT_EQ(rgb_at(image, 160 * 120 - 1), background) << name;
    }
    pictures.insert(std::string(image.rgba.begin(), image.rgba.end()));
  }
  EXPECT_EQ(pictures.size(), names.size());
  // "iso" is auto's view.
  RenderSettings iso, automatic;
  iso.width = automatic.width = 96;
  iso.height = automatic.height = 64;
  iso.camera = "iso";
  EXPECT_EQ(render(*scene_, iso).rgba, render(*scene_, automatic).rgba);
  EXPECT_FALSE(has_camera(*scene_, "nope"));
}

TEST(Render, UnknownCameraNamesTheChoices) {
  RenderSettings settings;
  settings.camera = "nope";
  try {
    render(small_scene(), settings);
    FAIL() << "no error";
  } catch (const RenderError& e) {
    EXPECT_NE(std::string(e.what()).find("'nope'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("front"), std::string::npos) << e.what();
  }
}

TEST(Render, BadInputIsRejected) {
  RenderScene scene = small_scene();
  RenderSettings settings;
  settings.width = 0;
  EXPECT_THROW(render(scene, settings), RenderError);
  settings.width = kMaxImageSize + 1;
  EXPECT_THROW(render(scene, settings), RenderError);
  settings.width = 16;
  settings.height = 16;
  settings.camera = "missing";
  try {
    render(scene, settings);
    ADD_FAILURE() << "expected RenderError";
  } catch (const RenderError& e) {
    EXPECT_NE(std::string(e.what()).find("no camera named 'missing'"), std::string::npos);
  }
  settings.camera.clear();
  scene.items[0].highlighted = {4};
  EXPECT_THROW(render(scene, settings), RenderError);
  scene.items[0].highlighted.clear();
  scene.items[0].mesh.reset();
  EXPECT_THROW(render(scene, settings), RenderError);
  scene = small_scene();
  scene.cameras.push_back({"flat", Camera{Vec3(0, 0, 1), Vec3(0, 0, 1), Vec3::UnitY(), 35}});
  settings.camera = "flat";
  EXPECT_THROW(render(scene, settings), RenderError);
}

std::uint32_t big_endian(const std::string& bytes, std::size_t offset) {
  std::uint32_t value = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    value = (value << 8) | static_cast<std::uint8_t>(bytes[offset + i]);
  }
  return value;
}

TEST(Render, PngHasSignatureAndHeader) {
  const TempDir dir;
  RenderSettings settings;
  settings.width = 37;
  settings.height = 23;
  const Image image = render(small_scene(), settings);
  const fs::path path = dir / "out.png";
  write_png(image, path);
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  ASSERT_GT(bytes.size(), 33u);
  EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_EQ(big_endian(bytes, 8), 13u);  // IHDR length
  EXPECT_EQ(bytes.substr(12, 4), "IHDR");
  EXPECT_EQ(big_endian(bytes, 16), 37u);
  EXPECT_EQ(big_endian(bytes, 20), 23u);
  EXPECT_EQ(bytes[24], 8);  // bit depth
  EXPECT_EQ(bytes[25], 6);  // colour type RGBA
  EXPECT_EQ(bytes.substr(bytes.size() - 8, 4), "IEND");

  // Same image, same file.
  const fs::path again = dir / "again.png";
  write_png(image, again);
  std::ifstream in_again(again, std::ios::binary);
  EXPECT_EQ(std::string((std::istreambuf_iterator<char>(in_again)), {}), bytes);
}

TEST(Render, PngErrorsNameThePath) {
  const TempDir dir;
  RenderSettings settings;
  settings.width = 4;
  settings.height = 4;
  const Image image = render(RenderScene{}, settings);
  const fs::path path = dir / "no/such/folder/out.png";
  try {
    write_png(image, path);
    ADD_FAILURE() << "expected RenderError";
  } catch (const RenderError& e) {
    EXPECT_NE(std::string(e.what()).find(path.string() + ": cannot be written"), std::string::npos)
        << e.what();
  }
  Image broken = image;
  broken.rgba.pop_back();
  EXPECT_THROW(write_png(broken, dir / "broken.png"), RenderError);
}

TEST(Render, SceneFromImportHasOneItemPerPart) {
  ImportOptions options;
  options.merge = false;
  const ImportReport report = import_file(kEngine, options);
  const RenderScene scene = scene_from_import(report);
  ASSERT_EQ(scene.items.size(), report.parts.size());
  for (std::size_t i = 0; i < scene.items.size(); ++i) {
    EXPECT_EQ(scene.items[i].name, report.parts[i].name);
    EXPECT_EQ(scene.items[i].mesh->triangle_count(), report.parts[i].mesh.triangle_count());
    ASSERT_TRUE(scene.items[i].color.has_value());
    EXPECT_EQ(*scene.items[i].color, palette_color(i));
  }
  EXPECT_TRUE(scene.items.back().X_WP.t == report.parts.back().X_RP.t);

  // Parts kept in their own frames render the same as parts in the root frame.
  options.part_frames = true;
  const RenderScene framed = scene_from_import(import_file(kEngine, options));
  RenderSettings settings;
  settings.width = 200;
  settings.height = 150;
  const Image a = render(scene, settings);
  const Image b = render(framed, settings);
  std::size_t differing = 0;
  for (std::size_t p = 0; p < a.rgba.size() / 4; ++p) differing += rgb_at(a, p) != rgb_at(b, p);
  EXPECT_LT(differing, a.rgba.size() / 4 / 50);
  EXPECT_EQ(scene.cameras, report.cameras);  // the file's own camera comes along
  EXPECT_EQ(scene.cameras.size(), 1u);
}

}  // namespace
}  // namespace dovetail::engine
