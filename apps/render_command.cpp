#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "cli.h"
#include "commands.h"
#include "dovetail/engine/mesh_import.h"
#include "dovetail/engine/render.h"
#include "dovetail/engine/scene.h"
#include "dovetail/engine/scene_render.h"
#include "dovetail/interaction/glove_plan.h"
#include "dovetail/interaction/glove_source.h"
#include "dovetail/interaction/glove_trace.h"
#include "dovetail/interaction/hand.h"
#include "dovetail/scripting/scenario_run.h"

namespace dovetail::cli {

namespace {

constexpr const char* kHelp =
    R"(usage: dovetail render INPUT --out PNG [--width W] [--height H] [--camera NAME|auto]
                       [--trace TRACE | --plan PLAN] [--time T] [--hand-size S]
                       [--hand-length M] [--units mm|cm|m] [--quiet]
       dovetail render SCENARIO.lua --out PNG [--time T] [--trace TRACE]
                       [--width W] [--height H] [--camera NAME|scenario|auto] [--quiet]

Draws a mesh or assembly file, or a scenario's frame, off-screen and writes
the picture as PNG.

  INPUT          a mesh or assembly file (OBJ, STL, PLY, glTF or GLB);
                 every mesh instance becomes a part with its own palette colour
  SCENARIO.lua   a scenario: it runs headless up to the first frame at or after
                 --time (default 0) and that frame is drawn, the hand and the
                 rules' highlights included, as 'dovetail run --render' draws
                 it; --trace replays a glove trace, as 'dovetail replay' does.
                 The camera is the scenario's (--camera scenario) when it
                 declares one, else auto, fitted to that frame; or a view
  --out PNG      the image to write
  --width W      image width in pixels, 1 to 16384 (default 1024)
  --height H     image height in pixels, 1 to 16384 (default 768)
  --camera NAME  a camera of the file (glTF cameras are named after their node, e.g.
                 nodes[81]; `dovetail inspect` lists them), a built-in view (front,
                 back, right, left, top, bottom, iso: the whole scene in view along
                 that axis, y up), or auto (default, the same as iso)
  --trace TRACE  also draw the hand, as a glove trace (docs/cli.md) has it at
                 time --time (seconds, default 0, interpolated between samples); the
                 input is then loaded as an assembly in metres, like a simulation
  --plan PLAN    the same with a simulated-glove plan (docs/interaction.md)
  --hand-size S  adult_m50 (default), adult_f50, adult_m95, adult_f05
  --hand-length M  scale the size to this hand length in metres (0: its own)
  --units U      with a hand: the unit of INPUT's numbers, mm, cm or m (default:
                 millimetres when its box is more than 100 across, else metres)
  --quiet        no summary on standard output

Flat shading with a light at the camera, depth-tested, no anti-aliasing; the
same input and options give the same PNG bytes. Prints a one-line JSON summary
on standard output (unless --quiet).
)";

/// The parts of a mesh or assembly file, in file units; `files` gets every
/// file read.
engine::RenderScene scene_of_file(const std::string& input, std::uint64_t& triangles,
                                  std::vector<std::string>& files) {
  engine::ImportReport report;
  try {
    engine::ImportOptions options;
    options.merge = false;
    report = engine::import_file(input, options);
  } catch (const collision::MeshError& e) {
    throw InputError(e.what());
  }
  for (const std::string& note : report.notes) {
    std::fprintf(stderr, "dovetail: note: %s: %s\n", input.c_str(), note.c_str());
  }
  for (const engine::ImportedPart& part : report.parts) triangles += part.mesh.triangle_count();
  files = report.files;
  return engine::scene_from_import(report);
}

/// The assembly in metres with the hand of a trace or plan at --time.
engine::RenderScene scene_with_hand(const Args& args, const std::string& input,
                                    const std::optional<std::string>& trace,
                                    const std::optional<std::string>& plan,
                                    std::uint64_t& triangles, std::vector<std::string>& files) {
  const double time = args.number("time", 0).value_or(0);
  interaction::HandDef hand_def;
  hand_def.size = args.value("hand-size").value_or("adult_m50");
  hand_def.hand_length = args.number("hand-length", 0).value_or(0);
  std::unique_ptr<interaction::HandModel> model;
  try {
    model = std::make_unique<interaction::HandModel>(hand_def);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("render: ") + e.what());
  }
  std::unique_ptr<interaction::GloveSource> source;
  try {
    if (trace) {
      source = std::make_unique<interaction::TraceSource>(interaction::read_trace(*trace));
    } else {
      source = std::make_unique<interaction::SimulatedGlove>(interaction::read_plan(*plan));
    }
  } catch (const interaction::TraceError& e) {
    throw InputError(e.what());
  } catch (const interaction::PlanError& e) {
    throw InputError(e.what());
  }
  engine::AssemblyOptions options;
  if (const std::optional<std::string> units = args.value("units")) {
    const std::optional<double> metres = engine::metres_per_unit(*units);
    if (!metres) throw UsageError("render: --units must be mm, cm or m, not '" + *units + "'");
    options.units = *metres;
  }
  engine::AssemblyReport assembly;
  engine::Scene parts;
  try {
    parts = engine::load_assembly(input, options, &assembly);
  } catch (const collision::MeshError& e) {
    throw InputError(e.what());
  }
  for (const std::string& note : assembly.notes) {
    // The hand is drawn in metres: a part read in the wrong unit is 1000
    // times too small or too large beside it.
    const bool units = note.rfind("units inferred", 0) == 0;
    std::fprintf(stderr, "dovetail: note: %s: %s%s\n", input.c_str(), note.c_str(),
                 units ? " (--units mm, cm or m says which)" : "");
  }
  triangles = assembly.triangles;
  files = assembly.files;
  engine::RenderScene scene = engine::render_scene(parts);
  for (engine::RenderItem& item : interaction::hand_render_items(*model, source->sample(time))) {
    triangles += item.mesh->triangle_count();
    scene.items.push_back(std::move(item));
  }
  return scene;
}

/// Whether INPUT names a scenario: a `.lua` file.
bool is_scenario_file(const std::string& input) {
  return std::filesystem::path(input).extension() == ".lua";
}

/// The scene of a scenario's frame at --time, run headless as `dovetail
/// run` runs it (with --trace as `replay`); `camera` becomes the scenario's
/// own when it has one and none was asked for.
scripting::RunOutcome::Picture scenario_picture(const Args& args, const std::string& input,
                                                const std::string& out, std::string& camera) {
  for (const char* option : {"plan", "hand-size", "hand-length", "units"}) {
    if (args.value(option)) {
      throw UsageError(std::string("render: --") + option +
                       " does not go with a scenario: its hand, glove and units are its own");
    }
  }
  scripting::RunOptions options;
  if (auto v = args.value("trace")) options.trace = *v;
  options.picture_at = args.number("time", 0).value_or(0);
  options.progress = stderr_is_terminal();
  options.outputs.emplace_back(out);  // never a file the scenario reads
  const scripting::RunOutcome outcome = scripting::run_scenario(input, options);
  for (const std::string& w : outcome.warnings) {
    std::fprintf(stderr, "warning: %s\n", engine::escape_control_bytes(w).c_str());
  }
  if (!outcome.picture) throw InputError(outcome.error);
  if (camera.empty()) {
    camera = engine::has_camera(outcome.picture->scene, scripting::kScenarioCamera)
                 ? scripting::kScenarioCamera
                 : "auto";
  }
  return *outcome.picture;
}

/// UsageError naming the scene's cameras and the built-in views when
/// `camera` is neither.
void check_camera(const engine::RenderScene& scene, const std::string& camera,
                  const std::string& input) {
  if (engine::has_camera(scene, camera)) return;
  std::string known;
  for (const auto& entry : scene.cameras) known += (known.empty() ? "" : ", ") + entry.first;
  std::string views;
  for (const std::string& v : engine::builtin_views()) views += (views.empty() ? "" : ", ") + v;
  throw UsageError("render: no camera named '" + camera + "' in " + input +
                   " (its cameras: " + (known.empty() ? std::string("none") : known) +
                   "; views: " + views + "; or auto)");
}

/// Renders and writes the PNG; the rendering's ms. InputError on failure.
double render_to_png(const engine::RenderScene& scene, const engine::RenderSettings& settings,
                     const std::string& input, const std::string& out) {
  const auto start = std::chrono::steady_clock::now();
  engine::Image image;
  try {
    image = engine::render(scene, settings);
  } catch (const engine::RenderError& e) {
    throw InputError(input + ": " + e.what());
  }
  const double render_ms = ms_since(start);
  try {
    engine::write_png(image, out);
  } catch (const engine::RenderError& e) {
    throw InputError(e.what());
  }
  return render_ms;
}

/// --width, --height and --camera.
engine::RenderSettings render_settings(const Args& args) {
  engine::RenderSettings settings;
  settings.width = static_cast<int>(args.integer("width", 1, engine::kMaxImageSize).value_or(1024));
  settings.height =
      static_cast<int>(args.integer("height", 1, engine::kMaxImageSize).value_or(768));
  settings.camera = args.value("camera").value_or("auto");
  if (settings.camera.empty()) throw UsageError("render: --camera must name a camera or be 'auto'");
  return settings;
}

}  // namespace

int render_command(std::span<const std::string> argv) {
  const Args args("render", argv,
                  {"out", "width", "height", "camera", "trace", "plan", "time", "hand-size",
                   "hand-length", "units"},
                  {"quiet"});
  if (args.help()) {
    std::fputs(kHelp, stdout);
    return kExitOk;
  }
  args.expect_positional(1, "one mesh or assembly file, or a scenario, INPUT");
  const std::string& input = args.positional()[0];
  const std::string out = args.required("out");
  engine::RenderSettings settings = render_settings(args);
  const std::optional<std::string> trace = args.value("trace");
  const std::optional<std::string> plan = args.value("plan");
  if (trace && plan) throw UsageError("render: give --trace or --plan, not both");
  std::vector<std::string> inputs = {input};
  if (trace || plan) inputs.push_back(trace ? *trace : *plan);
  refuse_overwriting_input("render", out, inputs);
  check_writable(out);

  const bool scenario = is_scenario_file(input);
  bool with_hand = trace || plan;
  if (!with_hand && !scenario) {
    for (const char* option : {"time", "hand-size", "hand-length", "units"}) {
      if (args.value(option)) {
        throw UsageError(std::string("render: --") + option + " needs --trace or --plan");
      }
    }
  }
  std::uint64_t triangles = 0;
  std::vector<std::string> files;
  std::optional<scripting::RunOutcome::Picture> frame;
  engine::RenderScene scene;
  if (scenario) {
    if (!args.value("camera")) settings.camera.clear();  // the scenario's, if it has one
    frame = scenario_picture(args, input, out, settings.camera);
    scene = std::move(frame->scene);
    with_hand = frame->hand;
    for (const engine::RenderItem& item : scene.items) triangles += item.mesh->triangle_count();
  } else {
    scene = with_hand ? scene_with_hand(args, input, trace, plan, triangles, files)
                      : scene_of_file(input, triangles, files);
    refuse_overwriting_input("render", out, files);  // nor a file the input refers to
  }

  check_camera(scene, settings.camera, input);
  // A drawing that fails with a hand may be the hand's doing (a trace that
  // puts it far away): both inputs are named.
  const double render_ms = render_to_png(
      scene, settings,
      with_hand && !scenario ? input + " with the hand of " + (trace ? *trace : *plan) : input,
      out);

  JsonLine json;
  json.add("input", input).add("out", out);
  if (frame) json.add("time", frame->time).add("frame", frame->frame);
  json.add("width", settings.width)
      .add("height", settings.height)
      .add("camera", settings.camera)
      .add("parts", std::uint64_t{scene.items.size()})
      .add("hand", with_hand)
      .add("triangles", triangles)
      .add("render_ms", std::round(render_ms * 1000.0) / 1000.0);
  if (!args.flag("quiet")) std::fputs((json.str() + "\n").c_str(), stdout);
  return kExitOk;
}

}  // namespace dovetail::cli
