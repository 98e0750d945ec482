/// \file glove_command.cpp
/// `dovetail glove`: the glove tools users need before scenarios exist:
/// convert a CyberGlove or OpenXR recording to a glove trace, turn a
/// simulated-glove plan into a trace, check a trace.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "cli.h"
#include "commands.h"
#include "dovetail/interaction/cyberglove.h"
#include "dovetail/interaction/glove_plan.h"
#include "dovetail/interaction/glove_source.h"
#include "dovetail/interaction/glove_trace.h"
#include "dovetail/interaction/hand_model.h"
#include "dovetail/interaction/openxr_hand.h"

namespace dovetail::cli {

namespace {

using interaction::GloveSample;

constexpr const char* kHelp =
    R"(usage: dovetail glove convert --cyberglove RAW --calibration CAL --out TRACE
       dovetail glove convert --openxr JOINTS --out TRACE
       dovetail glove plan PLAN --out TRACE [--rate HZ] [--noise] [--seed N]
       dovetail glove check TRACE

Glove traces (CSV: t, x y z, qw qx qy qz, 22 joint angles; see docs/cli.md).

  convert        a recording made elsewhere to a glove trace:
    --cyberglove RAW     CyberGlove rows `t` + 22 raw counts in the glove's native
                         order [+ x y z qw qx qy qz], with
    --calibration CAL    22 rows `GAIN OFFSET` (or a row of A and b): angle = A raw + b
    --openxr JOINTS      OpenXR hand-joint poses (26 joints: J_px J_py J_pz J_qx J_qy
                         J_qz J_qw per joint), converted to the 22 angles
  plan           samples a simulated-glove plan (docs/interaction.md) into a trace
    --rate HZ            samples per second (default 90)
    --noise              through the glove noise and latency model (defaults of
                         docs/interaction.md), seeded by
    --seed N             (default 1)
  check          reads a trace and reports its samples, duration and rate
  --out TRACE    the trace to write

Bad input gives an error naming the file and the line and exit code 1. Prints a
one-line JSON summary on standard output.
)";

void print_summary(const std::string& action, const std::vector<GloveSample>& samples,
                   const std::string& out) {
  JsonLine json;
  json.add("action", action).add("samples", std::uint64_t{samples.size()});
  const double duration = samples.empty() ? 0 : samples.back().t - samples.front().t;
  json.add("start", samples.empty() ? 0.0 : samples.front().t).add("duration", duration);
  if (samples.size() >= 2) {
    const interaction::TraceGaps g = interaction::trace_gaps(samples);
    // Rounded to a millionth of a hertz: 1 / (1 / 120.0) is not quite 120.
    json.add("rate_hz_median", std::round(1e6 / g.median) / 1e6)
        .add("gap_max_s", g.widest)
        .add("gap_max_after_s", g.widest_after);
  }
  if (!out.empty()) json.add("out", out);
  std::fputs((json.str() + "\n").c_str(), stdout);
}

/// Runs a reader or writer, turning the interaction layer's errors into InputError.
template <typename F>
auto input_step(F&& step) {
  try {
    return step();
  } catch (const interaction::TraceError& e) {
    throw InputError(e.what());
  } catch (const interaction::PlanError& e) {
    throw InputError(e.what());
  }
}

int convert(std::span<const std::string> argv) {
  const Args args("glove convert", argv, {"cyberglove", "calibration", "openxr", "out"}, {});
  if (args.help()) {
    std::fputs(kHelp, stdout);
    return kExitOk;
  }
  args.expect_positional(0, "no positional arguments");
  const std::string out = args.required("out");
  const auto raw = args.value("cyberglove");
  const auto xr = args.value("openxr");
  if (raw.has_value() == xr.has_value()) {
    throw UsageError("glove convert: give one of --cyberglove RAW or --openxr JOINTS");
  }
  std::vector<GloveSample> samples;
  if (raw) {
    const std::string calibration = args.required("calibration");
    const std::string inputs[] = {*raw, calibration};
    refuse_overwriting_input("glove convert", out, inputs);
    samples = input_step([&] {
      return interaction::read_cyberglove_raw(*raw, interaction::read_calibration(calibration));
    });
  } else {
    if (args.value("calibration")) {
      throw UsageError("glove convert: --calibration belongs to --cyberglove");
    }
    const std::string inputs[] = {*xr};
    refuse_overwriting_input("glove convert", out, inputs);
    samples = input_step([&] { return interaction::read_openxr(*xr); });
  }
  input_step([&] {
    interaction::write_trace(out, samples);
    return 0;
  });
  print_summary(raw ? "convert_cyberglove" : "convert_openxr", samples, out);
  return kExitOk;
}

/// The most samples `glove plan` writes: 31 hours at 90 Hz, about 4 GB while sampled.
constexpr double kMaxPlanSamples = 1e7;

/// --rate in Hz (default 90); any bad value gets the range's message.
double plan_rate(const Args& args) {
  const std::optional<std::string> text = args.value("rate");
  if (!text) return 90;
  double rate = -1;
  try {
    rate = *args.number("rate", 0);
  } catch (const UsageError&) {
    // not a number: the range's message below
  }
  if (!(rate > 0) || rate > 1e5) {
    throw UsageError("glove plan: --rate must be a number of Hz in (0, 100000], not '" + *text +
                     "'");
  }
  return rate;
}

/// The plan's samples at each multiple of 1/rate up to its end, and at the
/// end itself when it falls between two of them; `path` names the plan in
/// the error for a plan too long to hold.
std::vector<GloveSample> sample_plan(const interaction::GloveSource& source, double rate,
                                     const std::string& path) {
  const double end = source.end_time();
  // Counted as a double first: a plan of 1e300 s would not fit any integer.
  // Every sample is held until the trace is written (about 400 bytes each).
  const double on_grid = std::floor(end * rate + 1e-9);  // the last multiple of 1/rate
  const bool end_between = on_grid / rate < end;
  const double wanted = on_grid + (end_between ? 2 : 1);
  if (!(wanted <= kMaxPlanSamples)) {
    char text[160];
    std::snprintf(text, sizeof text,
                  ": the plan lasts %g s, %g samples at %g Hz; a trace holds at most 10^7 "
                  "(lower --rate or shorten the plan)",
                  end, wanted, rate);
    throw InputError(path + text);
  }
  const auto count = static_cast<std::uint64_t>(on_grid) + 1;
  std::vector<GloveSample> samples;
  samples.reserve(count);
  for (std::uint64_t k = 0; k < count; ++k) {
    samples.push_back(source.sample(static_cast<double>(k) / rate));
  }
  if (end_between) samples.push_back(source.sample(end));
  return samples;
}

int plan(std::span<const std::string> argv) {
  const Args args("glove plan", argv, {"out", "rate", "seed"}, {"noise"});
  if (args.help()) {
    std::fputs(kHelp, stdout);
    return kExitOk;
  }
  args.expect_positional(1, "one plan file PLAN");
  const std::string& path = args.positional()[0];
  const std::string out = args.required("out");
  const double rate = plan_rate(args);
  const std::string inputs[] = {path};
  refuse_overwriting_input("glove plan", out, inputs);

  std::shared_ptr<const interaction::GloveSource> source =
      std::make_shared<interaction::SimulatedGlove>(
          input_step([&] { return interaction::read_plan(std::filesystem::path(path)); }));
  if (args.flag("noise")) {
    interaction::GloveNoise noise;
    noise.seed = args.unsigned_integer("seed").value_or(1);
    source = std::make_shared<interaction::NoisyGlove>(source, noise);
  } else if (args.value("seed")) {
    throw UsageError("glove plan: --seed needs --noise");
  }
  const std::vector<GloveSample> samples = sample_plan(*source, rate, path);
  input_step([&] {
    interaction::write_trace(out, samples);
    return 0;
  });
  print_summary("plan", samples, out);
  return kExitOk;
}

int check(std::span<const std::string> argv) {
  const Args args("glove check", argv, {}, {});
  if (args.help()) {
    std::fputs(kHelp, stdout);
    return kExitOk;
  }
  args.expect_positional(1, "one trace file TRACE");
  const std::string& path = args.positional()[0];
  const auto samples =
      input_step([&] { return interaction::read_trace(std::filesystem::path(path)); });
  for (const interaction::JointExcursion& e :
       interaction::joints_outside(samples, interaction::kFarOutsideRange)) {
    std::fprintf(stderr, "warning: %s: %s: is it in other units, or a column misnamed?\n",
                 path.c_str(), interaction::describe(e).c_str());
  }
  for (const std::string& doubt : interaction::trace_doubts(path, samples)) {
    std::fprintf(stderr, "warning: %s: %s\n", path.c_str(), doubt.c_str());
  }
  // What a run would say of the trace in any scene: a start on a device
  // clock, and a tracker far from any bench (positions in millimetres).
  if (const double start = samples.front().t; start > 1) {
    std::fprintf(stderr,
                 "warning: %s: it starts at t=%.6g s; a run replays from t = 0 and the hand "
                 "stays at its first sample until then (shift its times to start at 0)\n",
                 path.c_str(), start);
  } else if (start < 0) {
    std::fprintf(stderr,
                 "warning: %s: it starts at t=%.6g s; a run starts at t = 0, so what it holds "
                 "before then is not used\n",
                 path.c_str(), start);
  }
  constexpr double kFar = 20;  // metres: no workspace a tracker covers
  for (const interaction::GloveSample& g : samples) {
    if (g.p_WH.norm() > kFar) {
      std::fprintf(stderr,
                   "warning: %s: the tracker is %.6g m from the origin at t=%.6g s, where a "
                   "tracked workspace is a few metres: are its positions in millimetres? A "
                   "trace is in metres\n",
                   path.c_str(), g.p_WH.norm(), g.t);
      break;
    }
  }
  print_summary("check", samples, "");
  return kExitOk;
}

}  // namespace

int glove_command(std::span<const std::string> argv) {
  if (argv.empty()) throw UsageError("glove: expected an action: convert, plan or check");
  const std::string& action = argv[0];
  if (action == "--help" || action == "-h") {
    std::fputs(kHelp, stdout);
    return kExitOk;
  }
  const auto rest = argv.subspan(1);
  if (action == "convert") return convert(rest);
  if (action == "plan") return plan(rest);
  if (action == "check") return check(rest);
  throw UsageError("glove: unknown action '" + action + "' (convert, plan, check)");
}

}  // namespace dovetail::cli
