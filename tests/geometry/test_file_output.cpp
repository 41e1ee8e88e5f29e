// WriteFileAtomically: complete files or none, no temporary files left, permissions kept.
#include <pushgraph/geometry/file_output.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

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
