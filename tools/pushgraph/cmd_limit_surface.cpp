// Being written by the limit-surface work (replaced before commit).
#include "cli_common.h"
namespace pushgraph::cli {
void RegisterLimitSurface(CLI::App&) {}
}  // namespace pushgraph::cli
