// core::GrowingFile on its own (the BVH and TRC stream writers test it through their formats): a
// writer killed at random moments leaves its counted lines whole; a failed write is cut back and
// a later one goes on; suspend() and the next append() reopen the file, refusing one changed
// meanwhile; the file appears with its first line, or replaces an old one only once its header
// is whole.

#include "core/growing_file.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <thread>

#include "core/input_error.hpp"
#include "support/files.hpp"

namespace mocap {
namespace {

namespace fs = std::filesystem;

// A file of numbered lines whose header counts them: "lines: 00000042\n".
constexpr std::string_view kHeader = "lines: 00000000\n";
constexpr std::int64_t kCountOffset = 7;

std::string count_field(int n) {
  char text[16];
  std::snprintf(text, sizeof text, "%08d", n);
  return text;
}

// Line k: lengths from 9 to ~700 bytes, so that many would cross a page.
std::string line(int k) {
  return "line " + std::to_string(k) + " " +
         std::string(static_cast<std::size_t>(k * 37 % 700), 'x') + "\n";
}

void append(GrowingFile& file, int k) { file.append(line(k), kCountOffset, count_field(k + 1)); }

// The counted lines and what follows them, checked as the project's readers take a file: the
// header's count, then that many whole lines (a line may follow spaces that moved it to the next
// page), then at most one uncounted line, whole, or spaces.
struct Contents {
  int counted = 0;
  std::string after;  // what follows the counted lines
};

Contents read_counted(const std::string& path) {
  const std::string text = test::read_file(path);
  EXPECT_GE(text.size(), kHeader.size());
  if (text.size() < kHeader.size()) return {};
  EXPECT_EQ(text.substr(0, kCountOffset), kHeader.substr(0, kCountOffset));
  Contents contents;
  contents.counted = std::stoi(text.substr(kCountOffset, 8));
  std::size_t at = kHeader.size();
  for (int k = 0; k < contents.counted; ++k) {
    while (at < text.size() && text[at] == ' ') ++at;
    const std::string expected = line(k);
    EXPECT_EQ(text.compare(at, expected.size(), expected), 0) << "counted line " << k;
    at += expected.size();
  }
  contents.after = at < text.size() ? text.substr(at) : std::string();
  return contents;
}

// What may follow the counted lines after a kill: nothing, spaces, or the next line whole.
void expect_whole_or_spaces(const Contents& contents) {
  const std::size_t text = contents.after.find_first_not_of(' ');
  if (text == std::string::npos) return;
  EXPECT_EQ(contents.after.substr(text), line(contents.counted))
      << "after the " << contents.counted << " counted lines";
}

TEST(GrowingFile, PaddingMovesALineThatWouldCrossAPageToTheNextOne) {
  EXPECT_EQ(GrowingFile::padding_to_keep_in_one_page(0, 100), 0u);
  EXPECT_EQ(GrowingFile::padding_to_keep_in_one_page(4000, 96), 0u);   // ends on the boundary
  EXPECT_EQ(GrowingFile::padding_to_keep_in_one_page(4000, 97), 96u);  // would cross it
  EXPECT_EQ(GrowingFile::padding_to_keep_in_one_page(8190, 10), 2u);
  EXPECT_EQ(GrowingFile::padding_to_keep_in_one_page(100, 5000), 0u);  // longer than a page
}

TEST(GrowingFile, LinesAreCountedInTheHeaderAndNoneCrossesAPage) {
  const test::TempDir dir;
  const std::string path = dir.file("lines.txt");
  GrowingFile file(path, "test file", kHeader, false);
  for (int k = 0; k < 40; ++k) append(file, k);
  file.close();
  file.close();  // idempotent
  const Contents contents = read_counted(path);
  EXPECT_EQ(contents.counted, 40);
  EXPECT_EQ(contents.after, "");
  // Each line starts and ends in one page.
  const std::string text = test::read_file(path);
  for (std::size_t start = kHeader.size(); start < text.size();) {
    start = text.find_first_not_of(' ', start);
    const std::size_t end = text.find('\n', start);
    ASSERT_NE(end, std::string::npos);
    EXPECT_EQ(start / 4096, end / 4096) << "the line at byte " << start << " crosses a page";
    start = end + 1;
  }
  EXPECT_THROW(append(file, 40), std::logic_error);  // after close
}

TEST(GrowingFile, AWriterKilledAtAnyMomentLeavesItsCountedLinesWhole) {
  const test::TempDir dir;
  for (int run = 0; run < 6; ++run) {
    const std::string path = dir.file("killed" + std::to_string(run) + ".txt");
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {  // writes until killed
      try {
        GrowingFile file(path, "test file", kHeader, true);
        for (int k = 0;; ++k) append(file, k);
      } catch (...) {
        _exit(1);
      }
    }
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (!fs::exists(path) && std::chrono::steady_clock::now() < deadline)
      std::this_thread::yield();  // until the first line is in
    std::this_thread::sleep_for(std::chrono::milliseconds(3 + 7 * run));
    kill(child, SIGKILL);
    int status = 0;
    waitpid(child, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status)) << "the writer stopped by itself (run " << run << ")";
    const Contents contents = read_counted(path);
    EXPECT_GT(contents.counted, 0) << "run " << run;
    expect_whole_or_spaces(contents);
  }
}

// The file-size limit makes writes beyond it fail (EFBIG) as a full disk would.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    getrlimit(RLIMIT_FSIZE, &saved_);
    old_handler_ = signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{bytes, saved_.rlim_max};
    setrlimit(RLIMIT_FSIZE, &limit);
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &saved_);
    signal(SIGXFSZ, old_handler_);
  }
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;

 private:
  rlimit saved_{};
  sighandler_t old_handler_ = SIG_DFL;
};

TEST(GrowingFile, AFailedWriteIsCutBackAndALaterOneGoesOn) {
  const test::TempDir dir;
  const std::string path = dir.file("full.txt");
  GrowingFile file(path, "test file", kHeader, false);
  int k = 0;
  {
    const FileSizeLimit limit(6000);
    try {
      for (; k < 1000; ++k) append(file, k);
      FAIL() << "no write failed beyond the file-size limit";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path + ": cannot write the test file"),
                std::string::npos)
          << e.what();
    }
  }
  Contents contents = read_counted(path);
  EXPECT_EQ(contents.counted, k);
  EXPECT_EQ(contents.after, "") << "the failed line was not cut back";
  append(file, k);  // the limit lifted: the file goes on where it stood
  file.close();
  contents = read_counted(path);
  EXPECT_EQ(contents.counted, k + 1);
  EXPECT_EQ(contents.after, "");
}

TEST(GrowingFile, AFileThatCannotTakeItsHeaderIsRefusedNamingIt) {
  try {
    GrowingFile file("/dev/full", "test file", kHeader, false);
    FAIL() << "/dev/full took the header";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/full: cannot write the test file"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(GrowingFile("/no/such/folder/lines.txt", "test file", kHeader, false), InputError);
}

TEST(GrowingFile, ASuspendedFileIsReopenedByTheNextLineUnlessChangedMeanwhile) {
  const test::TempDir dir;
  const std::string path = dir.file("suspended.txt");
  GrowingFile file(path, "test file", kHeader, true);
  append(file, 0);
  file.suspend();
  EXPECT_FALSE(file.is_open());
  EXPECT_TRUE(file.is_suspended());
  EXPECT_EQ(read_counted(path).counted, 1);  // every line on disk while closed
  append(file, 1);
  EXPECT_TRUE(file.is_open());
  EXPECT_FALSE(file.is_suspended());
  EXPECT_EQ(read_counted(path).counted, 2);

  file.suspend();
  std::FILE* other = std::fopen(path.c_str(), "a");  // another program writes to it
  ASSERT_NE(other, nullptr);
  std::fputs("not a line of ours\n", other);
  std::fclose(other);
  try {
    append(file, 2);
    FAIL() << "a file changed while suspended was appended to";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("changed by another program"), std::string::npos)
        << e.what();
  }
}

TEST(GrowingFile, AppearsWithItsFirstLineOrReplacesAnOldFileWithAWholeHeader) {
  const test::TempDir dir;
  const std::string path = dir.file("new.txt");
  const int probe = ::open(dir.path().c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0644);
  if (probe < 0) GTEST_SKIP() << "no unnamed files (O_TMPFILE) in " << dir.path();
  ::close(probe);
  {
    GrowingFile file(path, "test file", kHeader, true);
    EXPECT_FALSE(fs::exists(path)) << "the file has a name before its first line";
    append(file, 0);
    EXPECT_EQ(read_counted(path).counted, 1);
  }
  {
    GrowingFile empty(dir.file("empty.txt"), "test file", kHeader, true);
  }  // asked for: a file without lines is linked when it closes
  EXPECT_EQ(test::read_file(dir.file("empty.txt")), kHeader);

  // An old file stays as it is until the new header is whole, then is replaced (no .part left).
  test::write_file(path, "old contents\n");
  GrowingFile file(path, "test file", kHeader, true);
  EXPECT_EQ(test::read_file(path), kHeader);
  EXPECT_FALSE(fs::exists(path + ".part"));
  append(file, 0);
  file.close();
  EXPECT_EQ(read_counted(path).counted, 1);
}

}  // namespace
}  // namespace mocap
