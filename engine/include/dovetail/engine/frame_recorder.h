#pragma once
/// \file frame_recorder.h
/// Renders every N-th frame of a simulation run to numbered PNG files.
///
/// Why: a headless run is checked by its report, but a picture of the parts
/// and of the triangles in contact shows at a glance what happened. The
/// recorder is called after each step; it renders the scene with the
/// frame's contacts highlighted (render_scene) and writes
/// `<folder>/frame_000123.png`, the same bytes for the same run.

#include <cstdint>
#include <filesystem>
#include <vector>

#include "dovetail/engine/render.h"

namespace dovetail::engine {

class Simulation;

/// What to record and how.
struct FrameRecorderSettings {
  std::filesystem::path folder{};  ///< created with its parents when missing
  std::uint64_t every = 1;         ///< records frames 0, every, 2 * every, ...; at least 1
  RenderSettings render{};         ///< image size, camera, colours
};

/// Writes frame images of a run.
class FrameRecorder {
 public:
  /// Creates the folder. Throws RenderError for `every` 0, an empty folder,
  /// or a folder that cannot be created (the message names the folder).
  explicit FrameRecorder(const FrameRecorderSettings& settings);

  /// Call after Simulation::step: when the frame just simulated is a
  /// multiple of `every`, renders it (render_scene(simulation)) and writes
  /// frame_path(folder, frame). Returns whether an image was written. Does
  /// nothing before the first frame or twice for the same frame. Throws
  /// RenderError naming the file when it cannot be written.
  bool record(const Simulation& simulation);

  /// Steps the simulation up to `frames` times, recording after each step;
  /// stops early when the simulation is paused, like Simulation::run.
  /// Returns the frames simulated.
  std::uint64_t run(Simulation& simulation, std::uint64_t frames);

  /// `<folder>/frame_<frame, zero-padded to 6 digits>.png`.
  static std::filesystem::path frame_path(const std::filesystem::path& folder, std::uint64_t frame);

  const FrameRecorderSettings& settings() const { return settings_; }
  /// The files written so far, in the order written.
  const std::vector<std::filesystem::path>& written() const { return written_; }
  /// The image of the last file written (empty before the first).
  const Image& last_image() const { return last_image_; }

 private:
  FrameRecorderSettings settings_;
  std::vector<std::filesystem::path> written_;
  Image last_image_;
  bool recorded_any_ = false;
  std::uint64_t last_recorded_ = 0;
};

}  // namespace dovetail::engine
