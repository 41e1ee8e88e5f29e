// Trajectory JSON (io::ParseTrajectoryJson).
#include <pushgraph/io/trajectory_json.h>

#include "fuzz_target.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  pushgraph::fuzz::ExpectReturnOrClearError([&] { pushgraph::io::ParseTrajectoryJson(text, "fuzz.json"); });
  return 0;
}
