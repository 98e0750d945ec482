#include "cli.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <utility>

#include "dovetail/engine/paths.h"
#include "dovetail/scripting/vocabulary.h"

namespace dovetail::cli {

namespace {

std::string see_help(const std::string& command) {
  return " (see 'dovetail " + command + " --help')";
}

/// " (did you mean '--report'? see 'dovetail run --help')" for a misspelt
/// option: one the typed name begins (--baseline-tol), else one within a
/// few edits of it; none for a one-letter option (-o is no -j).
std::string option_hint(const std::string& command, const std::string& option,
                        const std::set<std::string>& value_options,
                        const std::set<std::string>& flags) {
  const std::string typed = option.substr(option.find_first_not_of('-'));
  std::vector<std::string> known;
  for (const std::set<std::string>* names : {&value_options, &flags}) {
    known.insert(known.end(), names->begin(), names->end());
  }
  known.emplace_back("help");
  std::string guess;
  if (typed.size() >= 3) {
    for (const std::string& name : known) {
      if (name.starts_with(typed) && (guess.empty() || name.size() < guess.size())) guess = name;
    }
  }
  if (guess.empty() && typed.size() >= 2) {
    guess = scripting::nearest_name(typed, known).value_or("");
  }
  if (guess.empty()) return see_help(command);
  return " (did you mean '" + std::string(guess.size() == 1 ? "-" : "--") + guess +
         "'? see 'dovetail " + command + " --help')";
}

}  // namespace

Args::Args(std::string command, std::span<const std::string> argv,
           std::set<std::string> value_options, std::set<std::string> flags)
    : command_(std::move(command)) {
  bool only_positional = false;
  for (std::size_t i = 0; i < argv.size(); ++i) {
    const std::string& arg = argv[i];
    if (only_positional || arg.size() < 2 || arg[0] != '-') {
      positional_.push_back(arg);
      continue;
    }
    if (arg == "--") {
      only_positional = true;
      continue;
    }
    if (arg == "--help" || arg == "-h") {
      help_ = true;
      continue;
    }
    // One-letter options the command declares may be written -j as well as
    // --j, and one that takes a value with the value joined on: -j2, as make's.
    const bool short_option =
        arg.size() == 2 && arg[1] != '-' &&
        (value_options.count(arg.substr(1)) != 0 || flags.count(arg.substr(1)) != 0);
    const bool short_joined = arg.size() > 2 && arg[1] != '-' &&
                              value_options.count(arg.substr(1, 1)) != 0 && arg[2] != '=';
    if (arg.rfind("--", 0) != 0 && !short_option && !short_joined) {
      throw UsageError(command_ + ": unknown option '" + arg + "'" +
                       option_hint(command_, arg, value_options, flags));
    }
    std::string name =
        short_joined ? arg.substr(1, 1) + "=" + arg.substr(2) : arg.substr(short_option ? 1 : 2);
    // The option as a message names it: -j for one letter, --name otherwise.
    const auto spelled = [](const std::string& n) { return (n.size() == 1 ? "-" : "--") + n; };
    std::optional<std::string> inline_value;
    if (const std::size_t eq = name.find('='); eq != std::string::npos) {
      inline_value = name.substr(eq + 1);
      name.resize(eq);
    }
    if (flags.count(name) != 0) {
      if (inline_value) {
        throw UsageError(command_ + ": option '" + spelled(name) + "' takes no value");
      }
      flags_set_.insert(name);
    } else if (value_options.count(name) != 0) {
      if (!inline_value) {
        if (i + 1 >= argv.size()) {
          throw UsageError(command_ + ": option '" + spelled(name) + "' needs a value" +
                           see_help(command_));
        }
        inline_value = argv[++i];
      }
      if (values_.count(name) != 0) {
        throw UsageError(command_ + ": option '" + spelled(name) + "' given twice");
      }
      values_[name] = *inline_value;
    } else {
      throw UsageError(command_ + ": unknown option '--" + name + "'" +
                       option_hint(command_, "--" + name, value_options, flags));
    }
  }
}

std::optional<std::string> Args::value(const std::string& name) const {
  const auto it = values_.find(name);
  if (it == values_.end()) return std::nullopt;
  return it->second;
}

void Args::expect_positional(std::size_t count, std::string_view what) const {
  if (positional_.size() != count) {
    throw UsageError(command_ + ": expected " + std::string(what) + ", got " +
                     std::to_string(positional_.size()) + " argument" +
                     (positional_.size() == 1 ? "" : "s") + see_help(command_));
  }
}

std::string Args::required(const std::string& name) const {
  std::optional<std::string> v = value(name);
  if (!v) throw UsageError(command_ + ": missing --" + name + see_help(command_));
  return *v;
}

std::optional<std::int64_t> Args::integer(const std::string& name, std::int64_t min,
                                          std::int64_t max) const {
  const std::optional<std::string> text = value(name);
  if (!text) return std::nullopt;
  std::int64_t v = 0;
  const auto [ptr, ec] = std::from_chars(text->data(), text->data() + text->size(), v);
  if (ec != std::errc() || ptr != text->data() + text->size() || v < min || v > max) {
    throw UsageError(command_ + ": " + (name.size() == 1 ? "-" : "--") + name +
                     " must be an integer from " + std::to_string(min) + " to " +
                     std::to_string(max) + ", not '" + *text + "'");
  }
  return v;
}

std::optional<std::uint64_t> Args::unsigned_integer(const std::string& name) const {
  const std::optional<std::string> text = value(name);
  if (!text) return std::nullopt;
  std::uint64_t v = 0;
  const auto [ptr, ec] = std::from_chars(text->data(), text->data() + text->size(), v);
  if (ec != std::errc() || ptr != text->data() + text->size()) {
    throw UsageError(command_ + ": --" + name + " must be a non-negative integer, not '" + *text +
                     "'");
  }
  return v;
}

std::optional<std::vector<double>> Args::number_list(const std::string& name) const {
  const std::optional<std::string> text = value(name);
  if (!text) return std::nullopt;
  std::vector<double> numbers;
  std::size_t start = 0;
  while (start <= text->size()) {
    std::size_t end = text->find(',', start);
    if (end == std::string::npos) end = text->size();
    const std::string item = text->substr(start, end - start);
    const char* first = item.data();
    if (!item.empty() && item[0] == '+') ++first;
    double v = 0;
    const auto [ptr, ec] = std::from_chars(first, item.data() + item.size(), v);
    if (item.empty() || ec != std::errc() || ptr != item.data() + item.size() ||
        !std::isfinite(v)) {
      throw UsageError(command_ + ": --" + name +
                       " must be a comma-separated list of finite numbers; '" + item +
                       "' is not one");
    }
    numbers.push_back(v);
    start = end + 1;
  }
  return numbers;
}

std::optional<double> Args::number(const std::string& name, double min) const {
  const std::optional<std::string> text = value(name);
  if (!text) return std::nullopt;
  const char* first = text->data();
  if (!text->empty() && (*text)[0] == '+') ++first;
  double v = 0;
  const auto [ptr, ec] = std::from_chars(first, text->data() + text->size(), v);
  if (text->empty() || ec != std::errc() || ptr != text->data() + text->size() ||
      !std::isfinite(v) || v < min) {
    char bound[32];
    std::snprintf(bound, sizeof bound, "%g", min);
    throw UsageError(command_ + ": --" + name + " must be a finite number >= " + bound + ", not '" +
                     *text + "'");
  }
  return v == 0 ? 0.0 : v;  // -0 reads as 0
}

collision::Method Args::method(collision::Method fallback) const {
  const std::optional<std::string> name = value("method");
  if (!name) return fallback;
  const std::optional<collision::Method> m = collision::parse_method(*name);
  if (!m) {
    throw UsageError(command_ + ": unknown method '" + *name +
                     "'; valid methods: " + method_list());
  }
  return *m;
}

void refuse_overwriting_input(const std::string& command, const std::string& output,
                              std::span<const std::string> inputs) {
  for (const std::string& input : inputs) {
    if (engine::same_file(output, input)) {
      throw UsageError(command + ": the output '" + output + "' is the input '" + input +
                       "'; it would be overwritten");
    }
  }
}

std::optional<std::vector<double>> contact_gaps(const Args& args) {
  std::optional<std::vector<double>> gaps = args.number_list("gaps");
  for (const double g : gaps.value_or(std::vector<double>{})) {
    if (!(std::abs(g) <= 1000)) {
      char text[32];
      std::snprintf(text, sizeof text, "%g", g);
      throw UsageError(args.command() + ": --gaps must be between -1000 and 1000 (fractions of " +
                       "the larger bounding-box diagonal), not " + text);
    }
  }
  return gaps;
}

void check_writable(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (path.empty()) throw InputError("'': cannot be written: the path is empty");
  if (fs::is_directory(path, ec)) throw InputError(path + ": cannot be written: is a directory");
  if (fs::exists(path, ec)) {
    if (fs::is_regular_file(path, ec)) {
      // Appending opens the file for writing without changing it.
      std::ofstream probe(path, std::ios::binary | std::ios::app);
      if (!probe) throw InputError(path + ": cannot be written: " + std::strerror(errno));
    } else if (::access(path.c_str(), W_OK) != 0) {
      // A pipe or a device is not opened twice: a reader would see the end.
      throw InputError(path + ": cannot be written: " + std::strerror(errno));
    }
    return;
  }
  // A missing folder is made, as --out and --render make theirs: an output
  // into reports/junit.xml works on a fresh CI runner.
  const fs::path folder = fs::path(path).parent_path();
  if (!folder.empty() && !fs::is_directory(folder, ec)) {
    fs::create_directories(folder, ec);
    if (ec || !fs::is_directory(folder)) {
      throw InputError(path + ": cannot be written: the folder " + folder.string() +
                       " cannot be made: " + (ec ? ec.message() : "a file is in the way"));
    }
  }
  if (::access(folder.empty() ? "." : folder.c_str(), W_OK) != 0) {
    throw InputError(path + ": cannot be written: " + std::strerror(errno));
  }
}

namespace {

/// The names of `all` joined by ", ".
template <typename All, typename Name>
std::string join_names(const All& all, Name name) {
  std::string list;
  for (const auto m : all) {
    if (!list.empty()) list += ", ";
    list += name(m);
  }
  return list;
}

}  // namespace

std::string method_list() { return join_names(collision::all_methods(), collision::method_name); }

std::string broadphase_list() {
  return join_names(collision::all_broadphases(), collision::broadphase_name);
}

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

double round_ms(double ms) { return std::round(ms * 1000.0) / 1000.0; }

double median(std::vector<double> values) {
  if (values.empty()) return std::nan("");
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

LoadedMesh load_mesh(const std::string& path) {
  try {
    engine::ImportReport report = engine::import_file(path, {});
    LoadedMesh loaded;
    loaded.validation = report.parts.front().validation;
    loaded.mesh = std::make_shared<const collision::Mesh>(std::move(report.parts.front().mesh));
    report.parts.clear();
    loaded.report = std::move(report);
    return loaded;
  } catch (const collision::MeshError& e) {
    throw InputError(e.what());
  }
}

BuiltModel build_timed(collision::Method method, std::shared_ptr<const collision::Mesh> mesh) {
  const auto start = std::chrono::steady_clock::now();
  BuiltModel built;
  built.model = collision::build_model(method, std::move(mesh));
  built.build_ms = ms_since(start);
  return built;
}

std::vector<std::filesystem::path> scenario_files(const std::filesystem::path& folder) {
  std::vector<std::filesystem::path> files;
  std::error_code ec;
  for (auto it = std::filesystem::directory_iterator(folder, ec);
       !ec && it != std::filesystem::directory_iterator(); it.increment(ec)) {
    std::error_code kind;
    if (it->path().extension() == ".lua" && !it->is_directory(kind)) files.push_back(it->path());
  }
  if (ec && ec != std::errc::no_such_file_or_directory && ec != std::errc::not_a_directory) {
    throw InputError(folder.string() + ": cannot be read: " + ec.message());
  }
  std::sort(files.begin(), files.end());
  return files;
}

void make_folder(const std::filesystem::path& folder) {
  if (folder.empty()) throw UsageError("an output folder must be named: the path is empty");
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (!std::filesystem::is_directory(folder, ec)) {
    throw InputError(folder.string() + ": cannot create the folder");
  }
}

bool stderr_is_terminal() { return isatty(STDERR_FILENO) != 0; }

std::string json_array(const std::vector<std::string>& items) {
  std::string out(1, '[');
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i > 0) out += ',';
    out += items[i];
  }
  out += ']';
  return out;
}

void JsonLine::key(std::string_view k) {
  if (!body_.empty()) body_ += ",";
  body_ += json_string(k) + ":";
}

JsonLine& JsonLine::add(std::string_view k, std::string_view text) {
  key(k);
  body_ += json_string(text);
  return *this;
}

JsonLine& JsonLine::add(std::string_view k, double number) {
  key(k);
  body_ += json_number(number);
  return *this;
}

JsonLine& JsonLine::add(std::string_view k, std::uint64_t number) {
  key(k);
  body_ += std::to_string(number);
  return *this;
}

JsonLine& JsonLine::add(std::string_view k, std::int64_t number) {
  key(k);
  body_ += std::to_string(number);
  return *this;
}

JsonLine& JsonLine::add(std::string_view k, bool value) {
  key(k);
  body_ += value ? "true" : "false";
  return *this;
}

JsonLine& JsonLine::add_raw(std::string_view k, std::string_view json) {
  key(k);
  body_ += json;
  return *this;
}

JsonLine& JsonLine::add_all(const JsonLine& other) {
  if (!body_.empty() && !other.body_.empty()) body_ += ",";
  body_ += other.body_;
  return *this;
}

}  // namespace dovetail::cli
