// Glove plans (interaction::read_plan): any input either reads or throws
// PlanError; a plan that reads has finite, non-negative durations.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "dovetail/interaction/glove_plan.h"
#include "fuzz_support.h"

using namespace dovetail;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in{std::string(fuzz::as_text(data, size))};
  interaction::GlovePlan plan;
  try {
    plan = interaction::read_plan(in, "fuzz.plan");
  } catch (const interaction::PlanError&) {
    return 0;
  }
  fuzz::require(!plan.steps.empty(), "a plan that reads has steps");
  for (const interaction::PlanStep& step : plan.steps) {
    fuzz::require(std::isfinite(step.duration) && step.duration >= 0, "durations are finite and >= 0");
  }
  return 0;
}
