#pragma once
// Shared by the libFuzzer harnesses (fuzz/README.md): a reader either returns or throws a
// std::exception with a message; anything else (a crash, a sanitizer report, another exception
// type, an empty message) is a finding. Readers that only take a path get the input through a
// file in the system's temporary folder.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <new>
#include <fstream>
#include <string>
#include <unistd.h>

namespace pushgraph::fuzz {

/// Runs `read` and checks the only way it may fail: a std::exception saying something (not
/// std::bad_alloc: an allocation the input's size does not justify is a finding).
template <class F>
void ExpectReturnOrClearError(F&& read) {
  try {
    read();
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "finding: std::bad_alloc (an allocation the input does not justify)\n");
    std::abort();
  } catch (const std::exception& e) {
    if (e.what() == nullptr || e.what()[0] == '\0') {
      std::fprintf(stderr, "finding: an exception without a message\n");
      std::abort();
    }
  }
}

/// The fuzz input as a file with the given extension (one per process, rewritten every run).
inline std::string AsFile(const uint8_t* data, size_t size, const std::string& extension) {
  static const std::string path =
      (std::filesystem::temp_directory_path() / ("pushgraph-fuzz-" + std::to_string(getpid()) + extension)).string();
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

}  // namespace pushgraph::fuzz
