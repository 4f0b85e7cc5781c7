// video::Mp4Writer writes an MP4 that OpenCV decodes frame for frame, also when the writing
// process is killed (SIGKILL) mid-way, and says which file failed when the disk is full or the
// file size limit is reached; video::FrameReader gives the frames of a file or folder by index.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <thread>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "core/input_error.hpp"
#include "support/files.hpp"
#include "video/frame_reader.hpp"
#include "video/mp4_writer.hpp"

namespace mocap::video {
namespace {

namespace fs = std::filesystem;

// Frame k: a flat colour that says k (blue 8k, red 255 - 8k) with a white square moving across.
cv::Scalar colour_of(int k) { return {double(8 * k % 256), 128.0, double(255 - 8 * k % 256)}; }

ImageBuffer picture(int k, int width = 320, int height = 180) {
  ImageBuffer image(width, height, PixelFormat::bgr8);
  cv::Mat mat(height, width, CV_8UC3, image.pixels_for_writing().data(), image.stride());
  mat.setTo(colour_of(k));
  mat(cv::Rect((7 * k) % (width - 20), height / 3, 16, 16)).setTo(cv::Scalar(255, 255, 255));
  return image;
}

// The mean colour away from the square.
cv::Scalar corner_colour(const cv::Mat& frame) {
  return cv::mean(frame(cv::Rect(0, 0, frame.cols, frame.rows / 4)));
}

bool close_to(const cv::Scalar& a, const cv::Scalar& b, double tolerance = 3.0) {
  for (int c = 0; c < 3; ++c)
    if (std::abs(a[c] - b[c]) > tolerance) return false;
  return true;
}

// Decodes the file; every frame's colour must be that of its index.
int decoded_frames(const std::string& path, cv::Size* size = nullptr) {
  cv::VideoCapture video(path, cv::CAP_FFMPEG);
  if (!video.isOpened()) return -1;
  int frames = 0;
  for (cv::Mat frame; video.read(frame); ++frames) {
    if (size) *size = frame.size();
    EXPECT_TRUE(close_to(corner_colour(frame), colour_of(frames)))
        << path << " frame " << frames << ": " << corner_colour(frame);
  }
  return frames;
}

std::vector<Mp4Codec> codecs() {
  std::vector<Mp4Codec> out = {Mp4Codec::mpeg4};
  if (h264_available()) out.push_back(Mp4Codec::h264);
  return out;
}

TEST(Mp4Writer, ClosedFileDecodesToEveryFrameInEachCodec) {
  test::TempDir dir;
  if (!h264_available()) std::cout << "[ note ] no libx264 in this FFmpeg: MPEG-4 only\n";
  for (Mp4Codec codec : codecs()) {
    const std::string path =
        dir.file(std::string("clip_") + (codec == Mp4Codec::h264 ? "h264" : "mpeg4") + ".mp4");
    Mp4Writer writer(path, 320, 180, {10.0, codec});
    EXPECT_EQ(writer.codec_name(), codec == Mp4Codec::h264 ? "libx264" : "mpeg4");
    for (int k = 0; k < 25; ++k) writer.write(picture(k));
    writer.close();
    writer.close();  // idempotent
    cv::Size size;
    EXPECT_EQ(decoded_frames(path, &size), 25) << path;
    EXPECT_EQ(size, cv::Size(320, 180));
    cv::VideoCapture video(path, cv::CAP_FFMPEG);
    EXPECT_NEAR(video.get(cv::CAP_PROP_FPS), 10.0, 0.01);
  }
}

// A process killed before its first frame was written leaves no file, rather than one that holds
// a header and no picture: the file appears with its first frame, and plays from then on.
TEST(Mp4Writer, TheFileAppearsWithItsFirstFrame) {
  test::TempDir dir;
  for (Mp4Codec codec : codecs()) {
    const std::string path = dir.file(codec == Mp4Codec::h264 ? "h264.mp4" : "mpeg4.mp4");
    Mp4Writer writer(path, 320, 180, {10.0, codec});
    EXPECT_FALSE(fs::exists(path)) << "made before any frame";
    writer.write(picture(0));
    ASSERT_TRUE(fs::exists(path));
    EXPECT_EQ(decoded_frames(path), 1) << path;
    writer.write(picture(1));
    EXPECT_GE(decoded_frames(path), 1) << path;
  }
}

TEST(Mp4Writer, OddSizesLoseTheirLastColumnAndRowAnyPixelFormat) {
  test::TempDir dir;
  const std::string path = dir.file("odd.mp4");
  {
    Mp4Writer writer(path, 321, 181);
    ImageBuffer rgb(321, 181, PixelFormat::rgb8);  // red, given as RGB
    for (std::size_t i = 0; i < rgb.pixels_for_writing().size(); i += 3)
      rgb.pixels_for_writing()[i] = std::byte{220};
    writer.write(rgb);
    EXPECT_THROW(writer.write(picture(0)), std::invalid_argument);  // another size
  }                                                                 // closed by the destructor
  cv::VideoCapture video(path, cv::CAP_FFMPEG);
  cv::Mat frame;
  ASSERT_TRUE(video.read(frame));
  EXPECT_EQ(frame.size(), cv::Size(320, 180));
  EXPECT_TRUE(close_to(corner_colour(frame), {0, 0, 220}, 10)) << corner_colour(frame);
  EXPECT_THROW(Mp4Writer(dir.file("x.mp4"), 1, 100), std::invalid_argument);
  EXPECT_THROW(Mp4Writer(dir.file("x.mp4"), 100, 100, {0.0}), std::invalid_argument);
}

// A child process writes frames as fast as it can and tells the parent through a pipe after each
// write() returned; the parent kills it (SIGKILL) after a varying number of frames. The file
// decodes to at least every frame the child had reported (a frame being written at the kill may
// be lost, never an earlier one), each with its own colour.
TEST(Mp4Writer, FileOfAProcessKilledMidWriteDecodesToTheFramesWritten) {
  test::TempDir dir;
  for (Mp4Codec codec : codecs()) {
    for (int round = 0; round < 4; ++round) {
      const std::string path = dir.file("killed" + std::to_string(round) + ".mp4");
      int pipe_fds[2];
      ASSERT_EQ(pipe(pipe_fds), 0);
      const pid_t child = fork();
      ASSERT_GE(child, 0);
      if (child == 0) {
        close(pipe_fds[0]);
        try {
          Mp4Writer writer(path, 320, 180, {25.0, codec});
          for (int k = 0; k < 5000; ++k) {  // bounded: it can never run away
            writer.write(picture(k));
            if (write(pipe_fds[1], &k, sizeof k) != sizeof k) _exit(4);
          }
        } catch (...) {
          _exit(3);
        }
        _exit(2);
      }
      close(pipe_fds[1]);
      const int kill_after = 5 + 17 * round;
      int reported = -1;
      for (int k; reported + 1 < kill_after && read(pipe_fds[0], &k, sizeof k) == sizeof k;)
        reported = k;
      ASSERT_EQ(kill(child, SIGKILL), 0);
      int status = 0;
      ASSERT_EQ(waitpid(child, &status, 0), child);
      close(pipe_fds[0]);
      ASSERT_TRUE(WIFSIGNALED(status)) << "the child ended by itself, status " << status;
      ASSERT_EQ(reported + 1, kill_after);
      const int frames = decoded_frames(path);
      std::cout << "[ note ] " << (codec == Mp4Codec::h264 ? "H.264" : "MPEG-4")
                << ": killed after " << kill_after
                << " frames reported written; the file decodes to " << frames << "\n";
      EXPECT_GE(frames, kill_after) << path;
    }
  }
}

TEST(Mp4Writer, FullDiskIsAnErrorNamingTheFile) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full here";
  try {
    Mp4Writer writer("/dev/full", 320, 180);
    for (int k = 0; k < 10; ++k) writer.write(picture(k));
    writer.close();
    FAIL() << "writing to /dev/full succeeded";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/full"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("No space left"), std::string::npos) << e.what();
  }
}

// `ulimit -f`: a child with a 64 KiB file size limit (SIGXFSZ ignored, as `mocap run` does) gets
// an error naming the file; the child's exit code says what it saw.
TEST(Mp4Writer, FileSizeLimitIsAnErrorNamingTheFile) {
  test::TempDir dir;
  const std::string path = dir.file("limited.mp4");
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{64 * 1024, 64 * 1024};
    if (setrlimit(RLIMIT_FSIZE, &limit) != 0) _exit(5);
    try {
      Mp4Writer writer(path, 320, 180, {25.0, Mp4Codec::mpeg4});
      for (int k = 0; k < 2000; ++k) writer.write(picture(k));
      writer.close();
    } catch (const InputError& e) {
      const std::string what = e.what();
      _exit(what.find(path) != std::string::npos && what.find("too large") != std::string::npos
                ? 0
                : 6);
    } catch (...) {
      _exit(7);
    }
    _exit(8);  // 2000 frames fitted into 64 KiB: no error seen
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "5: no limit set, 6: message without the file or reason, "
                                       "7: another exception, 8: no error";
}

TEST(Mp4Writer, UncreatableFileIsAnErrorNamingIt) {
  test::TempDir dir;
  const std::string path = dir.file("no/such/folder/v.mp4");
  try {
    Mp4Writer writer(path, 320, 180);
    FAIL() << "created " << path;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

// --- frames by index

// A 40-frame clip of known colours.
std::string clip(const test::TempDir& dir, int frames = 40) {
  const std::string path = dir.file("clip.mp4");
  Mp4Writer writer(path, 320, 180, {25.0, Mp4Codec::mpeg4, 10});
  for (int k = 0; k < frames; ++k) writer.write(picture(k));
  writer.close();
  return path;
}

cv::Scalar colour_of_frame(const Frame& frame) {
  const cv::Mat mat(frame.image.height(), frame.image.width(), CV_8UC3,
                    const_cast<std::byte*>(frame.image.data()), frame.image.stride());
  return corner_colour(mat);
}

TEST(FrameReader, DecodesInOrderPassesOverGapsAndStartsAgainOnlyToGoBack) {
  test::TempDir dir;
  FrameReader reader(clip(dir));
  EXPECT_EQ(reader.width(), 320);
  for (int k : {0, 1, 2, 2, 3}) {
    const auto frame = reader.frame(k);
    ASSERT_TRUE(frame);
    EXPECT_EQ(frame->index, k);
    EXPECT_TRUE(close_to(colour_of_frame(*frame), colour_of(k))) << k;
  }
  EXPECT_EQ(reader.returned(), 4);  // frame 2 twice: decoded once
  EXPECT_EQ(reader.passed_over(), 0);
  ASSERT_TRUE(reader.frame(20));
  EXPECT_EQ(reader.passed_over(), 16);
  const auto back = reader.frame(7);
  ASSERT_TRUE(back);
  EXPECT_TRUE(close_to(colour_of_frame(*back), colour_of(7)));
  EXPECT_EQ(reader.reopened(), 1);
  EXPECT_TRUE(reader.frame(39));
  EXPECT_FALSE(reader.frame(40));  // past the end
  EXPECT_FALSE(reader.frame(-1));
  EXPECT_TRUE(reader.frame(39));  // the last one is still there
}

TEST(FrameReader, ImageFoldersByIndexAndLiveSourcesRefused) {
  test::TempDir dir;
  fs::create_directories(dir.file("images"));
  for (int k = 0; k < 12; ++k) {
    const ImageBuffer p = picture(k);
    const cv::Mat mat(p.height(), p.width(), CV_8UC3, const_cast<std::byte*>(p.data()), p.stride());
    cv::imwrite(dir.file("images/img" + std::to_string(k) + ".png"), mat);  // img2 before img10
  }
  FrameReader reader(dir.file("images"));
  for (int k : {10, 3, 11}) {
    const auto frame = reader.frame(k);
    ASSERT_TRUE(frame);
    EXPECT_TRUE(close_to(colour_of_frame(*frame), colour_of(k), 1.0)) << k;
  }
  EXPECT_THROW(FrameReader("/dev/video9"), InputError);
  EXPECT_THROW(FrameReader("rtsp://127.0.0.1:1/x"), InputError);
  EXPECT_THROW(FrameReader(dir.file("missing.mp4")), InputError);
}

}  // namespace
}  // namespace mocap::video
