#include "video/mp4_writer.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <stdexcept>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/opt.h>
#include <libavutil/rational.h>
#include <libswscale/swscale.h>
}

#include "core/input_error.hpp"

namespace mocap::video {
namespace {

std::string av_error(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, text, sizeof text);
  return text;
}

// The muxer's output (format->pb is ours: AVFMT_FLAG_CUSTOM_IO, so it is never closed for us).
struct FormatDeleter {
  void operator()(AVFormatContext* f) const { avformat_free_context(f); }
};
struct AvioDeleter {
  void operator()(AVIOContext* io) const {
    av_freep(&io->buffer);
    avio_context_free(&io);
  }
};

// The file behind the muxer, created only once its first fragment is complete: until then the
// header is held here, so a process killed before its first frame is on disk leaves no file
// rather than one that holds no picture (nothing can play it). `position` runs on from the
// header, as the muxer's offsets expect.
class DeferredFile {
 public:
  explicit DeferredFile(std::string path) : path_(std::move(path)) {}
  ~DeferredFile() {
    if (fd_ >= 0) ::close(fd_);
  }
  DeferredFile(const DeferredFile&) = delete;
  DeferredFile& operator=(const DeferredFile&) = delete;

  // AVIOContext's write callback; an error is an AVERROR code the muxer keeps in pb->error.
#if LIBAVFORMAT_VERSION_MAJOR >= 61
  static int write_packet(void* self, const std::uint8_t* data, int size) {
#else
  static int write_packet(void* self, std::uint8_t* data, int size) {
#endif
    return static_cast<DeferredFile*>(self)->write(data, static_cast<std::size_t>(size));
  }
  // Creates the file with what was held back; 0 or an AVERROR code.
  int create() {
    if (fd_ >= 0) return 0;
    fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd_ < 0) return AVERROR(errno);
    const int r = write_all(reinterpret_cast<const std::uint8_t*>(held_.data()), held_.size());
    held_ = {};
    return r;
  }

 private:
  int write(const std::uint8_t* data, std::size_t size) {
    if (fd_ < 0) {
      held_.append(reinterpret_cast<const char*>(data), size);
      return static_cast<int>(size);
    }
    const int r = write_all(data, size);
    return r < 0 ? r : static_cast<int>(size);
  }
  int write_all(const std::uint8_t* data, std::size_t size) {
    while (size > 0) {
      const ssize_t n = ::write(fd_, data, size);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) return AVERROR(errno);
      data += n;
      size -= static_cast<std::size_t>(n);
    }
    return 0;
  }
  std::string path_;
  std::string held_;
  int fd_ = -1;
};
struct EncoderDeleter {
  void operator()(AVCodecContext* c) const { avcodec_free_context(&c); }
};
struct FrameDeleter {
  void operator()(AVFrame* f) const { av_frame_free(&f); }
};
struct PacketDeleter {
  void operator()(AVPacket* p) const { av_packet_free(&p); }
};
struct ScaleDeleter {
  void operator()(SwsContext* s) const { sws_freeContext(s); }
};

AVPixelFormat av_pixel_format(PixelFormat format) {
  switch (format) {
    case PixelFormat::gray8:
      return AV_PIX_FMT_GRAY8;
    case PixelFormat::rgb8:
      return AV_PIX_FMT_RGB24;
    case PixelFormat::bgr8:
      return AV_PIX_FMT_BGR24;
    case PixelFormat::rgba8:
      return AV_PIX_FMT_RGBA;
    case PixelFormat::bgra8:
      return AV_PIX_FMT_BGRA;
  }
  return AV_PIX_FMT_NONE;
}

// libx264 reports its CPU, profile and statistics at FFmpeg's default level (info) on stderr,
// once per file; warnings and errors stay. FFmpeg's log level is process-wide, and OpenCV's video
// backend lowers it the same way; it is only ever lowered here.
void quiet_ffmpeg_info_lines() {
  static std::once_flag once;
  std::call_once(once, [] {
    if (av_log_get_level() > AV_LOG_WARNING) av_log_set_level(AV_LOG_WARNING);
  });
}

const AVCodec* h264_encoder() { return avcodec_find_encoder_by_name("libx264"); }

}  // namespace

bool h264_available() { return h264_encoder() != nullptr; }

struct Mp4Writer::Impl {
  std::string path;
  Mp4WriterOptions options;
  int width = 0, height = 0;              // the pictures' size
  int coded_width = 0, coded_height = 0;  // even
  std::unique_ptr<DeferredFile> file;
  std::unique_ptr<AVIOContext, AvioDeleter> output;  // writes to `file`
  std::unique_ptr<AVFormatContext, FormatDeleter> format;
  std::unique_ptr<AVCodecContext, EncoderDeleter> encoder;
  AVStream* stream = nullptr;
  std::unique_ptr<AVFrame, FrameDeleter> yuv;
  std::unique_ptr<AVPacket, PacketDeleter> packet;
  std::unique_ptr<SwsContext, ScaleDeleter> convert;  // for pictures of `convert_from`
  AVPixelFormat convert_from = AV_PIX_FMT_NONE;
  std::int64_t frames = 0;
  bool closed = false;

  [[noreturn]] void fail(const std::string& what, int code) const {
    throw InputError(path, what + ": " + av_error(code));
  }
  [[noreturn]] void fail(const std::string& what) const { throw InputError(path, what); }

  void open_encoder() {
    const AVCodec* codec = options.codec == Mp4Codec::mpeg4 ? nullptr : h264_encoder();
    if (!codec && options.codec == Mp4Codec::h264)
      fail("H.264 asked for, but this FFmpeg has no libx264 encoder");
    if (!codec) codec = avcodec_find_encoder(AV_CODEC_ID_MPEG4);
    if (!codec) fail("this FFmpeg has neither the libx264 nor the MPEG-4 encoder");
    encoder.reset(avcodec_alloc_context3(codec));
    if (!encoder) throw std::bad_alloc();
    AVCodecContext& c = *encoder;
    c.width = coded_width;
    c.height = coded_height;
    c.pix_fmt = AV_PIX_FMT_YUV420P;
    c.sample_aspect_ratio = {1, 1};
    // MPEG-4 Part 2 allows time-base denominators up to 65535 (29.97 fps: 2997/100).
    c.framerate = av_d2q(options.fps, 65535);
    c.time_base = av_inv_q(c.framerate);
    c.gop_size = options.keyframe_interval > 0
                     ? options.keyframe_interval
                     : std::max(1, static_cast<int>(std::lround(options.fps)));
    c.max_b_frames = 0;  // B-frames hold frames back in the encoder: lost when killed
    c.thread_count = std::max(0, options.threads);
    c.color_range = AVCOL_RANGE_MPEG;  // what swscale makes of RGB by default (BT.601, limited)
    c.colorspace = AVCOL_SPC_SMPTE170M;
    if (format->oformat->flags & AVFMT_GLOBALHEADER) c.flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
    if (codec->id == AV_CODEC_ID_H264) {
      // zerolatency: no look-ahead, no B-frames, sliced threads: a frame leaves the encoder as
      // soon as it went in, so the file on disk is never more than a frame behind.
      if (av_opt_set(c.priv_data, "preset", options.h264_preset.c_str(), 0) < 0)
        fail("unknown H.264 preset '" + options.h264_preset + "'");
      av_opt_set(c.priv_data, "tune", "zerolatency", 0);
      av_opt_set(c.priv_data, "crf", "23", 0);
    } else {
      c.flags |= AV_CODEC_FLAG_QSCALE;
      c.global_quality = FF_QP2LAMBDA * 4;
    }
    // libx264 checks the preset only here: name it, the likeliest wrong setting.
    if (const int r = avcodec_open2(&c, codec, nullptr); r < 0)
      fail(std::string("cannot open the ") + codec->name + " encoder" +
               (codec->id == AV_CODEC_ID_H264 ? " (preset '" + options.h264_preset + "')" : ""),
           r);
  }

  void open() {
    quiet_ffmpeg_info_lines();
    AVFormatContext* f = nullptr;
    if (const int r = avformat_alloc_output_context2(&f, nullptr, "mp4", nullptr); r < 0)
      fail("cannot make an MP4 muxer", r);
    format.reset(f);
    open_encoder();
    stream = avformat_new_stream(format.get(), nullptr);
    if (!stream) throw std::bad_alloc();
    stream->time_base = encoder->time_base;
    stream->avg_frame_rate = encoder->framerate;
    if (const int r = avcodec_parameters_from_context(stream->codecpar, encoder.get()); r < 0)
      fail("cannot describe the video stream", r);
    check_folder();
    file = std::make_unique<DeferredFile>(path);
    constexpr int kBufferBytes = 64 * 1024;
    auto* buffer = static_cast<unsigned char*>(av_malloc(kBufferBytes));
    if (!buffer) throw std::bad_alloc();
    output.reset(avio_alloc_context(buffer, kBufferBytes, 1, file.get(), nullptr,
                                    &DeferredFile::write_packet, nullptr));
    if (!output) {
      av_free(buffer);
      throw std::bad_alloc();
    }
    format->pb = output.get();
    format->flags |= AVFMT_FLAG_CUSTOM_IO;
    // Fragmented: the index (moov) first and empty, each frame a fragment (moof + mdat) flushed
    // by write() below; default_base_moof makes fragments self-contained (browsers want it).
    AVDictionary* muxer_options = nullptr;
    av_dict_set(&muxer_options, "movflags", "empty_moov+default_base_moof+frag_custom", 0);
    const int r = avformat_write_header(format.get(), &muxer_options);
    av_dict_free(&muxer_options);
    if (r < 0) fail("cannot write the video's header", r);
    yuv.reset(av_frame_alloc());
    packet.reset(av_packet_alloc());
    if (!yuv || !packet) throw std::bad_alloc();
    yuv->format = AV_PIX_FMT_YUV420P;
    yuv->width = coded_width;
    yuv->height = coded_height;
    if (const int e = av_frame_get_buffer(yuv.get(), 0); e < 0) fail("cannot allocate a frame", e);
  }

  // The file is made at the first frame; its folder must take it now, so a bad path fails here.
  void check_folder() const {
    namespace fs = std::filesystem;
    const fs::path folder = fs::path(path).parent_path();
    std::error_code ec;
    if (!folder.empty() && !fs::is_directory(folder, ec))
      fail("cannot create the video file: no folder " + folder.string());
    if (::access(folder.empty() ? "." : folder.c_str(), W_OK | X_OK) != 0)
      fail(std::string("cannot create the video file: ") + std::strerror(errno));
  }

  // Everything the muxer holds goes to the operating system, which keeps it if the process dies
  // (the file made, with its header, when the first fragment is complete).
  void flush() {
    avio_flush(format->pb);
    if (format->pb->error < 0) fail("cannot write the video", format->pb->error);
    if (const int r = file->create(); r < 0) fail("cannot create the video file", r);
  }

  // Writes every packet the encoder has ready, each as its own fragment.
  void drain() {
    for (;;) {
      int r = avcodec_receive_packet(encoder.get(), packet.get());
      if (r == AVERROR(EAGAIN) || r == AVERROR_EOF) return;
      if (r < 0) fail("cannot encode the video", r);
      av_packet_rescale_ts(packet.get(), encoder->time_base, stream->time_base);
      packet->stream_index = stream->index;
      r = av_write_frame(format.get(), packet.get());
      av_packet_unref(packet.get());
      if (r < 0) fail("cannot write the video", r);
      // Closes the fragment now instead of when the next packet comes.
      if (r = av_write_frame(format.get(), nullptr); r < 0) fail("cannot write the video", r);
      flush();
    }
  }

  void convert_picture(const ImageBuffer& picture) {
    const AVPixelFormat from = av_pixel_format(picture.format());
    if (!convert || from != convert_from) {
      convert.reset(sws_getContext(coded_width, coded_height, from, coded_width, coded_height,
                                   AV_PIX_FMT_YUV420P, SWS_BILINEAR | SWS_ACCURATE_RND, nullptr,
                                   nullptr, nullptr));
      if (!convert) fail("cannot convert " + std::string(name(picture.format())) + " pictures");
      convert_from = from;
    }
    if (const int r = av_frame_make_writable(yuv.get()); r < 0) fail("cannot reuse a frame", r);
    const auto* rows = reinterpret_cast<const std::uint8_t*>(picture.data());
    const std::uint8_t* const source[4] = {rows, nullptr, nullptr, nullptr};
    const int source_stride[4] = {picture.stride(), 0, 0, 0};
    // Only the even part of an odd picture is read (its last column or row is left out).
    sws_scale(convert.get(), source, source_stride, 0, coded_height, yuv->data, yuv->linesize);
  }

  void finish() {
    if (closed) return;
    closed = true;
    if (const int r = avcodec_send_frame(encoder.get(), nullptr); r < 0)
      fail("cannot finish the encoding", r);
    drain();
    if (const int r = av_write_trailer(format.get()); r < 0) fail("cannot finish the video", r);
    flush();
  }
};

Mp4Writer::Mp4Writer(std::string path, int width, int height, Mp4WriterOptions options)
    : impl_(std::make_unique<Impl>()) {
  if (width < 2 || height < 2)
    throw std::invalid_argument("mp4 writer: pictures must be at least 2 x 2 pixels");
  if (!(options.fps > 0.0) || !std::isfinite(options.fps))
    throw std::invalid_argument("mp4 writer: the frame rate must be positive");
  Impl& w = *impl_;
  w.path = std::move(path);
  w.options = options;
  w.width = width;
  w.height = height;
  w.coded_width = width & ~1;
  w.coded_height = height & ~1;
  w.open();
}

Mp4Writer::~Mp4Writer() {
  if (!impl_ || impl_->closed || !impl_->format) return;
  try {
    impl_->finish();
  } catch (...) {
    // Destroyed without close(), e.g. while another error unwinds: the fragments written so far
    // already make a playable file; this error is not the first one.
  }
}

void Mp4Writer::write(const ImageBuffer& picture) {
  Impl& w = *impl_;
  if (w.closed) throw std::logic_error("mp4 writer: write after close");
  if (picture.width() != w.width || picture.height() != w.height)
    throw std::invalid_argument("mp4 writer: picture size changed during the video");
  w.convert_picture(picture);
  w.yuv->pts = w.frames;
  if (const int r = avcodec_send_frame(w.encoder.get(), w.yuv.get()); r < 0)
    w.fail("cannot encode the video", r);
  w.drain();
  ++w.frames;
}

void Mp4Writer::close() { impl_->finish(); }

const std::string& Mp4Writer::path() const { return impl_->path; }
std::int64_t Mp4Writer::frames() const { return impl_->frames; }
std::string_view Mp4Writer::codec_name() const { return impl_->encoder->codec->name; }

}  // namespace mocap::video
