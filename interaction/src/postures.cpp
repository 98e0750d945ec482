#include "dovetail/interaction/postures.h"

#include <array>
#include <utility>

namespace dovetail::interaction {

namespace {

/// Angles in the order of Joint: thumb roll, mcp, ip, abd; index, middle,
/// ring, pinky mcp/pip/dip; the three relative abductions; palm arch; wrist
/// pitch and yaw.
struct Posture {
  std::string_view name;
  JointAngles angles;
};

constexpr std::array<Posture, 6> kPostures = {{
    {"open", {}},
    {"fist",
     {40, 50, 40, 10, 90, 100, 70, 90, 100, 70, 90, 100, 70, 90, 100, 70, 0, 0, 0, 10, 0, 0}},
    {"pinch", {60, 10, 5, 0, 50, 60, 20, 10, 10, 5, 10, 10, 5, 10, 10, 5, 0, 0, 0, 0, 0, 0}},
    {"tripod", {60, 10, 5, 0, 50, 60, 20, 50, 60, 20, 15, 15, 5, 15, 15, 5, 0, 0, 0, 0, 0, 0}},
    {"power", {50, 30, 30, 30, 60, 70, 40, 60, 70, 40, 60, 70, 40, 60, 70, 40, 0, 0, 0, 10, 0, 0}},
    {"point", {40, 50, 40, 10, 0, 0, 0, 90, 100, 70, 90, 100, 70, 90, 100, 70, 0, 0, 0, 10, 0, 0}},
}};

}  // namespace

std::optional<JointAngles> named_posture(std::string_view name) {
  for (const Posture& p : kPostures) {
    if (p.name == name) return p.angles;
  }
  return std::nullopt;
}

std::vector<std::string> posture_names() {
  std::vector<std::string> names;
  for (const Posture& p : kPostures) names.emplace_back(p.name);
  return names;
}

}  // namespace dovetail::interaction
