// The TRC writer: what it writes reads back (io/trc.hpp), its layout is Pose2Sim's own (the demo's
// TRC beside it), and a writer killed at any moment leaves a file the reader takes.

#include "io/trc_writer.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "core/input_error.hpp"
#include "io/read_file.hpp"
#include "io/trc.hpp"
#include "support/files.hpp"
#include "support/shared_data.hpp"

namespace mocap::io {
namespace {

constexpr float kNan = std::numeric_limits<float>::quiet_NaN();

std::vector<std::string> lines_of(const std::string& text, std::size_t count) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; out.size() < count && std::getline(in, line);) out.push_back(line);
  return out;
}

std::vector<std::string> cells(const std::string& line) {
  std::vector<std::string> out;
  std::size_t start = 0;
  for (auto tab = line.find('\t');; tab = line.find('\t', start)) {
    out.push_back(line.substr(start, tab == std::string::npos ? tab : tab - start));
    if (tab == std::string::npos) break;
    start = tab + 1;
  }
  return out;
}

bool number(const std::string& cell, double& v) {
  char* end = nullptr;
  v = std::strtod(cell.c_str(), &end);
  return end != cell.c_str() && std::string(end).find_first_not_of(' ') == std::string::npos;
}

TrcLayout two_markers() {
  TrcLayout layout;
  layout.rate = 60.0;
  layout.markers = {"RHip", "LHip"};
  layout.first_frame = 5;
  return layout;
}

TEST(TrcWriter, StreamReadsBackWithMissingMarkersAndFrameNumbers) {
  test::TempDir dir;
  const std::string path = dir.file("p.trc");
  TrcStreamWriter writer(path, two_markers());
  EXPECT_EQ(read_trc(path).frames.size(), 0u);  // valid with its header alone
  const std::vector<glm::vec3> a = {{0.1f, 1.2f, -3.5f}, {kNan, 0.0f, 0.0f}};
  const std::vector<glm::vec3> b = {{0.2f, 1.25f, -3.25f}, {1.0f, 2.0f, 3.0f}};
  writer.append(a);
  writer.append(b);
  writer.close();
  const TrcFile f = read_trc(path);
  EXPECT_EQ(f.rate, 60.0);
  ASSERT_EQ(f.markers, two_markers().markers);
  ASSERT_EQ(f.frames.size(), 2u);
  EXPECT_NEAR(f.frames[0][0].z, -3.5f, 1e-6f);
  EXPECT_TRUE(std::isnan(f.frames[0][1].x));
  EXPECT_NEAR(f.frames[1][1].y, 2.0f, 1e-6f);
  // Frame# counts on from first_frame; Time = Frame# / DataRate, as Pose2Sim writes it.
  const auto rows = lines_of(read_whole_file(path, 1 << 20), 7);
  EXPECT_EQ(cells(rows[5])[0], "5");
  EXPECT_NEAR(std::stod(cells(rows[6])[1]), 6.0 / 60.0, 1e-12);
  EXPECT_EQ(cells(rows[2])[6], "4");  // OrigDataStartFrame: Frame# - 1 of the first row
  // The same frames written at once are the same file.
  const std::vector<std::vector<glm::vec3>> frames = {a, b};
  EXPECT_EQ(format_trc("p.trc", two_markers(), frames), read_whole_file(path, 1 << 20));
}

TEST(TrcWriter, LayoutIsPose2SimsOwn) {
  MOCAP_REQUIRE_SHARED("eval/pose2sim_demo/S00_P00_T01_BalancingTrial/pose-3d");
  const auto theirs_path = test::shared_data() /
                           "eval/pose2sim_demo/S00_P00_T01_BalancingTrial/pose-3d/"
                           "S00_P00_T01_BalancingTrial_0-100.trc";
  const std::string theirs_text = read_whole_file(theirs_path, 8 << 20);
  const TrcFile theirs = parse_trc(theirs_text, theirs_path.string());
  TrcLayout layout;
  layout.rate = theirs.rate;
  layout.markers = theirs.markers;
  layout.first_frame = 1;
  const std::string ours_text = format_trc(theirs_path.filename().string(), layout, theirs.frames);
  const auto ours_lines = lines_of(ours_text, 6), their_lines = lines_of(theirs_text, 6);
  ASSERT_EQ(ours_lines.size(), 6u);
  for (std::size_t l = 0; l < 6; ++l) {
    const auto ours = cells(ours_lines[l]), their = cells(their_lines[l]);
    ASSERT_EQ(ours.size(), their.size()) << "line " << l + 1;
    for (std::size_t c = 0; c < ours.size(); ++c) {
      double a = 0.0, b = 0.0;
      if (number(ours[c], a) && number(their[c], b)) {  // ours padded, to the micrometre
        EXPECT_NEAR(a, b, 1e-6) << "line " << l + 1 << " cell " << c;
      } else {
        EXPECT_EQ(ours[c], their[c]) << "line " << l + 1 << " cell " << c;
      }
    }
  }
  const TrcFile back = parse_trc(ours_text, "ours.trc");
  ASSERT_EQ(back.frames.size(), theirs.frames.size());
  for (std::size_t f = 0; f < back.frames.size(); ++f)
    for (std::size_t m = 0; m < back.markers.size(); ++m)
      EXPECT_NEAR(glm::length(back.frames[f][m] - theirs.frames[f][m]), 0.0f, 2e-6f);
}

TEST(TrcWriter, KilledWriterLeavesAReadableFile) {
  test::TempDir dir;
  const std::string path = dir.file("killed.trc");
  for (int run = 0; run < 3; ++run) {
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      TrcLayout layout;
      layout.markers.assign(15, "M");
      for (std::size_t m = 0; m < layout.markers.size(); ++m)
        layout.markers[m] += std::to_string(m);
      TrcStreamWriter writer(path, layout);
      std::vector<glm::vec3> row(15, glm::vec3(1.5f, -2.25f, 0.125f));
      for (long i = 0;; ++i) writer.append(row);  // until killed
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(30 + 25 * run));
    kill(child, SIGKILL);
    int status = 0;
    waitpid(child, &status, 0);
    const TrcFile f = read_trc(path);  // throws if the kill left it invalid
    EXPECT_GT(f.frames.size(), 0u);
    for (const auto& frame : f.frames) EXPECT_EQ(frame[14].y, -2.25f);
  }
}

TEST(TrcWriter, OneUncountedLastRowIsIgnoredTwoAreAnError) {
  const std::vector<std::vector<glm::vec3>> one = {{{1, 2, 3}, {4, 5, 6}}};
  const std::string text = format_trc("x.trc", two_markers(), one);
  const std::string extra = "6\t0.1\t1\t2\t3\t4\t5\t6\n";
  EXPECT_EQ(parse_trc(text + extra, "x.trc").frames.size(), 1u);
  EXPECT_EQ(parse_trc(text + extra.substr(0, 7), "x.trc").frames.size(), 1u);  // cut short
  EXPECT_THROW(parse_trc(text + extra + extra, "x.trc"), InputError);
}

TEST(TrcWriter, ErrorsNameTheFile) {
  try {
    TrcStreamWriter writer("/nonexistent-folder/p.trc", two_markers());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-folder/p.trc"), std::string::npos);
  }
  test::TempDir dir;
  TrcStreamWriter writer(dir.file("w.trc"), two_markers());
  EXPECT_THROW(writer.append(std::vector<glm::vec3>(3)), std::invalid_argument);
}

}  // namespace
}  // namespace mocap::io
