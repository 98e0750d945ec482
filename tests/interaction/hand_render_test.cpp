// The hand in renders: drawn in its own colour, reaching for a part of the
// engine assembly.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <sstream>

#include "dovetail/engine/render.h"
#include "dovetail/engine/scene.h"
#include "dovetail/engine/scene_render.h"
#include "dovetail/interaction/glove_plan.h"
#include "dovetail/interaction/glove_source.h"
#include "dovetail/interaction/hand.h"

namespace dovetail::interaction {
namespace {

const std::filesystem::path kEngine = std::filesystem::path(DOVETAIL_ASSIMP_MODELS) /
                                      "glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";

/// Pixels whose colour is the hand's under any shade: flat shading scales
/// all three channels alike, so the ratios G/R and B/R stay the hand's.
std::size_t hand_pixels(const engine::Image& image) {
  const double g_over_r = kHandColor[1] / kHandColor[0];
  const double b_over_r = kHandColor[2] / kHandColor[0];
  std::size_t count = 0;
  for (std::size_t i = 0; i + 3 < image.rgba.size(); i += 4) {
    const double r = image.rgba[i], g = image.rgba[i + 1], b = image.rgba[i + 2];
    if (r < 60) continue;  // too dark for the ratios to survive rounding to bytes
    if (std::abs(g / r - g_over_r) < 0.03 && std::abs(b / r - b_over_r) < 0.03) ++count;
  }
  return count;
}

TEST(HandRender, TheHandReachingForAnEnginePartIsDrawnInItsColour) {
  if (!std::filesystem::exists(kEngine)) GTEST_SKIP() << kEngine << " is not installed";
  const engine::Scene engine_parts = engine::load_assembly(kEngine);
  std::istringstream plan_text(
      "start 0.30 0.35 0.30  1 0 0 0\n"
      "reach 1.0  0.12 0.17 0.08  0.966 0 0.259 0\n"
      "close 0.5 power\n");
  const SimulatedGlove glove(read_plan(plan_text, "reach.plan"));
  const engine::RenderSettings settings{.width = 400, .height = 300, .camera = "iso"};

  engine::RenderScene without = engine::render_scene(engine_parts);
  engine::RenderScene with = without;
  for (engine::RenderItem& item : hand_render_items(HandModel(), glove.sample(1.5))) {
    with.items.push_back(std::move(item));
  }
  const engine::Image plain = engine::render(without, settings);
  const engine::Image reaching = engine::render(with, settings);
  EXPECT_EQ(hand_pixels(plain), 0U) << "no part of the engine has the hand's colour";
  EXPECT_GT(hand_pixels(reaching), 300U) << "the hand covers a visible patch";
  // The hand is above the crankcase, in the upper half of the picture.
  std::size_t upper = 0, lower = 0;
  for (int y = 0; y < reaching.height; ++y) {
    engine::Image row{reaching.width,
                      1,
                      {reaching.rgba.begin() + 4 * y * reaching.width,
                       reaching.rgba.begin() + 4 * (y + 1) * reaching.width}};
    (y < reaching.height / 2 ? upper : lower) += hand_pixels(row);
  }
  EXPECT_GT(upper, 10 * lower);
}

TEST(HandRender, SimulationPartsOfTheHandCarryTheHandColour) {
  engine::Simulation sim(engine::Scene{});
  const Hand hand(sim, std::make_shared<SimulatedGlove>(GlovePlan{}));
  const engine::RenderScene scene = engine::render_scene(sim.scene());
  ASSERT_EQ(scene.items.size(), kSegmentCount);
  for (const engine::RenderItem& item : scene.items) {
    ASSERT_TRUE(item.color);
    EXPECT_EQ((*item.color)[0], kHandColor[0]) << item.name;
    EXPECT_EQ((*item.color)[2], kHandColor[2]) << item.name;
  }
}

}  // namespace
}  // namespace dovetail::interaction
