#pragma once
// The io module's error: every unreadable or invalid file, and every file that cannot be written.
#include <stdexcept>

namespace pushgraph::io {

/// Thrown for unreadable or invalid input files; what() names the file and the location.
class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace pushgraph::io
