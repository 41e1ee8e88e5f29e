// MIT pushing recordings in JSON (io::ReadMitPush on a .json file).
#include <pushgraph/io/mit_push.h>

#include "fuzz_target.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = pushgraph::fuzz::AsFile(data, size, ".json");
  pushgraph::fuzz::ExpectReturnOrClearError([&] { pushgraph::io::ReadMitPush(path); });
  return 0;
}
