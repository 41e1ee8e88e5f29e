// Estimator config JSON (graph::ParseEstimatorConfig).
#include <pushgraph/graph/config.h>

#include "fuzz_target.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  pushgraph::fuzz::ExpectReturnOrClearError([&] { pushgraph::graph::ParseEstimatorConfig(text); });
  return 0;
}
