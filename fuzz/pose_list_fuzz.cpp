// Pose lists (engine::read_pose_list): any input either reads or throws
// PoseListError; every pose read is finite with an orthonormal rotation, and
// format_pose of it reads back with the same translation bits (pose_list.h).

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "dovetail/engine/pose_list.h"
#include "fuzz_support.h"

using namespace dovetail;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = fuzz::scratch_dir() / "poses.txt";
  fuzz::write_file(path, fuzz::as_text(data, size));
  std::vector<engine::PoseEntry> poses;
  try {
    poses = engine::read_pose_list(path);
  } catch (const engine::PoseListError&) {
    return 0;
  }
  for (const engine::PoseEntry& pose : poses) {
    const collision::Transform& X = pose.X_AB;
    fuzz::require(X.t.allFinite() && X.R.allFinite(), "a pose read is finite");
    const collision::Real error = (X.R * X.R.transpose() - collision::Mat3::Identity()).cwiseAbs().maxCoeff();
    fuzz::require(error < 1e-12, "a pose read has an orthonormal rotation");
    const std::optional<collision::Transform> again = engine::parse_pose_line(engine::format_pose(X), "again");
    fuzz::require(again.has_value() && again->t == X.t, "a formatted pose reads back its translation");
  }
  return 0;
}
