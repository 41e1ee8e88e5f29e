// Evaluation config JSON (evaluation::LoadEvaluationConfig, which takes a path).
#include <pushgraph/evaluation/config.h>

#include "fuzz_target.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = pushgraph::fuzz::AsFile(data, size, ".json");
  pushgraph::fuzz::ExpectReturnOrClearError([&] {
    pushgraph::evaluation::EvaluationOptions options;
    pushgraph::evaluation::LoadEvaluationConfig(path, &options);
  });
  return 0;
}
