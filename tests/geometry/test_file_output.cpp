// WriteFileAtomically: complete files or none, no temporary files left, permissions kept.
#include <pushgraph/geometry/file_output.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

namespace pushgraph::geometry {
namespace {

namespace fs = std::filesystem;

std::string Read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class FileOutput : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("pushgraph_file_output_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  int FilesIn() const { return static_cast<int>(std::distance(fs::directory_iterator(dir_), fs::directory_iterator())); }
  fs::path dir_;
};

TEST_F(FileOutput, WritesReplacesAndLeavesNoTemporaryFile) {
  const fs::path p = dir_ / "a.json";
  EXPECT_EQ(WriteFileAtomically(p.string(), "first\n"), "");
  EXPECT_EQ(Read(p), "first\n");
  EXPECT_EQ(WriteFileAtomically(p.string(), std::string(1 << 20, 'x')), "");
  EXPECT_EQ(Read(p).size(), std::size_t{1} << 20);
  EXPECT_EQ(FilesIn(), 1);
}

TEST_F(FileOutput, KeepsTheTargetsPermissions) {
  const fs::path p = dir_ / "b.txt";
  ASSERT_EQ(WriteFileAtomically(p.string(), "x"), "");
  fs::permissions(p, fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  ASSERT_EQ(WriteFileAtomically(p.string(), "y"), "");
  EXPECT_EQ(fs::status(p).permissions() & fs::perms::mask,
            fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
}

TEST_F(FileOutput, FailuresNameThePathAndKeepTheOldFile) {
  const fs::path missing = dir_ / "no_such_folder" / "c.json";
  const std::string error = WriteFileAtomically(missing.string(), "x");
  EXPECT_NE(error.find(missing.string()), std::string::npos) << error;
  const std::string onto_folder = WriteFileAtomically(dir_.string(), "x");
  EXPECT_NE(onto_folder.find("is a directory"), std::string::npos) << onto_folder;
  EXPECT_EQ(FilesIn(), 0);
}

// A symbolic link is written through (its file replaced, the link kept, a relative or dangling
// link too, a loop refused by name); a FIFO (as /dev/null, a device) is written into, not replaced.
TEST_F(FileOutput, LinksAndSpecialFilesAreWrittenThroughNotReplaced) {
  const fs::path target = dir_ / "target.json", link = dir_ / "link.json";
  std::ofstream(target) << "old";
  fs::create_symlink("target.json", link);  // relative to the link's folder
  EXPECT_EQ(WriteFileAtomically(link.string(), "new"), "");
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(link)));
  EXPECT_EQ(Read(target), "new");
  const fs::path dangling = dir_ / "dangling.json";
  fs::create_symlink(dir_ / "made_by_the_write.json", dangling);
  EXPECT_EQ(WriteFileAtomically(dangling.string(), "made"), "");
  EXPECT_EQ(Read(dir_ / "made_by_the_write.json"), "made");
  const fs::path loop_a = dir_ / "loop_a", loop_b = dir_ / "loop_b";
  fs::create_symlink(loop_b, loop_a);
  fs::create_symlink(loop_a, loop_b);
  const std::string loop = WriteFileAtomically(loop_a.string(), "x");
  EXPECT_NE(loop.find("symbolic links"), std::string::npos) << loop;

  // (A FIFO stands for /dev/null here: the same code path, and a regression would not replace
  // the machine's /dev/null when the tests run as root.)
  const fs::path fifo = dir_ / "fifo.json";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::string received;
  std::thread reader([&] { received = Read(fifo); });
  EXPECT_EQ(WriteFileAtomically(fifo.string(), "through the pipe"), "");
  reader.join();
  EXPECT_EQ(received, "through the pipe");
  EXPECT_TRUE(fs::is_fifo(fifo));

  // /dev/stdout into a pipe (`pushgraph estimate ... -o /dev/stdout | jq`): a link to
  // "pipe:[N]", which names no file; it failed with "cannot create a temporary file in /proc/self/fd".
  int ends[2];
  ASSERT_EQ(::pipe(ends), 0);
  const std::string through = "/proc/self/fd/" + std::to_string(ends[1]);
  ASSERT_TRUE(fs::is_symlink(fs::symlink_status(through)));
  EXPECT_EQ(WriteFileAtomically(through, "into the pipe"), "");
  ::close(ends[1]);
  char buffer[64] = {};
  const ssize_t n = ::read(ends[0], buffer, sizeof buffer - 1);
  ::close(ends[0]);
  EXPECT_EQ(std::string(buffer, n > 0 ? static_cast<std::size_t>(n) : 0), "into the pipe");
}

TEST_F(FileOutput, ConcurrentWritersLeaveOneWholeFile) {
  const fs::path p = dir_ / "d.txt";
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (int k = 0; k < 20; ++k) EXPECT_EQ(WriteFileAtomically(p.string(), std::string(100000, static_cast<char>('a' + t))), "");
    });
  for (auto& t : threads) t.join();
  const std::string text = Read(p);
  ASSERT_EQ(text.size(), 100000u);
  EXPECT_EQ(text.find_first_not_of(text[0]), std::string::npos);  // one writer's whole content
  EXPECT_EQ(FilesIn(), 1);
}

}  // namespace
}  // namespace pushgraph::geometry
