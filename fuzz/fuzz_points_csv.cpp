// Points CSV (io::ParsePointsCsv, read by `pushgraph distance`).
#include <pushgraph/io/points_csv.h>

#include "fuzz_target.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  pushgraph::fuzz::ExpectReturnOrClearError([&] { pushgraph::io::ParsePointsCsv(text, "fuzz.csv"); });
  return 0;
}
