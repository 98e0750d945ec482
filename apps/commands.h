#pragma once
/// \file commands.h
/// The `dovetail` commands. Each takes the arguments after its name, writes
/// its results to stdout, and returns the exit code; failures are thrown as
/// cli::UsageError or cli::InputError and reported by main.

#include <span>
#include <string>

namespace dovetail::cli {

/// `dovetail query A B --poses FILE ...`: collision flags for a pose list.
int query_command(std::span<const std::string> args);
/// `dovetail inspect MESH ...`: mesh statistics and per-method hierarchy sizes.
int inspect_command(std::span<const std::string> args);
/// `dovetail poses A B --out FILE ...`: writes a contact-distance pose list.
int poses_command(std::span<const std::string> args);
/// `dovetail bench`: every collision method against brute force on a peg and a ring.
int bench_command(std::span<const std::string> args);
/// `dovetail run [SCENARIO] ...`: runs a Lua scenario headless (the first shipped one by default).
int run_command(std::span<const std::string> args);
/// `dovetail replay SCENARIO TRACE ...`: run with a recorded glove trace.
int replay_command(std::span<const std::string> args);
/// `dovetail check SCENARIO`: loads and resolves a scenario without simulating.
int check_command(std::span<const std::string> args);
/// `dovetail new NAME`: writes a commented starting scenario.
int new_command(std::span<const std::string> args);
/// `dovetail regress DIR ...`: every scenario of a folder, each in its own process.
int regress_command(std::span<const std::string> args);
/// `dovetail reference`: the scenario vocabulary as Markdown.
int reference_command(std::span<const std::string> args);
/// `dovetail broadphase --boxes FILE ...`: overlapping box pairs, frame by frame.
int broadphase_command(std::span<const std::string> args);
/// `dovetail render INPUT --out PNG ...`: draws a mesh or assembly file to PNG.
int render_command(std::span<const std::string> args);
/// `dovetail pipeline --scene FILE ...`: the whole collision pipeline on a scene from files.
int pipeline_command(std::span<const std::string> args);
/// `dovetail capture FILE...`: replays failure-capture files.
int capture_command(std::span<const std::string> args);
/// `dovetail glove convert|plan|check ...`: glove traces from recordings and plans.
int glove_command(std::span<const std::string> args);

}  // namespace dovetail::cli
