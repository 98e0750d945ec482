#include "dovetail/engine/frame_recorder.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "../support/temp_dir.h"
#include "dovetail/collision/primitives.h"
#include "dovetail/engine/scene_render.h"
#include "dovetail/engine/simulation.h"

namespace dovetail::engine {
namespace {

namespace fs = std::filesystem;
using collision::Vec3;

/// A fresh folder for one test.
class TempDir : public test::TempDir {
 public:
  TempDir() : test::TempDir("dovetail_frames") {}
};

/// Pixels whose colour is `color` times one shade factor, within rounding.
std::size_t count_shades_of(const Image& image, const Color& color) {
  std::size_t count = 0;
  const double base = 255.0 * (color[0] + color[1] + color[2]);
  for (std::size_t p = 0; p < image.rgba.size() / 4; ++p) {
    const std::uint8_t* rgb = &image.rgba[4 * p];
    const double s = (rgb[0] + rgb[1] + rgb[2]) / base;
    if (s < 0.2 || s > 1.01) continue;
    bool match = true;
    for (int c = 0; c < 3; ++c) match = match && std::abs(rgb[c] - 255.0 * color[c] * s) <= 2.5;
    count += match;
  }
  return count;
}

Transform at(const Vec3& p) {
  Transform X;
  X.t = p;
  return X;
}

const Vec3 kApart(3.0, 0.2, 0.15);
const Vec3 kInside(0.8, 0.2, 0.15);  // 0.2 deep into the block, edges crossing its faces

/// A fixed block and a box pushed into it at frame 5 (triangle contacts from
/// frame 5 on); every frame before is apart.
Simulation two_boxes(collision::ContactDetail contacts = collision::ContactDetail::kTriangles,
                     int threads = 1) {
  Scene scene;
  const auto box =
      std::make_shared<const collision::Mesh>(collision::make_box(Vec3::Constant(0.5)));
  scene.add_part({.name = "block", .movable = false, .render_mesh = box});
  scene.add_part({.name = "slider", .X_QP = at(kApart), .render_mesh = box});
  SimulationSettings settings;
  settings.contacts = contacts;
  settings.collision_threads = threads;
  Simulation simulation(std::move(scene), settings);
  simulation.queue_pose({.frame = 5, .part = "slider", .X_QP = at(kInside)});
  return simulation;
}

FrameRecorderSettings small_frames(const fs::path& folder, std::uint64_t every) {
  FrameRecorderSettings settings;
  settings.folder = folder;
  settings.every = every;
  settings.render.width = 160;
  settings.render.height = 120;
  return settings;
}

std::vector<std::uint8_t> read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(FrameRecorder, FramePathIsZeroPadded) {
  EXPECT_EQ(FrameRecorder::frame_path("out", 123), fs::path("out") / "frame_000123.png");
  EXPECT_EQ(FrameRecorder::frame_path("out", 0), fs::path("out") / "frame_000000.png");
  EXPECT_EQ(FrameRecorder::frame_path("out", 1234567), fs::path("out") / "frame_1234567.png");
}

TEST(FrameRecorder, WritesEveryThirdFrameIntoANewFolder) {
  TempDir dir;
  const fs::path folder = dir / "run/frames";  // created with its parent
  Simulation simulation = two_boxes();
  FrameRecorder recorder(small_frames(folder, 3));
  EXPECT_EQ(recorder.run(simulation, 10), 10u);

  const std::vector<fs::path> expected = {folder / "frame_000000.png", folder / "frame_000003.png",
                                          folder / "frame_000006.png", folder / "frame_000009.png"};
  EXPECT_EQ(recorder.written(), expected);
  std::set<fs::path> on_disk;
  for (const auto& entry : fs::directory_iterator(folder)) on_disk.insert(entry.path());
  EXPECT_EQ(on_disk, std::set<fs::path>(expected.begin(), expected.end()));
  for (const fs::path& path : expected) {
    const std::vector<std::uint8_t> bytes = read_bytes(path);
    ASSERT_GE(bytes.size(), 8u) << path;
    EXPECT_EQ(bytes[1], 'P');
    EXPECT_EQ(bytes[2], 'N');
    EXPECT_EQ(bytes[3], 'G');
  }
}

TEST(FrameRecorder, ContactFramesShowTheHighlightColourOthersDoNot) {
  TempDir dir;
  Simulation simulation = two_boxes();
  const FrameRecorderSettings settings = small_frames(dir.path(), 3);
  FrameRecorder recorder(settings);
  std::vector<std::size_t> highlighted;
  for (int k = 0; k < 10; ++k) {
    simulation.step();
    if (recorder.record(simulation)) {
      highlighted.push_back(count_shades_of(recorder.last_image(), settings.render.highlight));
      // The slider is drawn in palette colour 1 in every frame; the block,
      // palette colour 0, shows only while nothing of it is highlighted (in
      // contact each of its faces towards the camera has a crossed triangle).
      EXPECT_GT(count_shades_of(recorder.last_image(), palette_color(1)), 50u);
      if (simulation.last_frame().frame < 5) {
        EXPECT_GT(count_shades_of(recorder.last_image(), palette_color(0)), 50u);
      }
    }
  }
  ASSERT_EQ(highlighted.size(), 4u);  // frames 0, 3 (apart), 6, 9 (in contact)
  EXPECT_EQ(highlighted[0], 0u);
  EXPECT_EQ(highlighted[1], 0u);
  EXPECT_GT(highlighted[2], 20u);
  EXPECT_GT(highlighted[3], 20u);
}

TEST(FrameRecorder, SameRunGivesSameFilesAtAnyThreadCount) {
  TempDir dir;
  for (const int threads : {1, 2}) {
    Simulation simulation = two_boxes(collision::ContactDetail::kTriangles, threads);
    FrameRecorder recorder(small_frames(dir / (threads == 1 ? "a" : "b"), 3));
    recorder.run(simulation, 10);
  }
  for (const char* frame : {"frame_000000.png", "frame_000006.png"}) {
    const auto a = read_bytes(dir / "a" / frame);
    EXPECT_FALSE(a.empty());
    EXPECT_EQ(a, read_bytes(dir / "b" / frame)) << frame;
  }
}

TEST(FrameRecorder, UnwritableFolderIsAnErrorNamingIt) {
  TempDir dir;
  const fs::path file = dir / "not_a_folder";
  std::ofstream(file) << "x";
  const fs::path folder = file / "frames";
  try {
    FrameRecorder recorder(small_frames(folder, 1));
    FAIL() << "no error for " << folder;
  } catch (const RenderError& error) {
    EXPECT_NE(std::string(error.what()).find(folder.string()), std::string::npos) << error.what();
  }
  try {
    FrameRecorder recorder(small_frames(file, 1));
    FAIL() << "no error for " << file;
  } catch (const RenderError& error) {
    EXPECT_NE(std::string(error.what()).find(file.string()), std::string::npos) << error.what();
  }
  EXPECT_THROW(FrameRecorder(small_frames(dir.path(), 0)), RenderError);
}

TEST(SceneRender, TriangleContactsHighlightOnlyTouchingTriangles) {
  Simulation simulation = two_boxes();
  for (int k = 0; k < 6; ++k) simulation.step();
  const RenderScene scene = render_scene(simulation);
  ASSERT_EQ(scene.items.size(), 2u);
  EXPECT_EQ(scene.items[0].name, "block");
  EXPECT_EQ(scene.items[1].name, "slider");
  EXPECT_EQ(scene.items[0].color, palette_color(0));
  EXPECT_EQ(scene.items[1].color, palette_color(1));
  EXPECT_EQ(scene.items[1].X_WP.t, kInside);
  for (const RenderItem& item : scene.items) {
    EXPECT_FALSE(item.highlighted.empty()) << item.name;
    EXPECT_LT(item.highlighted.size(), item.mesh->triangles.size()) << item.name;
    EXPECT_TRUE(std::is_sorted(item.highlighted.begin(), item.highlighted.end()));
  }
  // The same highlights from the scene, the step and the id map.
  const RenderScene again =
      render_scene(simulation.scene(), &simulation.collision_world().last_step(),
                   [&](PartId part) { return simulation.collision_id(part); });
  EXPECT_EQ(again.items[0].highlighted, scene.items[0].highlighted);
  EXPECT_EQ(again.items[1].highlighted, scene.items[1].highlighted);
  EXPECT_THROW(render_scene(simulation.scene(), &simulation.collision_world().last_step()),
               RenderError);
}

TEST(SceneRender, PairContactsHighlightWholeParts) {
  Simulation simulation = two_boxes(collision::ContactDetail::kPairs);
  for (int k = 0; k < 5; ++k) simulation.step();
  for (const RenderItem& item : render_scene(simulation).items) {
    EXPECT_TRUE(item.highlighted.empty()) << item.name;  // apart
  }
  simulation.step();
  for (const RenderItem& item : render_scene(simulation).items) {
    EXPECT_EQ(item.highlighted.size(), item.mesh->triangles.size()) << item.name;
  }
}

}  // namespace
}  // namespace dovetail::engine
