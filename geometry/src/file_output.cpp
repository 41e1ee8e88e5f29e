// Atomic file replacement: temporary file in the same folder, fsync, rename (POSIX).
#include <pushgraph/geometry/file_output.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace pushgraph::geometry {

namespace {

std::string Failure(const std::string& path, const std::string& what, int error) {
  return path + ": cannot write (" + what + (error != 0 ? std::string(": ") + std::strerror(error) : "") + ")";
}

// A FIFO, a character device (/dev/null, a terminal) or a socket cannot be replaced by a
// renamed file without destroying it (as root, renaming over /dev/null replaces the device):
// the text is written into it, as a shell redirection would.
std::string WriteThrough(const std::string& path, const std::string& content) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) return Failure(path, "cannot open", errno);
  for (std::size_t written = 0; written < content.size();) {
    const ssize_t n = ::write(fd, content.data() + written, content.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int error = errno;
      ::close(fd);
      return Failure(path, "write failed", error);
    }
    written += static_cast<std::size_t>(n);
  }
  if (::close(fd) != 0) return Failure(path, "close failed", errno);
  return "";
}

std::string WriteFile(const std::string& path, const std::string& content, int links_followed);

// A symbolic link: the file it names is replaced (atomically, when it is a regular file), the
// link stays, as a shell redirection through it would.
std::string WriteThroughLink(const std::string& path, const std::string& content, int links_followed) {
  namespace fs = std::filesystem;
  if (links_followed >= 40) return Failure(path, "too many levels of symbolic links", ELOOP);
  std::error_code ec;
  fs::path pointed = fs::read_symlink(path, ec);
  if (ec) return Failure(path, "cannot read the symbolic link", ec.value());
  if (pointed.is_relative()) pointed = fs::path(path).parent_path() / pointed;
  return WriteFile(pointed.string(), content, links_followed + 1);
}

std::string WriteFile(const std::string& path, const std::string& content, int links_followed) {
  namespace fs = std::filesystem;
  const auto failure = [&](const std::string& what, int error) { return Failure(path, what, error); };
  std::error_code ec;
  const fs::file_status own = fs::symlink_status(path, ec);
  if (!ec && fs::is_symlink(own)) {
    // A link to a pipe, a terminal or a socket (/dev/stdout into a pipe names "pipe:[N]", no
    // path): written into through the link, as a shell redirection would.
    const fs::file_status pointed = fs::status(path, ec);
    if (!ec && (fs::is_fifo(pointed) || fs::is_character_file(pointed) || fs::is_socket(pointed)))
      return WriteThrough(path, content);
    return WriteThroughLink(path, content, links_followed);
  }
  if (fs::is_directory(path, ec)) return path + ": is a directory, not a file to write";
  if (!ec && fs::exists(own) && !fs::is_regular_file(own)) return WriteThrough(path, content);
  // The temporary file sits beside the target (same file system, so the rename is atomic).
  const fs::path target(path);
  const fs::path folder = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::string pattern = (folder / ("." + target.filename().string() + ".tmp-XXXXXX")).string();
  const int fd = ::mkstemp(pattern.data());
  if (fd < 0) return failure("cannot create a temporary file in " + folder.string(), errno);
  const std::string temporary = pattern;
  const auto abandon = [&](const std::string& what, int error) {
    ::close(fd);
    ::unlink(temporary.c_str());
    return failure(what, error);
  };
  for (std::size_t written = 0; written < content.size();) {
    const ssize_t n = ::write(fd, content.data() + written, content.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      return abandon("write failed", errno);
    }
    written += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) return abandon("flush to disk failed", errno);
  // mkstemp makes the file 0600: keep the target's permissions, or give a new file what open(2)
  // would (0666 & ~umask; the umask read from /proc, as setting it to read it is not
  // thread-safe).
  const fs::file_status old_status = fs::status(target, ec);
  mode_t mode = 0644;
  if (!ec && fs::exists(old_status)) {
    mode = static_cast<mode_t>(old_status.permissions() & fs::perms::mask);
  } else if (std::FILE* status = std::fopen("/proc/self/status", "r")) {
    char line[256];
    unsigned mask = 022;
    while (std::fgets(line, sizeof line, status))
      if (std::sscanf(line, "Umask: %o", &mask) == 1) break;
    std::fclose(status);
    mode = static_cast<mode_t>(0666 & ~mask);
  }
  ::fchmod(fd, mode);
  if (::close(fd) != 0) {
    ::unlink(temporary.c_str());
    return failure("close failed", errno);
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    const int error = errno;
    ::unlink(temporary.c_str());
    return failure("rename into place failed", error);
  }
  return "";
}

}  // namespace

std::string WriteFileAtomically(const std::string& path, const std::string& content) {
  return WriteFile(path, content, 0);
}

}  // namespace pushgraph::geometry
