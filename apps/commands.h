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
/// `dovetail run`: the built-in default job (every method against brute force).
int run_command(std::span<const std::string> args);
/// `dovetail broadphase --boxes FILE ...`: overlapping box pairs, frame by frame.
int broadphase_command(std::span<const std::string> args);
/// `dovetail render INPUT --out PNG ...`: draws a mesh or assembly file to PNG.
int render_command(std::span<const std::string> args);
/// `dovetail glove convert|plan|check ...`: glove traces from recordings and plans.
int glove_command(std::span<const std::string> args);

}  // namespace dovetail::cli
