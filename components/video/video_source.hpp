#pragma once
// Frames from a video file, a camera device (V4L2 through OpenCV), a network stream (RTSP/HTTP
// through OpenCV's FFmpeg backend) or a folder of numbered images, as bgr8 ImageBuffers with
// their capture timestamps. OpenCV stays inside the .cpp file.
//
// Outside input is not trusted: a missing, unreadable, truncated or damaged input and a camera
// that is absent or stops delivering all throw InputError naming the path, never crash or hang.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "core/image_buffer.hpp"

namespace mocap::video {

enum class SourceKind { file, device, network, image_folder };
std::string_view name(SourceKind kind);

// What a source string names: "/dev/videoN" or a bare number a camera device; rtsp://, rtsps://,
// http://, https://, rtmp://, udp:// or tcp:// a network stream; an existing folder a folder of
// images; anything else a video file. Decided from the string (and for folders, the file system).
SourceKind classify(const std::string& source);

// True for the image files a folder source reads (by extension, case-insensitive).
bool is_image_file_name(std::string_view file_name);

// Whether SourceOptions::decoder_threads takes effect: it needs OpenCV 4.7 (CAP_PROP_N_THREADS);
// older OpenCV's FFmpeg backend decodes with one thread per core.
bool decoder_threads_supported();

struct SourceOptions {
  // FFmpeg decoding threads for files and network streams (0: FFmpeg's default, one per core).
  // Decoding competes with the detector for the cores.
  int decoder_threads = 0;
  // The frame rate of an image folder (its images carry none); 30 when 0.
  double folder_fps = 0.0;
  // Camera devices: the mode asked for (0: the device's current one).
  int width = 0, height = 0;
  double fps = 0.0;
  // Network streams: how long opening and each read may take. Opening includes FFmpeg's look at
  // the stream (about 33 frames of an RTSP H.264 camera: 3.3 s at 10 fps), so keep it longer.
  int timeout_ms = 10000;
};

struct Frame {
  ImageBuffer image;            // bgr8
  std::int64_t index = 0;       // position in the source, counting skipped frames, from 0
  double media_time_s = 0.0;    // presentation time in the source (files, folders: from 0)
  std::int64_t capture_ns = 0;  // CLOCK_REALTIME when it was captured (devices: the driver's
                                // buffer timestamp when it has one) or read (files, folders)
};

class VideoSource {
 public:
  // Opens the source and decodes its first frame; throws InputError naming it when that fails.
  explicit VideoSource(std::string source, SourceOptions options = {});
  ~VideoSource();
  VideoSource(VideoSource&&) noexcept;
  VideoSource& operator=(VideoSource&&) noexcept;

  // The next frame; nullopt at the end of a file, folder or network stream (a live stream whose
  // server closed it, went away or stopped sending for timeout_ms: the frames FFmpeg still held
  // come first; video::Playback reopens a live stream). Throws InputError
  // when a file, or a file served over a network stream, ends well before the frames its
  // container announces (truncated, connection lost), an image
  // of a folder cannot be read, or a camera device stops delivering (unplugged).
  std::optional<Frame> read();
  // Passes over the next frame without converting it (a live file source that fell behind);
  // false at the end. Same errors as read().
  bool skip();

  const std::string& source() const;
  SourceKind kind() const;
  bool live() const;  // a camera device or network stream: it runs whether or not it is read
  int width() const;
  int height() const;
  double fps() const;                // 0 when the source does not say
  std::int64_t frame_count() const;  // -1 when unknown (devices, live streams)
  std::int64_t frames_read() const;  // returned or skipped so far
  // Frames the file's container announces that could not be decoded (damaged frames FFmpeg
  // passed over), known once read() or skip() has reached the end; 0 before that and for other
  // sources. More than a tenth of the announced frames missing is a truncated file (an error).
  std::int64_t frames_undecodable() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mocap::video
