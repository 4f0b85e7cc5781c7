// io::LineFile: the file appears with its first line, checking it touches nothing, every line is
// whole, and a write that fails names the file and leaves the lines before it.

#include <gtest/gtest.h>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>

#include "core/input_error.hpp"
#include "io/line_file.hpp"
#include "support/files.hpp"

namespace mocap::io {
namespace {

namespace fs = std::filesystem;

TEST(LineFile, TheFileAppearsWithItsFirstLineAndCheckingTouchesNothing) {
  test::TempDir dir;
  const std::string path = dir.file("new/folder/poses.jsonl");
  LineFile file(path);
  file.check_writable();
  EXPECT_TRUE(fs::is_directory(dir.file("new/folder")));
  EXPECT_FALSE(fs::exists(path));
  EXPECT_TRUE(fs::is_empty(dir.file("new/folder"))) << "the probe file was left behind";
  file.write("{\"frame\": 0}");
  file.write("{\"frame\": 1}");
  file.close();
  EXPECT_EQ(test::read_file(path), "{\"frame\": 0}\n{\"frame\": 1}\n");

  // An existing file is checked without being changed, and replaced at the first line.
  LineFile again(path);
  again.check_writable();
  EXPECT_EQ(test::read_file(path), "{\"frame\": 0}\n{\"frame\": 1}\n");
  again.write("x");
  again.close();
  EXPECT_EQ(test::read_file(path), "x\n");
}

TEST(LineFile, AFileThatCannotBeMadeIsNamed) {
  test::TempDir dir;
  test::write_file(dir.file("plain"), "a file, not a folder");
  const std::string path = dir.file("plain/poses.jsonl");
  LineFile file(path);
  try {
    file.check_writable();
    FAIL() << "a folder inside a file was taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  EXPECT_THROW(file.write("x"), InputError);
}

// Over the file size limit (SIGXFSZ ignored, as `mocap run` does) the write fails naming the file
// and the file keeps its whole lines only.
TEST(LineFile, AFailedWriteLeavesOnlyWholeLines) {
  test::TempDir dir;
  const std::string path = dir.file("limited.jsonl");
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{100, 100};
    if (setrlimit(RLIMIT_FSIZE, &limit) != 0) _exit(5);
    LineFile file(path);
    try {
      for (int k = 0; k < 100; ++k) file.write(std::string(29, 'a' + static_cast<char>(k % 26)));
    } catch (const InputError& e) {
      _exit(std::string(e.what()).find(path) != std::string::npos ? 0 : 6);
    }
    _exit(7);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  ASSERT_EQ(WEXITSTATUS(status), 0) << "5: no limit, 6: message without the file, 7: no error";
  EXPECT_EQ(fs::file_size(path), 90u);  // three lines of 30 bytes; the fourth was cut back
}

}  // namespace
}  // namespace mocap::io
