/// \file regress_command.cpp
/// `dovetail regress DIR`: every scenario of a folder, each in its own
/// process (`dovetail run`), so a failing or hostile scenario never stops the
/// others; a summary line per scenario, JUnit XML and a self-contained HTML
/// report (expectations, event timeline, the final frame of each).

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "cli.h"
#include "commands.h"
#include "dovetail/engine/json.h"
#include "dovetail/engine/paths.h"
#include "dovetail/scripting/scenario_run.h"
#include "report_diff.h"

extern char** environ;

namespace dovetail::cli {

namespace {

constexpr const char* kHelp =
    R"(usage: dovetail regress DIR [--out OUT] [--junit X.xml] [--html R.html] [-j N]
                        [--shard K/N] [--threads N] [--timeout S]
                        [--baseline B [--baseline-tolerance T]]

Runs every *.lua scenario in DIR (file-name order), each in its own process,
checks its expectations and prints a line per scenario. Exits 0 when all pass,
3 when one fails, cannot run or (with --baseline) changed.

  --out OUT      per-scenario reports, logs and final frames (default regress-out)
  --junit X      JUnit XML, one test case per scenario
  --html R       a self-contained HTML report
  -j N           scenarios run at once (default 1)
  --shard K/N    only the scenarios i (0-based, file-name order) with i % N == K - 1,
                 to spread a folder over N machines
  --threads N    collision worker threads per scenario (default 1)
  --timeout S    seconds before a scenario is stopped (default 900)
  --baseline B   compare every report with B/STEM.json, the OUT of an earlier regress
                 (dovetail regress DIR --out B makes one): a scenario that passes
                 but whose report differs in anything (a step's time, an event, a
                 final pose, the state hash) is CHANGED, and the first difference
                 is its reason
  --baseline-tolerance T
                 numbers a, b of the two reports are alike when |a - b| <= T * max(1,
                 |a|, |b|), and the state hash is not compared (default 0: the reports
                 must be the same bit for bit, as runs of one build are)
)";

/// How many of a scenario's differences from its baseline are kept.
constexpr std::size_t kChangesKept = 50;

struct Job {
  std::filesystem::path file;
  std::string stem;
  pid_t pid = -1;
  std::chrono::steady_clock::time_point start;
  double seconds = 0;
  int exit_code = -1;
  std::string stopped;  ///< why the run was stopped from outside (its timeout, a signal), if it was
  std::string status;   ///< passed, failed, error
  std::string log;      ///< what the run wrote on stderr
  nlohmann::json report;
  /// With --baseline: the first differences from the baseline's report, how
  /// many there are in all, why the baseline's report could not be read,
  /// and whether there was none.
  std::optional<std::filesystem::path> baseline;  ///< BASELINE/STEM.json
  double baseline_tolerance = 0;
  std::vector<ReportChange> changes;
  std::size_t changes_total = 0;
  std::string baseline_error;
  bool without_baseline = false;
  bool compared = false;  ///< both reports read and compared
};

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string xml_escape(const std::string& text) {
  // UTF-8, and without U+FFFE and U+FFFF, which XML 1.0 does not allow either.
  std::string valid = engine::valid_utf8(text);
  for (const std::string_view bad : {"\xEF\xBF\xBE", "\xEF\xBF\xBF"}) {
    for (std::size_t at = valid.find(bad); at != std::string::npos; at = valid.find(bad, at)) {
      valid.replace(at, bad.size(), "\xEF\xBF\xBD");
    }
  }
  std::string out;
  for (const char c : valid) {
    switch (c) {
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '&':
        out += "&amp;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        // XML 1.0 allows no control characters but tab and line ends.
        if (static_cast<unsigned char>(c) >= 0x20 || c == '\n' || c == '\t' || c == '\r') out += c;
    }
  }
  return out;
}

std::string base64(const std::string& bytes) {
  static constexpr char kTable[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::uint32_t b0 = static_cast<unsigned char>(bytes[i]);
    const std::uint32_t b1 = i + 1 < bytes.size() ? static_cast<unsigned char>(bytes[i + 1]) : 0;
    const std::uint32_t b2 = i + 2 < bytes.size() ? static_cast<unsigned char>(bytes[i + 2]) : 0;
    const std::uint32_t n = (b0 << 16) | (b1 << 8) | b2;
    out += kTable[(n >> 18) & 63];
    out += kTable[(n >> 12) & 63];
    out += i + 1 < bytes.size() ? kTable[(n >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kTable[n & 63] : '=';
  }
  return out;
}

std::string format_seconds(double s) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.3f", s);
  return buffer;
}

/// The first difference from the baseline, and how many more there are.
std::string change_reason(const Job& job) {
  if (job.changes.empty()) return {};
  std::string reason = "changed from the baseline: " + job.changes.front().str();
  if (job.changes_total > 1) {
    reason += " (and " + std::to_string(job.changes_total - 1) + " more)";
  }
  return reason;
}

/// The first line of the log that says why, or the status.
std::string first_reason(const Job& job) {
  if (!job.baseline_error.empty()) return job.baseline_error;
  if (job.status == "changed") return change_reason(job);
  std::istringstream lines(job.log);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind("warning: ", 0) == 0 || line.empty()) continue;
    return line;
  }
  return job.stopped.empty() ? job.status : job.stopped;
}

/// Compares the job's report (`report`, in OUT) with its baseline's: CHANGED
/// when the run passed and they differ; an error when the baseline's report
/// is not one. Both are read with their fields in the file's order, so the
/// first difference is the first in the report.
void compare_with_baseline(Job& job, const std::filesystem::path& report) {
  std::error_code ec;
  if (!std::filesystem::exists(*job.baseline, ec)) {
    job.without_baseline = true;
    return;
  }
  using Ordered = nlohmann::ordered_json;
  Ordered was;
  try {
    was = parse_report(read_file(*job.baseline));
  } catch (const std::runtime_error& e) {
    job.baseline_error = job.baseline->string() + ": not a Dovetail scenario report (" + e.what() +
                         "); make it again with regress --out";
    job.status = "error";
    return;
  }
  if (!is_scenario_report(was)) {
    job.baseline_error = job.baseline->string() +
                         ": not a Dovetail scenario report (its \"format\" is not "
                         "\"dovetail-scenario-report\")";
    job.status = "error";
    return;
  }
  if (const auto version = was.find("version");
      version == was.end() ||
      *version != nlohmann::ordered_json(scripting::kScenarioReportVersion)) {
    job.baseline_error = job.baseline->string() + ": a report of version " +
                         (version == was.end() ? std::string("none") : version->dump()) +
                         ", where this Dovetail writes version " +
                         std::to_string(scripting::kScenarioReportVersion) +
                         ": make the baseline again";
    job.status = "error";
    return;
  }
  Ordered now;
  try {
    now = parse_report(read_file(report));
  } catch (const std::runtime_error&) {
    return;  // the run wrote none: its error says why
  }
  if (!is_scenario_report(now)) return;
  job.changes = report_changes(was, now, kChangesKept, job.changes_total, job.baseline_tolerance);
  job.compared = true;
  if (job.changes_total > 0 && job.status == "passed") job.status = "changed";
}

/// Removes what an earlier regress left of `job`'s outputs, so that none of
/// it passes for this run's: the report and the final frame.
void remove_old_outputs(const Job& job, const std::filesystem::path& out) {
  std::error_code ec;
  std::filesystem::remove(out / (job.stem + ".json"), ec);
  std::filesystem::remove(out / job.stem / "final.png", ec);
}

/// The report in the file at `path` when it is a Dovetail scenario report
/// (any other file, JSON or not, too deep or of odd types: nullopt).
std::optional<nlohmann::ordered_json> scenario_report_at(const std::filesystem::path& path) {
  try {
    nlohmann::ordered_json report = parse_report(read_file(path));
    if (is_scenario_report(report)) return report;
  } catch (const std::runtime_error&) {
    // not JSON, or nested deeper than any report
  }
  return std::nullopt;
}

/// "1 scenario", "3 scenarios".
std::string scenarios_counted(std::size_t n) {
  return std::to_string(n) + (n == 1 ? " scenario" : " scenarios");
}

/// The names joined by ", ".
std::string comma_list(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
  return text;
}

/// Removes what an earlier regress of this folder left in `out` of
/// scenarios no longer in it (deleted or renamed since), so that OUT, kept
/// as a CI artifact, holds only the outputs of the scenarios there; returns
/// their names. OUT may hold other files, and other folders' outputs: only
/// a Dovetail report beside its log whose scenario file was in this folder
/// and is gone counts, and of its frames folder (not a link) only the final
/// frame.
std::vector<std::string> remove_stale_outputs(const std::filesystem::path& out,
                                              const std::filesystem::path& folder,
                                              const std::vector<std::filesystem::path>& files) {
  std::set<std::string> stems;
  for (const std::filesystem::path& f : files) stems.insert(f.stem().string());
  std::vector<std::string> removed;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(out, ec)) {
    const std::filesystem::path& report = entry.path();
    const std::string stem = report.stem().string();
    if (report.extension() != ".json" || stems.count(stem) != 0 ||
        !std::filesystem::is_regular_file(report, ec) ||
        !std::filesystem::is_regular_file(out / (stem + ".log"), ec)) {
      continue;
    }
    const std::optional<nlohmann::ordered_json> json = scenario_report_at(report);
    if (!json || !json->contains("file") || !(*json)["file"].is_string()) continue;
    const std::filesystem::path scenario = (*json)["file"].get<std::string>();
    if (std::filesystem::exists(scenario, ec) ||
        !engine::same_file(scenario.parent_path().empty() ? "." : scenario.parent_path(), folder)) {
      continue;
    }
    removed.push_back(stem);
  }
  std::sort(removed.begin(), removed.end());
  for (const std::string& stem : removed) {
    std::filesystem::remove(out / (stem + ".json"), ec);
    std::filesystem::remove(out / (stem + ".log"), ec);
    const std::filesystem::path frames = out / stem;
    if (!std::filesystem::is_symlink(frames, ec)) {
      std::filesystem::remove(frames / "final.png", ec);
      std::filesystem::remove(frames, ec);  // only if nothing else is in it
    }
  }
  return removed;
}

/// Starts the run of `job` with its standard error in OUT/STEM.log; false,
/// with the reason in job.stopped, when it cannot start.
bool start(Job& job, const std::filesystem::path& out, int threads) {
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe");
  const std::filesystem::path folder = out / job.stem;  // `run --render` makes it
  std::vector<std::string> args = {self.string(),
                                   "run",
                                   "--report",
                                   (out / (job.stem + ".json")).string(),
                                   "--render",
                                   folder.string(),
                                   "--threads",
                                   std::to_string(threads),
                                   "--quiet",
                                   "--",  // a file named "-x.lua" is a scenario, not an option
                                   job.file.string()};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  remove_old_outputs(job, out);
  job.start = std::chrono::steady_clock::now();
  const std::string log = (out / (job.stem + ".log")).string();
  const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    job.stopped = "not run: " + log + " cannot be written: " + std::strerror(errno);
    return false;
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, fd, STDERR_FILENO);
  const int rc = posix_spawn(&job.pid, self.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(fd);
  if (rc != 0) {
    job.pid = -1;
    job.stopped = "not run: " + self.string() + " cannot be started: " + std::strerror(rc);
    return false;
  }
  return true;
}

/// Gathers what the run of `job` left, given how its process ended
/// (nothing when it never started).
void finish(Job& job, std::optional<int> wait_status, const std::filesystem::path& out) {
  job.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - job.start).count();
  if (!wait_status) {
    job.exit_code = kExitInputError;
  } else if (WIFEXITED(*wait_status)) {
    job.exit_code = WEXITSTATUS(*wait_status);
  } else {
    job.exit_code = 128 + WTERMSIG(*wait_status);
    if (job.stopped.empty()) {
      job.stopped = "the run ended with signal " + std::to_string(WTERMSIG(*wait_status));
    }
  }
  job.status = job.exit_code == kExitOk            ? "passed"
               : job.exit_code == kExitCheckFailed ? "failed"
                                                   : "error";
  const std::filesystem::path log = out / (job.stem + ".log");
  const std::filesystem::path report = out / (job.stem + ".json");
  std::error_code ec;
  if (!job.stopped.empty()) {
    // The run wrote no report: the log and a report say why it stopped.
    std::ofstream(log, std::ios::binary | std::ios::app) << job.stopped << "\n";
    if (!std::filesystem::exists(report, ec)) {
      // The scenario report's own schema, with nothing simulated.
      scripting::RunOutcome stopped;
      stopped.status = scripting::RunOutcome::Status::kError;
      stopped.name = job.stem;
      stopped.file = job.file;
      stopped.error = job.stopped;
      std::ofstream(report, std::ios::binary) << stopped.to_json();
    }
  }
  job.log = read_file(log);
  if (job.log.empty() && !job.stopped.empty()) job.log = job.stopped + "\n";  // no log to read
  if (std::filesystem::is_regular_file(report, ec)) {
    job.report = nlohmann::json::parse(read_file(report), nullptr, false);
    if (job.report.is_discarded()) job.report = nlohmann::json();
  }
  if (job.baseline) compare_with_baseline(job, report);
}

/// The differences from the baseline, a line each, for the JUnit XML.
std::string changes_text(const Job& job) {
  if (job.changes.empty()) return {};
  std::string text = "differences from the baseline (" + job.baseline->string() + "):\n";
  for (const ReportChange& c : job.changes) text += "  " + c.str() + "\n";
  if (job.changes_total > job.changes.size()) {
    text += "  and " + std::to_string(job.changes_total - job.changes.size()) + " more\n";
  }
  return text;
}

void write_junit(const std::vector<Job>& jobs, const std::filesystem::path& path, double total) {
  std::size_t failures = 0, errors = 0;
  for (const Job& j : jobs) {
    failures += j.status == "failed" || j.status == "changed";
    errors += j.status == "error";
  }
  std::string xml = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  xml += "<testsuites tests=\"" + std::to_string(jobs.size()) + "\" failures=\"" +
         std::to_string(failures) + "\" errors=\"" + std::to_string(errors) + "\" time=\"" +
         format_seconds(total) + "\">\n";
  xml += "  <testsuite name=\"dovetail.regress\" tests=\"" + std::to_string(jobs.size()) +
         "\" failures=\"" + std::to_string(failures) + "\" errors=\"" + std::to_string(errors) +
         "\" time=\"" + format_seconds(total) + "\">\n";
  for (const Job& j : jobs) {
    xml += "    <testcase classname=\"scenarios\" name=\"" + xml_escape(j.stem) + "\" file=\"" +
           xml_escape(j.file.generic_string()) + "\" time=\"" + format_seconds(j.seconds) + "\"";
    if (j.status == "passed") {
      xml += j.without_baseline
                 ? ">\n      <system-out>no baseline to compare with: " +
                       xml_escape(j.baseline->string()) + "</system-out>\n    </testcase>\n"
                 : "/>\n";
      continue;
    }
    const std::string element = j.status == "error" ? "error" : "failure";
    xml += ">\n      <" + element + " message=\"" + xml_escape(first_reason(j)) + "\">" +
           xml_escape(j.log + changes_text(j) +
                      (j.baseline_error.empty() ? "" : j.baseline_error + "\n")) +
           "</" + element + ">\n    </testcase>\n";
  }
  xml += "  </testsuite>\n</testsuites>\n";
  std::ofstream out(path, std::ios::binary);
  out << xml;
  if (!out.flush()) throw InputError(path.string() + ": cannot be written");
}

/// An event's or message's "time", formatted; empty when it has none.
std::string seconds_of(const nlohmann::json& entry) {
  const auto it = entry.find("time");
  return it != entry.end() && it->is_number() ? format_seconds(it->get<double>()) : std::string();
}

std::string html_text(const nlohmann::json& value) {
  return value.is_string() ? xml_escape(value.get<std::string>()) : xml_escape(value.dump());
}

/// The report's warnings (loading and set-up) and messages (log, warn,
/// fail, violation, as the run wrote them) as one table; empty when there
/// are none.
std::string html_messages(const nlohmann::json& r) {
  std::string rows;
  if (r.contains("warnings") && r["warnings"].is_array()) {
    for (const auto& w : r["warnings"]) {
      rows += "<tr><td>before the run</td><td class=\"failed\">warn</td><td>" + html_text(w) +
              "</td><td></td></tr>\n";
    }
  }
  if (r.contains("messages") && r["messages"].is_array()) {
    for (const auto& m : r["messages"]) {
      const std::string level = m.value("level", "");
      rows += "<tr><td>" + seconds_of(m) + "</td><td" +
              (level == "log" ? "" : " class=\"failed\"") + ">" + html_text(level) + "</td><td>" +
              html_text(m.value("text", "")) + "</td><td>" + html_text(m.value("where", "")) +
              "</td></tr>\n";
    }
  }
  if (rows.empty()) return "";
  return "<table><tr><th>time (s)</th><th>level</th><th>message</th><th>where</th></tr>\n" + rows +
         "</table>\n";
}

/// One scenario's part of the HTML report: outcome, log, final frame,
/// expectations, steps, messages and event timeline.
std::string html_scenario(const Job& j, std::size_t index, const std::filesystem::path& out) {
  std::string h;
  const nlohmann::json& r = j.report;
  h += "<div class=\"scenario\" id=\"scenario-" + std::to_string(index + 1) + "\"><h2>" +
       xml_escape(j.stem);
  if (r.contains("scenario")) h += ": " + html_text(r["scenario"]);
  h += " <span class=\"" + j.status + "\">" + j.status + "</span></h2>\n";
  h += "<p>" + xml_escape(j.file.generic_string()) + "</p>\n";
  if (!j.log.empty()) h += "<pre>" + xml_escape(j.log) + "</pre>\n";
  if (!j.changes.empty()) {
    h += "<details open><summary>changed from the baseline (" + std::to_string(j.changes_total) +
         " differences)</summary><table><tr><th>where</th><th>now</th><th>baseline</th></tr>\n";
    for (const ReportChange& c : j.changes) {
      h += "<tr><td><code>" + xml_escape(c.where) + "</code></td><td><code>" + xml_escape(c.now) +
           "</code></td><td><code>" + xml_escape(c.was) + "</code></td></tr>\n";
    }
    if (j.changes_total > j.changes.size()) {
      h += "<tr><td colspan=\"3\">and " + std::to_string(j.changes_total - j.changes.size()) +
           " more</td></tr>\n";
    }
    h += "</table></details>\n";
  } else if (j.without_baseline) {
    h += "<p>No baseline to compare with: " + xml_escape(j.baseline->string()) + "</p>\n";
  }
  const std::filesystem::path png = out / j.stem / "final.png";
  std::error_code ec;
  if (std::filesystem::is_regular_file(png, ec)) {
    h += "<img alt=\"final frame of " + xml_escape(j.stem) + "\" src=\"data:image/png;base64," +
         base64(read_file(png)) + "\">\n";
  }
  if (r.contains("expectations") && r["expectations"].is_array()) {
    h += "<table><tr><th>expectation</th><th>where</th><th></th><th>detail</th></tr>\n";
    for (const auto& e : r["expectations"]) {
      const bool ok = e.value("passed", false);
      h += "<tr><td><code>" + html_text(e.value("expect", "")) + "</code></td><td>" +
           html_text(e.value("where", "")) + "</td><td class=\"" + (ok ? "passed" : "failed") +
           "\">" + (ok ? "holds" : "fails") + "</td><td>" + html_text(e.value("detail", "")) +
           "</td></tr>\n";
    }
    h += "</table>\n";
  }
  if (r.contains("steps") && r["steps"].is_array() && !r["steps"].empty()) {
    h += "<table><tr><th>step</th><th>done at (s)</th></tr>\n";
    for (const auto& s : r["steps"]) {
      h += "<tr><td>" + html_text(s.value("name", "")) + "</td><td>" +
           (s.contains("done_at") && s["done_at"].is_number()
                ? format_seconds(s["done_at"].get<double>())
                : std::string("not done")) +
           (s.value("out_of_order", false) ? " (out of order)" : "") + "</td></tr>\n";
    }
    h += "</table>\n";
  }
  h += html_messages(r);
  if (r.contains("simulation") && r["simulation"].contains("events")) {
    // The hand's segments touch parts many times a second: their contacts
    // get a table of their own, so the parts' events are not lost among them.
    std::string parts_rows, hand_rows;
    std::size_t parts_count = 0, hand_count = 0;
    for (const auto& e : r["simulation"]["events"]) {
      const std::string kind = e.value("kind", "");
      const bool hand = kind.rfind("hand_contact", 0) == 0;
      (hand ? hand_count : parts_count) += 1;
      (hand ? hand_rows : parts_rows) +=
          "<tr><td>" + seconds_of(e) + "</td><td>" + html_text(kind) + "</td><td>" +
          html_text(e.value("a", "")) + "</td><td>" + html_text(e.value("b", "")) + "</td></tr>\n";
    }
    const auto table = [&](const std::string& title, std::size_t n, const std::string& rows) {
      h += "<details><summary>" + title + " (" + std::to_string(n) +
           " events)</summary><table><tr><th>time (s)</th><th>event</th><th>a</th><th>b</th></tr>"
           "\n" +
           rows + "</table></details>\n";
    };
    table("event timeline", parts_count, parts_rows);
    if (hand_count > 0) table("the hand's contacts", hand_count, hand_rows);
  }
  h += "</div>\n";
  return h;
}

/// "k of n scenarios passed", and how many changed or had no baseline.
std::string summary_of(const std::vector<Job>& jobs) {
  std::size_t passed = 0, failed = 0, errors = 0, changed = 0, without = 0, same = 0;
  for (const Job& j : jobs) {
    passed += j.status == "passed";
    failed += j.status == "failed";
    errors += j.status == "error";
    changed += j.status == "changed";
    without += j.without_baseline;
    same += j.compared && j.changes_total == 0;
  }
  std::string text =
      std::to_string(passed) + " of " + std::to_string(jobs.size()) + " scenarios passed";
  if (failed > 0) text += ", " + std::to_string(failed) + " failed";
  if (errors > 0) text += ", " + std::to_string(errors) + (errors == 1 ? " error" : " errors");
  if (changed > 0) text += ", " + std::to_string(changed) + " changed from the baseline";
  if (without > 0) text += ", " + std::to_string(without) + " without a baseline";
  if (same > 0) text += ", " + std::to_string(same) + " the same as the baseline";
  return text;
}

void write_html(const std::vector<Job>& jobs, const std::filesystem::path& path,
                const std::filesystem::path& out, int interrupted) {
  std::string h = R"(<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>Dovetail regression</title>
<style>
body{font-family:sans-serif;margin:2em;color:#222;background:#fafafa}
h1{font-size:1.5em} h2{font-size:1.2em;margin-top:2em}
.passed{color:#1a7f37} .failed,.error{color:#c62828} .changed{color:#b25e00}
table{border-collapse:collapse;margin:.5em 0} td,th{border:1px solid #ccc;padding:.2em .6em;text-align:left;font-size:.9em}
th{background:#eee} .scenario{background:#fff;border:1px solid #ddd;padding:1em;margin:1em 0}
img{max-width:480px;border:1px solid #ccc} pre{background:#f0f0f0;padding:.5em;white-space:pre-wrap}
details{margin:.5em 0}
</style></head><body>
<h1>Dovetail regression</h1>
)";
  h += "<p id=\"summary\">" + summary_of(jobs) +
       (interrupted != 0 ? "; interrupted by signal " + std::to_string(interrupted)
                         : std::string()) +
       ".</p>\n<table><tr><th>scenario</th><th>outcome</th><th>seconds</th><th>reason</th></"
       "tr>\n";
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    const Job& j = jobs[i];
    h += "<tr><td><a href=\"#scenario-" + std::to_string(i + 1) + "\">" + xml_escape(j.stem) +
         "</a></td><td class=\"" + j.status + "\">" + j.status + "</td><td>" +
         format_seconds(j.seconds) + "</td><td>" +
         (j.status == "passed" ? "" : xml_escape(first_reason(j))) + "</td></tr>\n";
  }
  h += "</table>\n";
  for (std::size_t i = 0; i < jobs.size(); ++i) h += html_scenario(jobs[i], i, out);
  h += "</body></html>\n";
  std::ofstream file(path, std::ios::binary);
  file << h;
  if (!file.flush()) throw InputError(path.string() + ": cannot be written");
}

/// --shard K/N as (K, N); (1, 1) without it.
std::pair<std::size_t, std::size_t> parse_shard(const Args& args) {
  const std::optional<std::string> shard = args.value("shard");
  if (!shard) return {1, 1};
  // Digits only, each number within std::size_t: no sign, no wrap-around.
  const auto number = [&](std::string_view text, std::size_t& value) {
    if (text.empty() || text.find_first_not_of("0123456789") != std::string_view::npos)
      return false;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    return error == std::errc() && end == text.data() + text.size();
  };
  const std::size_t slash = shard->find('/');
  std::size_t k = 0, n = 0;
  if (slash == std::string::npos || !number(std::string_view(*shard).substr(0, slash), k) ||
      !number(std::string_view(*shard).substr(slash + 1), n) || n == 0 || k == 0 || k > n) {
    throw UsageError("regress: --shard must be K/N with 1 <= K <= N, not '" + *shard + "'");
  }
  return {k, n};
}

/// The scenarios of `folder` that fall to shard K of N (every N-th, in file-name order).
std::vector<Job> shard_jobs(const std::filesystem::path& folder, std::size_t shard_k,
                            std::size_t shard_n) {
  const std::vector<std::filesystem::path> files = scenario_files(folder);
  // An empty folder is most likely a wrong path: it fails, where an empty
  // shard (more shards than scenarios) passes.
  if (files.empty()) {
    throw InputError(folder.string() +
                     ": no scenarios in this folder (regress runs its *.lua files, not those "
                     "of its subfolders)");
  }
  std::vector<Job> jobs;
  for (std::size_t i = 0; i < files.size(); ++i) {
    if (i % shard_n != shard_k - 1) continue;
    Job job;
    job.file = files[i];
    job.stem = files[i].stem().string();
    jobs.push_back(std::move(job));
  }
  if (jobs.empty()) {
    std::fprintf(stderr, "dovetail: note: regress: no scenarios in %s for this shard\n",
                 folder.string().c_str());
  }
  return jobs;
}

/// Prints the line of a finished job.
void print_line(const Job& job) {
  std::string reason = job.status == "passed" ? "" : first_reason(job);
  if (job.without_baseline) reason += reason.empty() ? "(no baseline)" : " (no baseline)";
  std::printf("%-7s %-32s %8.2f s%s%s\n",
              job.status == "passed"    ? "PASS"
              : job.status == "failed"  ? "FAIL"
              : job.status == "changed" ? "CHANGED"
                                        : "ERROR",
              job.stem.c_str(), job.seconds, reason.empty() ? "" : "  ", reason.c_str());
  std::fflush(stdout);
}

/// Collects the child `pid` that ended with `wait_status` and prints its
/// line; false when it is none of the jobs.
bool collect(std::vector<Job>& jobs, pid_t pid, int wait_status, const std::filesystem::path& out,
             const std::string& interrupted) {
  for (Job& job : jobs) {
    if (job.pid != pid) continue;
    job.pid = -1;
    // Ctrl-C reaches the runs too: one it ended was stopped by the interrupt.
    if (!interrupted.empty() && WIFSIGNALED(wait_status) && job.stopped.empty()) {
      job.stopped = "stopped: " + interrupted;
    }
    finish(job, wait_status, out);
    print_line(job);
    return true;
  }
  return false;
}

/// The signal that asked regress to stop (SIGINT, SIGTERM, SIGHUP), or 0.
volatile std::sig_atomic_t g_interrupted = 0;

extern "C" void on_interrupt(int signal_number) { g_interrupted = signal_number; }

std::string interrupted_by(int signal_number) {
  return "regress was interrupted by signal " + std::to_string(signal_number);
}

/// While it lives, an interrupt stops the runs rather than regress itself,
/// so that no run is left behind and the summaries are still written.
class InterruptHandlers {
 public:
  InterruptHandlers() {
    struct sigaction action {};
    action.sa_handler = on_interrupt;
    sigemptyset(&action.sa_mask);
    for (std::size_t i = 0; i < kSignals.size(); ++i) {
      sigaction(kSignals[i], nullptr, &previous_[i]);
      // A signal ignored by whoever started regress (nohup) stays ignored.
      if (previous_[i].sa_handler != SIG_IGN) sigaction(kSignals[i], &action, nullptr);
    }
  }
  ~InterruptHandlers() {
    for (std::size_t i = 0; i < kSignals.size(); ++i)
      sigaction(kSignals[i], &previous_[i], nullptr);
  }
  InterruptHandlers(const InterruptHandlers&) = delete;
  InterruptHandlers& operator=(const InterruptHandlers&) = delete;

 private:
  static constexpr std::array<int, 3> kSignals = {SIGINT, SIGTERM, SIGHUP};
  std::array<struct sigaction, 3> previous_{};
};

/// Stops every run still going and waits for it, `why` in its log: on an
/// interrupt, and when regress itself fails, no run outlives it.
void stop_running(std::vector<Job>& jobs, const std::filesystem::path& out,
                  const std::string& why) {
  for (Job& job : jobs) {
    if (job.pid <= 0) continue;
    if (job.stopped.empty()) job.stopped = why;
    kill(job.pid, SIGKILL);
    int wait_status = 0;
    while (waitpid(job.pid, &wait_status, 0) < 0 && errno == EINTR) {
    }
    job.pid = -1;
    finish(job, wait_status, out);
    print_line(job);
  }
}

/// Runs the jobs, `parallel` at a time, each in its own process killed after
/// `timeout` seconds. Returns the signal that interrupted them, or 0; the
/// jobs not run then are reported as such.
int run_jobs(std::vector<Job>& jobs, const std::filesystem::path& out, std::size_t parallel,
             int threads, double timeout) {
  const InterruptHandlers handlers;
  std::size_t next = 0, running = 0, done = 0;
  try {
    while (done < jobs.size() && g_interrupted == 0) {
      while (running < parallel && next < jobs.size() && g_interrupted == 0) {
        Job& job = jobs[next++];
        if (start(job, out, threads)) {
          ++running;
        } else {
          finish(job, std::nullopt, out);
          print_line(job);
          ++done;
        }
      }
      int wait_status = 0;
      const pid_t pid = waitpid(-1, &wait_status, WNOHANG);
      if (pid > 0) {
        const int signal_number = g_interrupted;
        if (collect(jobs, pid, wait_status, out,
                    signal_number != 0 ? interrupted_by(signal_number) : std::string())) {
          --running;
          ++done;
        }
        continue;
      }
      const auto now = std::chrono::steady_clock::now();
      for (Job& job : jobs) {
        if (job.pid > 0 && job.stopped.empty() &&
            std::chrono::duration<double>(now - job.start).count() > timeout) {
          char reason[96];
          std::snprintf(reason, sizeof reason, "stopped after the timeout of %g s", timeout);
          job.stopped = reason;
          kill(job.pid, SIGKILL);
        }
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  } catch (...) {
    stop_running(jobs, out, "stopped: regress failed");
    throw;
  }
  const int signal_number = g_interrupted;
  if (signal_number == 0) return 0;
  const std::string why = interrupted_by(signal_number);
  stop_running(jobs, out, "stopped: " + why);
  for (; next < jobs.size(); ++next) {
    Job& job = jobs[next];
    job.start = std::chrono::steady_clock::now();
    job.stopped = "not run: " + why;
    // Nothing of an earlier regress may stand for it: a fresh log and report.
    remove_old_outputs(job, out);
    std::ofstream(out / (job.stem + ".log"), std::ios::binary | std::ios::trunc);
    finish(job, std::nullopt, out);
    print_line(job);
  }
  return signal_number;
}

/// Refuses a folder in which two scenarios would write one output: the
/// report, log and frames folder of "a.lua" are a.json, a.log and a/, so
/// "a.log.lua" or "a.json.lua" beside it would write over them.
void check_output_names(const std::vector<std::filesystem::path>& files) {
  std::map<std::string, std::filesystem::path> owner;
  for (const std::filesystem::path& f : files) {
    const std::string stem = f.stem().string();
    for (const std::string& name : {stem + ".json", stem + ".log", stem}) {
      const auto [it, fresh] = owner.emplace(name, f);
      if (!fresh && it->second != f) {
        throw InputError("regress: " + it->second.string() + " and " + f.string() +
                         " would both write OUT/" + name + "; rename one of them");
      }
    }
  }
}

/// A path made absolute and canonical as far as it exists; "results/" is "results".
std::filesystem::path full_path(const std::filesystem::path& p) {
  std::filesystem::path f = std::filesystem::weakly_canonical(std::filesystem::absolute(p));
  return f.has_filename() ? f : f.parent_path();
}

/// Whether `file` is inside folder `out` (at any depth).
bool inside(const std::filesystem::path& out, const std::string& file) {
  const std::filesystem::path out_folder = full_path(out);
  const std::filesystem::path parent = full_path(std::filesystem::absolute(file).parent_path());
  const auto [end, at] =
      std::mismatch(out_folder.begin(), out_folder.end(), parent.begin(), parent.end());
  return end == out_folder.end();
}

/// Checks the outputs before any scenario runs and before the output folder
/// is made: the --junit and --html files neither a scenario, nor each
/// other, nor a scenario's output, and writable (one inside the output
/// folder is checked for writing once the folder is made, regress_command);
/// no scenario's output another scenario.
void check_outputs(const std::optional<std::string>& junit, const std::optional<std::string>& html,
                   const std::vector<std::filesystem::path>& files,
                   const std::filesystem::path& out) {
  std::vector<std::string> scenarios;
  for (const std::filesystem::path& f : files) scenarios.push_back(f.string());
  for (const std::optional<std::string>& summary : {junit, html}) {
    if (!summary) continue;
    refuse_overwriting_input("regress", *summary, scenarios);
    if (!inside(out, *summary)) check_writable(*summary);
  }
  if (junit && html && engine::same_file(*junit, *html)) {
    throw UsageError("regress: --junit and --html name the same file '" + *junit + "'");
  }
  // No scenario's output is another scenario (regress DIR --out DIR: the
  // frames folder of "b.lua.lua" is DIR/b.lua).
  for (const std::filesystem::path& f : files) {
    const std::string stem = f.stem().string();
    for (const std::string& name : {stem + ".json", stem + ".log", stem}) {
      for (const std::filesystem::path& g : files) {
        if (engine::same_file(out / name, g)) {
          throw UsageError("regress: " + (out / name).string() + ", an output of " + f.string() +
                           ", is the scenario " + g.string() + "; choose another --out");
        }
      }
    }
  }
  // Nor the output folder, nor a scenario's own output: its report, its
  // log, its frames folder or a frame in it.
  for (const auto& [option, summary] : {std::pair{"junit", junit}, std::pair{"html", html}}) {
    if (!summary) continue;
    if (engine::same_file(*summary, out)) {
      throw UsageError(std::string("regress: --") + option + " '" + *summary +
                       "' is the output folder");
    }
    for (const std::filesystem::path& f : files) {
      const std::string stem = f.stem().string();
      if (engine::same_file(*summary, out / (stem + ".json")) ||
          engine::same_file(*summary, out / (stem + ".log")) ||
          engine::same_file(*summary, out / stem) || inside(out / stem, *summary)) {
        throw UsageError(std::string("regress: --") + option + " '" + *summary +
                         "' is an output of " + f.string() + " in " + out.string());
      }
    }
  }
}

/// The baseline: a folder, not OUT (each run removes its old report from
/// OUT before it starts), holding a report of at least one of DIR's
/// scenarios; neither --junit nor --html may write into it. Notes the
/// reports of scenarios no longer in DIR.
void check_baseline(const std::filesystem::path& baseline, const std::filesystem::path& out,
                    const std::optional<std::string>& junit, const std::optional<std::string>& html,
                    const std::vector<std::filesystem::path>& files,
                    const std::filesystem::path& folder) {
  std::error_code ec;
  // The scenarios' own folder is no place for reports: a folder of its own.
  const bool in_scenarios = engine::same_file(baseline, folder);
  const std::string make_one =
      " (make a baseline with 'dovetail regress " + folder.string() + " --out " +
      (in_scenarios ? (folder / ".." / "baseline").lexically_normal().string()
                    : baseline.string()) +
      "'" + (in_scenarios ? ", a folder of its own, then give it as --baseline)" : ")");
  if (!std::filesystem::exists(baseline, ec)) {
    throw InputError(baseline.string() + ": no such folder" + make_one);
  }
  if (!std::filesystem::is_directory(baseline, ec)) {
    throw InputError(baseline.string() +
                     ": not a folder; --baseline names the folder an earlier regress wrote its "
                     "reports into" +
                     make_one);
  }
  if (engine::same_file(baseline, out)) {
    throw UsageError("regress: --baseline " + baseline.string() +
                     " is the output folder: its reports would be replaced before they are "
                     "compared (give another --out)");
  }
  for (const auto& [option, summary] : {std::pair{"junit", junit}, std::pair{"html", html}}) {
    if (summary && inside(baseline, *summary)) {
      throw UsageError(std::string("regress: --") + option + " '" + *summary +
                       "' is in the baseline folder " + baseline.string() +
                       ": it would overwrite what the runs are compared with");
    }
  }
  std::set<std::string> stems;
  std::size_t found = 0;
  for (const std::filesystem::path& f : files) {
    stems.insert(f.stem().string());
    found += std::filesystem::exists(baseline / (f.stem().string() + ".json"), ec) ? 1 : 0;
  }
  if (found == 0) {
    throw InputError(baseline.string() + ": holds no report of a scenario in " + folder.string() +
                     " (STEM.json for STEM.lua)" + make_one);
  }
  std::vector<std::string> gone;
  for (const auto& entry : std::filesystem::directory_iterator(baseline, ec)) {
    const std::filesystem::path& p = entry.path();
    if (p.extension() != ".json" || stems.count(p.stem().string()) != 0) continue;
    if (scenario_report_at(p)) gone.push_back(p.stem().string());
  }
  std::sort(gone.begin(), gone.end());
  if (!gone.empty()) {
    std::fprintf(stderr,
                 "dovetail: note: regress: the baseline %s has reports of %s not in %s (deleted or "
                 "renamed since it was made?): %s\n",
                 baseline.string().c_str(), scenarios_counted(gone.size()).c_str(),
                 folder.string().c_str(), comma_list(gone).c_str());
  }
}

}  // namespace

int regress_command(std::span<const std::string> argv) {
  const Args args("regress", argv,
                  {"out", "junit", "html", "j", "shard", "threads", "timeout", "baseline",
                   "baseline-tolerance"},
                  {});
  if (args.help()) {
    std::fputs(kHelp, stdout);
    return kExitOk;
  }
  args.expect_positional(1, "a folder of scenarios");
  const std::filesystem::path folder = args.positional()[0];
  if (!std::filesystem::is_directory(folder)) {
    std::error_code ec;
    throw InputError(folder.string() + ": not a folder" +
                     (std::filesystem::is_regular_file(folder, ec)
                          ? " (regress runs every scenario of a folder; 'dovetail run " +
                                folder.string() + "' runs one)"
                          : std::string()));
  }
  const std::filesystem::path out = args.value("out").value_or("regress-out");
  const auto parallel = static_cast<std::size_t>(args.integer("j", 1, 256).value_or(1));
  const int threads = static_cast<int>(args.integer("threads", 0, 1024).value_or(1));
  const double timeout = args.number("timeout", 1).value_or(900);
  const auto [shard_k, shard_n] = parse_shard(args);
  const std::optional<std::string> junit = args.value("junit");
  const std::optional<std::string> html = args.value("html");
  check_outputs(junit, html, scenario_files(folder), out);
  check_output_names(scenario_files(folder));
  std::vector<Job> jobs = shard_jobs(folder, shard_k, shard_n);
  const double tolerance = args.number("baseline-tolerance", 0).value_or(0);
  if (const std::optional<std::string> baseline = args.value("baseline")) {
    check_baseline(*baseline, out, junit, html, scenario_files(folder), folder);
    for (Job& job : jobs) {
      job.baseline = std::filesystem::path(*baseline) / (job.stem + ".json");
      job.baseline_tolerance = tolerance;
    }
  } else if (args.value("baseline-tolerance")) {
    throw UsageError("regress: --baseline-tolerance needs --baseline B");
  }
  make_folder(out);
  if (::access(out.c_str(), W_OK | X_OK) != 0) {
    throw InputError(out.string() + ": cannot be written: " + std::strerror(errno));
  }
  for (const std::optional<std::string>& summary : {junit, html}) {
    if (summary && inside(out, *summary)) check_writable(*summary);
  }
  if (const std::vector<std::string> stale =
          remove_stale_outputs(out, folder, scenario_files(folder));
      !stale.empty()) {
    std::fprintf(stderr,
                 "dovetail: note: regress: removed from %s the outputs of %s no longer in %s: "
                 "%s\n",
                 out.string().c_str(), scenarios_counted(stale.size()).c_str(),
                 folder.string().c_str(), comma_list(stale).c_str());
  }

  const auto begin = std::chrono::steady_clock::now();
  const int interrupted = run_jobs(jobs, out, parallel, threads, timeout);
  const double total =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  std::size_t passed = 0;
  for (const Job& j : jobs) passed += j.status == "passed";
  std::printf("%s (%.1f s)%s\n", summary_of(jobs).c_str(), total,
              interrupted != 0 ? ", interrupted" : "");
  if (junit) write_junit(jobs, *junit, total);
  if (html) write_html(jobs, *html, out, interrupted);
  if (interrupted != 0) {
    // Ended by the signal, as a caller (a shell loop) expects of an interrupt.
    std::fflush(nullptr);
    std::signal(interrupted, SIG_DFL);
    std::raise(interrupted);
    return 128 + interrupted;
  }
  return passed == jobs.size() ? kExitOk : kExitCheckFailed;
}

}  // namespace dovetail::cli
