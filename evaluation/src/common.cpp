// Helpers shared by the evaluation's source files (internal.h).
#include "internal.h"

#include <nlohmann/json.hpp>

#include <algorithm>

namespace pushgraph::evaluation::internal {

std::uint64_t SplitMix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

std::string DumpJson(const nlohmann::json& value, int indent) {
  return value.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::uint64_t Fnv1a(const std::string& s) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  return h;
}


bool HasProtocol(const std::vector<Protocol>& ps, Protocol p) { return std::find(ps.begin(), ps.end(), p) != ps.end(); }

}  // namespace pushgraph::evaluation::internal
