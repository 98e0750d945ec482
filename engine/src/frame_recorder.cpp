#include "dovetail/engine/frame_recorder.h"

#include <cstdio>
#include <string>
#include <system_error>
#include <utility>

#include "dovetail/engine/scene_render.h"
#include "dovetail/engine/simulation.h"

namespace dovetail::engine {

namespace fs = std::filesystem;

FrameRecorder::FrameRecorder(const FrameRecorderSettings& settings) : settings_(settings) {
  if (settings_.every == 0) throw RenderError("FrameRecorder: 'every' must be at least 1");
  if (settings_.folder.empty()) throw RenderError("FrameRecorder: no folder given");
  std::error_code ec;
  fs::create_directories(settings_.folder, ec);
  if (ec) {
    throw RenderError(settings_.folder.string() +
                      ": cannot create the frame folder: " + ec.message());
  }
  if (!fs::is_directory(settings_.folder, ec)) {
    throw RenderError(settings_.folder.string() + ": cannot create the frame folder: not a folder");
  }
}

fs::path FrameRecorder::frame_path(const fs::path& folder, std::uint64_t frame) {
  char name[48];
  std::snprintf(name, sizeof(name), "frame_%06llu.png", static_cast<unsigned long long>(frame));
  return folder / name;
}

bool FrameRecorder::record(const Simulation& simulation) {
  if (simulation.frame() == 0) return false;
  const std::uint64_t frame = simulation.last_frame().frame;
  if (frame % settings_.every != 0) return false;
  if (recorded_any_ && frame == last_recorded_) return false;
  const fs::path path = frame_path(settings_.folder, frame);
  Image image = render(render_scene(simulation), settings_.render);
  write_png(image, path);
  last_image_ = std::move(image);
  written_.push_back(path);
  recorded_any_ = true;
  last_recorded_ = frame;
  return true;
}

std::uint64_t FrameRecorder::run(Simulation& simulation, std::uint64_t frames) {
  std::uint64_t done = 0;
  while (done < frames && !simulation.paused()) {
    simulation.step();
    ++done;
    record(simulation);
  }
  return done;
}

}  // namespace dovetail::engine
