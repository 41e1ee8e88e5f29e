// MIT pushing recordings in HDF5 (io::ReadMitPush on a .h5 file).
#include <pushgraph/io/mit_push.h>

#include "fuzz_target.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = pushgraph::fuzz::AsFile(data, size, ".h5");
  pushgraph::fuzz::ExpectReturnOrClearError([&] { pushgraph::io::ReadMitPush(path); });
  return 0;
}
