#include "dovetail/interaction/glove_plan.h"

#include <array>
#include <cmath>
#include <fstream>
#include <istream>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "dovetail/interaction/glove_trace.h"
#include "dovetail/interaction/postures.h"
#include "text_reading.h"

namespace dovetail::interaction {

namespace {

constexpr std::array<std::string_view, 7> kPoseFields = {"x", "y", "z", "qw", "qx", "qy", "qz"};
constexpr std::size_t kPoseFieldCount = kPoseFields.size();

bool is_blank(char c) { return c == ' ' || c == '\t'; }

/// The blank-separated fields of a line before any `#`.
std::vector<std::string_view> split_fields(std::string_view text) {
  text = text.substr(0, text.find('#'));
  std::vector<std::string_view> fields;
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && is_blank(text[i])) ++i;
    const std::size_t start = i;
    while (i < text.size() && !is_blank(text[i])) ++i;
    if (i > start) fields.push_back(text.substr(start, i - start));
  }
  return fields;
}

std::string list_postures() {
  std::string list;
  for (const std::string& name : posture_names()) list += (list.empty() ? "" : ", ") + name;
  return list;
}

/// One step line: its keyword and the fields after it, with errors naming the line.
class StepLine {
 public:
  StepLine(std::string where, std::vector<std::string_view> fields)
      : where_(std::move(where)), fields_(std::move(fields)) {}

  std::string_view keyword() const { return fields_.front(); }
  /// Fields after the keyword.
  std::size_t count() const { return fields_.size() - 1; }
  /// Field i after the keyword (0-based).
  std::string_view field(std::size_t i) const { return fields_[i + 1]; }

  [[noreturn]] void fail(const std::string& what) const { throw PlanError(where_ + ": " + what); }

  void expect_count(bool ok, std::string_view form) const {
    if (!ok) {
      fail(std::string(keyword()) + " expects " + std::string(form) + ", found " +
           std::to_string(count()) + " field" + (count() == 1 ? "" : "s"));
    }
  }

  /// Field i as a finite number; `what` names it in messages.
  Real number(std::size_t i, const std::string& what) const {
    const std::optional<Real> value = parse_number(field(i));
    if (!value) fail(what + " " + quoted(field(i)) + " is not a number");
    if (!std::isfinite(*value)) fail(what + " " + quoted(field(i)) + " is not finite");
    return *value;
  }

  /// Field 0 as a duration.
  Real duration() const {
    const Real value = number(0, std::string(keyword()) + " duration");
    if (value < 0) fail(std::string(keyword()) + " duration " + quoted(field(0)) + " is negative");
    return value;
  }

  /// The pose in the seven fields from `first`; `label` names it in messages.
  TrackerPose pose(std::size_t first, const std::string& label) const {
    std::array<Real, kPoseFieldCount> v{};
    for (std::size_t c = 0; c < kPoseFieldCount; ++c) {
      v[c] = number(first + c, label + " " + std::string(kPoseFields[c]));
    }
    if (v[3] == 0 && v[4] == 0 && v[5] == 0 && v[6] == 0) {
      fail(label + " quaternion (qw qx qy qz) is zero");
    }
    TrackerPose pose;
    pose.p_WH = Vec3(v[0], v[1], v[2]);
    pose.q_WH = normalized({v[3], v[4], v[5], v[6]});
    return pose;
  }

  /// A posture name or the 22 angles from `first` to the end of the line.
  JointAngles posture(std::size_t first) const {
    if (count() - first == 1) {
      const std::optional<JointAngles> angles = named_posture(field(first));
      if (!angles) {
        fail("unknown posture " + quoted(field(first)) + " (known: " + list_postures() + ")");
      }
      return *angles;
    }
    JointAngles angles{};
    for (std::size_t j = 0; j < kJointCount; ++j) {
      angles[j] = number(
          first + j, std::string(keyword()) + " " + std::string(joint_name(static_cast<Joint>(j))));
    }
    return angles;
  }

 private:
  std::string where_;
  std::vector<std::string_view> fields_;
};

/// The plan being read and the line state that checks `start`.
class PlanReader {
 public:
  void read(const StepLine& line, std::size_t line_number) {
    const std::string_view keyword = line.keyword();
    if (keyword == "start") {
      read_start(line, line_number);
      return;
    }
    PlanStep step;
    if (keyword == "reach") {
      line.expect_count(line.count() == 1 + kPoseFieldCount, "DURATION X Y Z QW QX QY QZ");
      step.kind = PlanStep::Kind::kReach;
      step.duration = line.duration();
      step.poses.push_back(line.pose(1, "reach"));
    } else if (keyword == "path") {
      line.expect_count(line.count() > 1 && (line.count() - 1) % kPoseFieldCount == 0,
                        "DURATION and one or more poses X Y Z QW QX QY QZ");
      step.kind = PlanStep::Kind::kPath;
      step.duration = line.duration();
      const std::size_t poses = (line.count() - 1) / kPoseFieldCount;
      for (std::size_t i = 0; i < poses; ++i) {
        step.poses.push_back(
            line.pose(1 + i * kPoseFieldCount, "path pose " + std::to_string(i + 1)));
      }
    } else if (keyword == "close") {
      line.expect_count(line.count() == 2 || line.count() == 1 + kJointCount,
                        "DURATION and a posture name or 22 angles");
      step.kind = PlanStep::Kind::kClose;
      step.duration = line.duration();
      step.posture = line.posture(1);
    } else if (keyword == "open" || keyword == "wait") {
      line.expect_count(line.count() == 1, "DURATION");
      step.kind = keyword == "open" ? PlanStep::Kind::kOpen : PlanStep::Kind::kWait;
      step.duration = line.duration();
    } else {
      line.fail("unknown step " + quoted(keyword) +
                " (expected start, reach, path, close, open or wait)");
    }
    total_ += step.duration;
    if (!std::isfinite(total_)) line.fail("the plan's duration overflows");
    plan_.steps.push_back(std::move(step));
  }

  GlovePlan finish(std::string_view name) {
    if (plan_.steps.empty()) throw PlanError(std::string(name) + ": plan has no steps");
    return std::move(plan_);
  }

 private:
  void read_start(const StepLine& line, std::size_t line_number) {
    if (start_line_ != 0) {
      line.fail("start given twice (first on line " + std::to_string(start_line_) + ")");
    }
    if (!plan_.steps.empty()) line.fail("start must come before every other step");
    start_line_ = line_number;
    line.expect_count(line.count() == kPoseFieldCount || line.count() == kPoseFieldCount + 1 ||
                          line.count() == kPoseFieldCount + kJointCount,
                      "X Y Z QW QX QY QZ and an optional posture (a name or 22 angles)");
    plan_.start = line.pose(0, "start");
    if (line.count() > kPoseFieldCount) plan_.start_posture = line.posture(kPoseFieldCount);
  }

  GlovePlan plan_;
  Real total_ = 0;
  std::size_t start_line_ = 0;
};

}  // namespace

Real GlovePlan::duration() const {
  Real total = 0;
  for (const PlanStep& step : steps) total += step.duration;
  return total;
}

GlovePlan read_plan(std::istream& in, std::string_view name) {
  PlanReader reader;
  try {
    LineReader lines(in, name);
    while (const std::optional<std::string_view> text = lines.next()) {
      std::vector<std::string_view> fields = split_fields(*text);
      if (fields.empty()) continue;
      reader.read(StepLine(lines.name() + ":" + std::to_string(lines.line()), std::move(fields)),
                  lines.line());
    }
  } catch (const TraceError& e) {
    throw PlanError(e.what());  // a line too long or a read error, from the shared line reader
  }
  return reader.finish(name);
}

GlovePlan read_plan(const std::filesystem::path& path) {
  std::ifstream in;
  try {
    in = open_for_reading(path);
  } catch (const TraceError& e) {
    throw PlanError(e.what());
  }
  return read_plan(in, path.string());
}

}  // namespace dovetail::interaction
