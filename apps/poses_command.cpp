#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "cli.h"
#include "commands.h"
#include "dovetail/collision/pose_sampling.h"
#include "dovetail/engine/pose_list.h"

namespace dovetail::cli {

namespace {

constexpr const char* kHelp =
    R"(usage: dovetail poses A B --out FILE [--directions N] [--seed S] [--gaps g1,g2,...]

Writes a contact-distance pose list for B against A: for each of N random
(orientation, direction) samples, B is moved along the direction until it just
touches A (bisection with the boxtree method), and one pose is written per gap
from that contact distance. Gaps are fractions of the object size (the larger
bounding-box diagonal); negative gaps push B into A.

  --out FILE        the pose list to write
  --directions N    number of samples (default 100)
  --seed S          random seed (default 1); same seed, same list
  --gaps LIST       comma-separated gaps (default -0.05,-0.01,-0.001,0.001,0.01,0.05,0.2)

Each line is `tx ty tz qw qx qy qz gap`: the pose of B in A's frame and the gap
it was generated for (an extra column, ignored by pose-list readers), with 17
significant digits (the gap in its shortest exact form). Prints a one-line JSON summary.
)";

/// `text` on one line, for the comment header.
std::string one_line(std::string text) {
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return text;
}

/// Shortest text that reads back as the same double.
std::string shortest(double value) { return json_number(value); }

/// The pose list with its comment header (the command line that makes it again).
void write_poses(std::ofstream& out, const std::string& path_a, const std::string& path_b,
                 const collision::ContactPoseSettings& settings,
                 const std::vector<collision::SampledPose>& poses) {
  std::string gaps_text;
  for (double g : settings.gaps) {
    if (!gaps_text.empty()) gaps_text += ',';
    gaps_text += shortest(g);
  }
  out << "# dovetail poses " << one_line(path_a) << " " << one_line(path_b) << " --directions "
      << settings.directions << " --seed " << settings.seed << " --gaps " << gaps_text << "\n";
  out << "# tx ty tz qw qx qy qz gap\n";
  for (const collision::SampledPose& pose : poses) {
    out << engine::format_pose(pose.X_AB) << ' ' << shortest(pose.gap) << '\n';
  }
}

}  // namespace

int poses_command(std::span<const std::string> argv) {
  const Args args("poses", argv, {"out", "directions", "seed", "gaps"}, {});
  if (args.help()) {
    std::fputs(kHelp, stdout);
    return kExitOk;
  }
  args.expect_positional(2, "two mesh files A and B");
  const std::string out_path = args.required("out");
  collision::ContactPoseSettings settings;
  settings.directions =
      static_cast<int>(args.integer("directions", 1, 10'000'000).value_or(settings.directions));
  settings.seed = args.unsigned_integer("seed").value_or(settings.seed);
  if (std::optional<std::vector<double>> gaps = contact_gaps(args)) settings.gaps = *gaps;

  const std::string inputs[] = {args.positional()[0], args.positional()[1]};
  refuse_overwriting_input("poses", out_path, inputs);
  check_writable(out_path);  // replaced only once the poses are there

  const std::string& path_a = args.positional()[0];
  const std::string& path_b = args.positional()[1];
  const LoadedMesh a = load_mesh(path_a);
  const LoadedMesh b = load_mesh(path_b);
  refuse_overwriting_input("poses", out_path, a.report.files);
  refuse_overwriting_input("poses", out_path, b.report.files);
  const BuiltModel model_a = build_timed(collision::Method::kBoxtree, a.mesh);
  const BuiltModel model_b = build_timed(collision::Method::kBoxtree, b.mesh);

  const auto start = std::chrono::steady_clock::now();
  const std::vector<collision::SampledPose> poses =
      collision::contact_distance_poses(*model_a.model, *model_b.model, settings);
  const double generate_ms = ms_since(start);
  // A gap large for meshes this size can place B beyond the bound that
  // query reads (pose lists, docs/cli.md): refused, not written unreadable.
  const collision::Real bound = collision::MeshLimits{}.max_abs_coordinate;
  for (const collision::SampledPose& pose : poses) {
    if (!(pose.X_AB.t.cwiseAbs().maxCoeff() <= bound)) {
      throw InputError("poses: a gap of " + shortest(pose.gap) +
                       " places B beyond the coordinate limit of 1e30 that pose lists keep to; "
                       "give smaller --gaps");
    }
  }

  std::ofstream out(out_path, std::ios::binary | std::ios::trunc);
  if (!out) throw InputError(out_path + ": cannot be written: " + std::strerror(errno));
  write_poses(out, path_a, path_b, settings, poses);
  out.close();
  if (!out) throw InputError(out_path + ": write failed: " + std::strerror(errno));

  const std::size_t per_direction = settings.gaps.empty() ? 1 : settings.gaps.size();
  JsonLine json;
  json.add("out", out_path)
      .add("a", path_a)
      .add("b", path_b)
      .add("poses", std::uint64_t{poses.size()})
      .add("directions", std::int64_t{settings.directions})
      .add("directions_found", std::uint64_t{poses.size() / per_direction})
      .add("seed", settings.seed)
      .add("generate_ms", std::round(generate_ms * 1000.0) / 1000.0);
  std::fputs((json.str() + "\n").c_str(), stdout);
  if (poses.size() / per_direction < static_cast<std::size_t>(settings.directions)) {
    std::fprintf(stderr,
                 "dovetail: note: only %zu of %d directions reached contact (B may pass "
                 "through A without touching)\n",
                 poses.size() / per_direction, settings.directions);
  }
  return kExitOk;
}

}  // namespace dovetail::cli
