#include "report_diff.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string_view>

namespace dovetail::cli {

namespace {

using json = nlohmann::ordered_json;

/// A value as the change shows it: JSON, long texts cut.
std::string shown(const json& value) {
  constexpr std::size_t kLongest = 160;
  std::string text = value.dump(-1, ' ', false, json::error_handler_t::replace);
  if (text.size() > kLongest) text = text.substr(0, kLongest) + "...";
  return text;
}

void replace_in_strings(json& value, const std::string& from, const std::string& to) {
  if (from.empty()) return;
  if (value.is_string()) {
    std::string text = value.get<std::string>();
    for (std::size_t at = text.find(from); at != std::string::npos;
         at = text.find(from, at + to.size())) {
      text.replace(at, from.size(), to);
    }
    value = std::move(text);
  } else if (value.is_structured()) {
    for (json& child : value) replace_in_strings(child, from, to);
  }
}

/// The report without its `file`, the scenario's path in its texts read as
/// the file's name, and its folder's paths as relative to the folder.
json normalized(const json& report) {
  json r = report;
  if (!r.is_object() || !r.contains("file") || !r["file"].is_string()) return r;
  const std::filesystem::path file = r["file"].get<std::string>();
  r.erase("file");
  replace_in_strings(r, file.string(), file.filename().string());
  if (file.has_parent_path()) replace_in_strings(r, file.parent_path().string() + "/", "");
  return r;
}

/// What names an entry of a list: a step's or part's name, an
/// expectation's text, a pair of parts; empty when nothing does.
std::string label_of(const json& entry) {
  if (!entry.is_object()) return {};
  for (const char* key : {"name", "part", "expect"}) {
    if (const auto it = entry.find(key); it != entry.end() && it->is_string()) {
      return it->get<std::string>();
    }
  }
  const auto a = entry.find("a");
  const auto b = entry.find("b");
  if (a != entry.end() && b != entry.end() && a->is_string() && b->is_string() &&
      !entry.contains("kind")) {  // an event is named by its place in the timeline
    return a->get<std::string>() + "/" + b->get<std::string>();
  }
  return {};
}

class Differ {
 public:
  Differ(std::size_t limit, double tolerance) : limit_(limit), tolerance_(tolerance) {}

  void walk(const json& was, const json& now, const std::string& where) {
    if (was.is_object() && now.is_object()) {
      for (const auto& [key, value] : now.items()) {
        const std::string at = where.empty() ? key : where + "." + key;
        if (tolerance_ > 0 && at == "simulation.state_hash") continue;
        if (const auto it = was.find(key); it != was.end()) {
          walk(*it, value, at);
        } else {
          add(at, shown(value), "null");
        }
      }
      for (const auto& [key, value] : was.items()) {
        if (!now.contains(key)) add(where.empty() ? key : where + "." + key, "null", shown(value));
      }
      return;
    }
    if (was.is_array() && now.is_array()) {
      const std::size_t common = std::min(was.size(), now.size());
      for (std::size_t i = 0; i < common; ++i) {
        const std::string label = label_of(now[i]);
        const std::string index = where + "[" + std::to_string(i) + "]";
        if (label != label_of(was[i])) {
          add(index, shown(now[i]), shown(was[i]));  // another entry in its place
        } else {
          walk(was[i], now[i], label.empty() ? index : where + "[" + label + "]");
        }
      }
      if (was.size() != now.size()) {
        add(where + " entries", std::to_string(now.size()), std::to_string(was.size()));
      }
      for (std::size_t i = common; i < now.size(); ++i) {
        add(where + "[" + std::to_string(i) + "]", shown(now[i]), "null");
      }
      for (std::size_t i = common; i < was.size(); ++i) {
        add(where + "[" + std::to_string(i) + "]", "null", shown(was[i]));
      }
      return;
    }
    if (was.is_number() && now.is_number() && tolerance_ > 0) {
      const double a = was.get<double>();
      const double b = now.get<double>();
      if (std::abs(a - b) <= tolerance_ * std::max({1.0, std::abs(a), std::abs(b)})) return;
    }
    if (was != now) add(where, shown(now), shown(was));
  }

  std::vector<ReportChange> changes;
  std::size_t total = 0;

 private:
  void add(std::string where, std::string now, std::string was) {
    ++total;
    if (changes.size() < limit_)
      changes.push_back({std::move(where), std::move(now), std::move(was)});
  }

  std::size_t limit_;
  double tolerance_;
};

}  // namespace

std::string ReportChange::str() const { return where + ": " + now + ", was " + was; }

std::vector<ReportChange> report_changes(const json& baseline, const json& now, std::size_t limit,
                                         std::size_t& total, double tolerance) {
  Differ differ(limit, tolerance);
  differ.walk(normalized(baseline), normalized(now), "");
  total = differ.total;
  return std::move(differ.changes);
}

bool is_scenario_report(const json& report) {
  if (!report.is_object()) return false;
  const auto format = report.find("format");
  return format != report.end() && *format == "dovetail-scenario-report";
}

}  // namespace dovetail::cli
