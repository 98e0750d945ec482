#pragma once
/// \file postures.h
/// Named hand postures: joint angles for the simulated glove's "close to a
/// posture" and for tests.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dovetail/interaction/glove_sample.h"

namespace dovetail::interaction {

/// The joint angles of a named posture, or nullopt. Names: `open` (every
/// angle 0: the flat hand), `fist`, `pinch` (thumb tip toward the index tip),
/// `tripod` (thumb, index and middle tips), `power` (fingers wrapped around
/// a cylinder of about 40 mm), `point` (index straight, the others curled).
std::optional<JointAngles> named_posture(std::string_view name);
/// The names accepted by named_posture, in a fixed order.
std::vector<std::string> posture_names();

}  // namespace dovetail::interaction
