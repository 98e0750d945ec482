// Glove traces (interaction::read_trace): any input either reads or throws
// TraceError; a trace that reads is written and read back bit for bit, and
// writing it again gives the same bytes (glove_trace.h).

#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "dovetail/interaction/glove_trace.h"
#include "fuzz_support.h"

using namespace dovetail;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in{std::string(fuzz::as_text(data, size))};
  std::vector<interaction::GloveSample> samples;
  try {
    samples = interaction::read_trace(in, "fuzz.csv");
  } catch (const interaction::TraceError&) {
    return 0;
  }
  const std::string written = interaction::format_trace(samples);
  std::istringstream again{written};
  const std::vector<interaction::GloveSample> reread = interaction::read_trace(again, "written.csv");
  fuzz::require(reread.size() == samples.size(), "a written trace reads back the same sample count");
  for (std::size_t i = 0; i < samples.size(); ++i) {
    fuzz::require(interaction::same_bits(reread[i], samples[i]),
                  "a written trace reads back bit for bit");
  }
  fuzz::require(interaction::format_trace(reread) == written, "writing a read trace gives the same bytes");
  return 0;
}
