#pragma once
/// \file cli.h
/// What every `dovetail` command shares: argument parsing, the two kinds of
/// failure (usage, input) with their exit codes, timing, JSON output, and
/// loading meshes and models.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "dovetail/collision/broadphase.h"
#include "dovetail/collision/model.h"
#include "dovetail/engine/json.h"
#include "dovetail/engine/mesh_import.h"

namespace dovetail::cli {

/// Exit codes of the command line.
inline constexpr int kExitOk = 0;
inline constexpr int kExitInputError = 1;   ///< bad input file, unwritable output, I/O failure
inline constexpr int kExitUsage = 2;        ///< unknown command or option, missing argument
inline constexpr int kExitCheckFailed = 3;  ///< a self-check failed (`run`: methods disagree)

/// The command line was wrong; exit code 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An input could not be used or an output not written; exit code 1.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Parsed arguments of one command: positionals in order, `--name value` (or
/// `--name=value`) options and `--flag` switches. Only names the command
/// declares are accepted.
class Args {
 public:
  /// `value_options` take a value, `flags` do not. `--help`/`-h` is always known.
  Args(std::string command, std::span<const std::string> argv, std::set<std::string> value_options,
       std::set<std::string> flags);

  bool help() const { return help_; }
  const std::vector<std::string>& positional() const { return positional_; }
  bool flag(const std::string& name) const { return flags_set_.count(name) != 0; }
  std::optional<std::string> value(const std::string& name) const;

  /// Requires exactly `count` positional arguments named by `what` for messages.
  void expect_positional(std::size_t count, std::string_view what) const;
  /// The value of a required option; UsageError when absent.
  std::string required(const std::string& name) const;

  /// Option parsers; UsageError naming the option when malformed.
  std::optional<std::int64_t> integer(const std::string& name, std::int64_t min,
                                      std::int64_t max) const;
  std::optional<std::uint64_t> unsigned_integer(const std::string& name) const;
  std::optional<std::vector<double>> number_list(const std::string& name) const;
  /// A finite decimal number >= `min` (optional sign and exponent).
  std::optional<double> number(const std::string& name, double min) const;
  /// --method, default `fallback`; UsageError listing the valid names.
  collision::Method method(collision::Method fallback) const;

  const std::string& command() const { return command_; }

 private:
  std::string command_;
  bool help_ = false;
  std::vector<std::string> positional_;
  std::map<std::string, std::string> values_;
  std::set<std::string> flags_set_;
};

/// UsageError when `output` names the same file as one of `inputs`: writing
/// it would destroy an input before it is read.
void refuse_overwriting_input(const std::string& command, const std::string& output,
                              std::span<const std::string> inputs);

/// InputError unless `path` can be written: not a folder, in a folder that
/// exists (a missing one is made) and, when the file exists, open for
/// writing. Creates and truncates no file, so that a command can check its
/// outputs before any work and still leave an existing file as it was when
/// the run fails on its inputs.
void check_writable(const std::string& path);

/// --gaps of the contact-distance poses: fractions of the larger bounding-box
/// diagonal, each in [-1000, 1000] (farther poses are not contact poses, and
/// far enough ones overflow); UsageError otherwise.
std::optional<std::vector<double>> contact_gaps(const Args& args);

/// "boxtree, dop6, ..., brute".
std::string method_list();
/// The broad phases' names, "brute, sap, ...".
std::string broadphase_list();

/// Milliseconds since `start`.
double ms_since(std::chrono::steady_clock::time_point start);
/// Milliseconds rounded to the microsecond, for summaries.
double round_ms(double ms);
/// The median; NaN for none.
double median(std::vector<double> values);

/// A mesh imported merged, with the import's findings.
struct LoadedMesh {
  std::shared_ptr<const collision::Mesh> mesh;
  engine::ImportReport report;  ///< parts emptied; validation and notes kept
  collision::MeshValidation validation;
};
/// Imports `path` merged; engine::ImportError becomes InputError.
LoadedMesh load_mesh(const std::string& path);

/// A built model and how long the build took.
struct BuiltModel {
  std::shared_ptr<const collision::CollisionModel> model;
  double build_ms = 0;
};
BuiltModel build_timed(collision::Method method, std::shared_ptr<const collision::Mesh> mesh);

/// The `*.lua` entries directly in `folder` (not its subfolders) that are not
/// folders, in file-name order: a link to a missing file is listed, so that
/// running it names the problem. None when `folder` is not a folder;
/// InputError naming it when it exists and cannot be read.
std::vector<std::filesystem::path> scenario_files(const std::filesystem::path& folder);

/// Creates `folder` and its parents when missing; InputError naming it when
/// it cannot be made.
void make_folder(const std::filesystem::path& folder);

/// True when stderr is a terminal (progress is shown only then).
bool stderr_is_terminal();

/// A one-line JSON object built key by key, in insertion order.
class JsonLine {
 public:
  JsonLine& add(std::string_view key, std::string_view text);
  JsonLine& add(std::string_view key, const char* text) { return add(key, std::string_view(text)); }
  JsonLine& add(std::string_view key, double number);
  JsonLine& add(std::string_view key, std::uint64_t number);
  JsonLine& add(std::string_view key, std::int64_t number);
  JsonLine& add(std::string_view key, int number) { return add(key, std::int64_t{number}); }
  JsonLine& add(std::string_view key, bool value);
  /// A value that is already JSON (an array or object).
  JsonLine& add_raw(std::string_view key, std::string_view json);
  /// Every key of `other`, in its order, after the keys so far.
  JsonLine& add_all(const JsonLine& other);
  std::string str() const { return "{" + body_ + "}"; }

 private:
  void key(std::string_view k);
  std::string body_;
};

using engine::json_string;
/// `[item,item,...]` from items that are already JSON.
std::string json_array(const std::vector<std::string>& items);
using engine::json_number;

}  // namespace dovetail::cli
