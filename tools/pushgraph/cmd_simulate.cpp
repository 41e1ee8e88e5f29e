// Being written by the limit-surface work (replaced before commit).
#include "cli_common.h"
namespace pushgraph::cli {
void RegisterSimulate(CLI::App&) {}
}  // namespace pushgraph::cli
