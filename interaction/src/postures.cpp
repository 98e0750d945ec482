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
    // Thumb opposed, its tip's pad on the index tip's radial pulp (their capsules 0.2 mm apart).
    {"pinch", {75, 10, 10, 15, 60, 30, 5, 10, 10, 5, 10, 10, 5, 10, 10, 5, 0, 0, 0, 0, 0, 0}},
    // Index and middle side by side, the thumb's tip pad below the middle of their tips.
    {"tripod", {85, 10, 15, 15, 40, 60, 30, 40, 70, 0, 15, 15, 5, 15, 15, 5, -10, 0, 0, 0, 0, 0}},
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
