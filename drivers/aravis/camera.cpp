#include "camera.hpp"

#include <arv.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <stdexcept>

#include "pixel_conversion.hpp"

namespace mocap::aravis {
namespace {

// GObjects are reference counted; a unique_ptr holds exactly one reference.
struct GObjectUnref {
  void operator()(void* object) const {
    if (object) g_object_unref(object);
  }
};
template <class T>
using GPtr = std::unique_ptr<T, GObjectUnref>;

// The GError out-parameter of an Aravis call: freed on every path, turned into an exception
// naming the camera and what was being done.
class ErrorSlot {
 public:
  ErrorSlot() = default;
  ~ErrorSlot() { clear(); }
  ErrorSlot(const ErrorSlot&) = delete;
  ErrorSlot& operator=(const ErrorSlot&) = delete;
  GError** out() {
    clear();
    return &error_;
  }
  bool failed() const { return error_ != nullptr; }
  void throw_if_failed(const std::string& camera, const std::string& what) {
    if (!error_) return;
    const std::string message = "camera '" + camera + "': " + what + ": " + error_->message;
    clear();
    throw std::runtime_error(message);
  }

 private:
  void clear() {
    if (error_) g_error_free(error_);
    error_ = nullptr;
  }
  GError* error_ = nullptr;
};

std::string text(const char* s) { return s ? s : ""; }

// Stream buffers back the camera at every frame rate: about half a second of frames.
int pool_size(const CameraSettings& settings, double frame_rate) {
  if (settings.buffers > 0) return settings.buffers;
  return std::clamp(static_cast<int>(std::ceil(frame_rate * 0.5)), 4, 64);
}

// Camera ids, serials and addresses all name a camera for the user; Aravis opens by id. Empty
// `wanted`: the first camera found.
std::optional<DeviceInfo> discover(const std::string& wanted) {
  for (const DeviceInfo& device : list_devices()) {
    if (wanted.empty() || device.id == wanted || device.serial == wanted ||
        device.address == wanted)
      return device;
  }
  return std::nullopt;
}

using FakeFill = std::function<void(std::span<std::byte>, int, int)>;

void on_control_lost(ArvDevice*, gpointer flag) {
  static_cast<std::atomic<bool>*>(flag)->store(true);  // Aravis' heartbeat thread
}

}  // namespace

// Aravis' device list is one global table that arv_update_device_list rebuilds: every use of it
// (discovery, opening by id) takes this lock, so two camera nodes can reconnect at once.
namespace {
std::mutex& device_list_mutex() {
  static std::mutex mutex;
  return mutex;
}
}  // namespace

std::vector<DeviceInfo> list_devices() {
  const std::lock_guard lock(device_list_mutex());
  arv_update_device_list();
  std::vector<DeviceInfo> devices;
  const unsigned n = arv_get_n_devices();
  for (unsigned i = 0; i < n; ++i) {
    devices.push_back({text(arv_get_device_id(i)), text(arv_get_device_vendor(i)),
                       text(arv_get_device_model(i)), text(arv_get_device_serial_nbr(i)),
                       text(arv_get_device_address(i)), text(arv_get_device_protocol(i))});
  }
  return devices;
}

void enable_fake_interface() {
  const std::lock_guard lock(device_list_mutex());
  arv_enable_interface("Fake");
}

struct Camera::Impl {
  DeviceInfo info;
  std::string label;   // how errors name the camera
  FakeFill fake_fill;  // declared first, so it outlives the camera and stream that call it
  GPtr<ArvCamera> camera;
  GPtr<ArvStream> stream;
  gulong lost_handler = 0;
  std::size_t payload = 0;  // bytes of each stream buffer
  std::atomic<bool> lost{false};
  CameraFormat format = CameraFormat::mono8;
  int buffers = 0;
  StreamCounters counters;
  std::optional<std::uint64_t> last_id;  // of the last complete frame
  std::uint64_t incomplete_since_last = 0;
  std::optional<std::int64_t> clock_offset;  // min(arrival - device time), see Camera::next
  // The stream watchdog (CameraSettings::loss_timeout): when the last buffer (or the start) was.
  std::chrono::steady_clock::duration loss_timeout{};
  std::chrono::steady_clock::time_point last_buffer;
  bool any_buffer = false;
  std::string loss_reason;  // set by the thread calling next(); the heartbeat sets `lost` only

  ~Impl() {
    if (camera && stream && !lost) {
      ErrorSlot ignored;  // closing: a camera that no longer answers is not an error here
      arv_camera_stop_acquisition(camera.get(), ignored.out());
    }
    stream.reset();  // joins the stream's receiving thread
    if (camera && lost_handler)
      g_signal_handler_disconnect(arv_camera_get_device(camera.get()), lost_handler);
  }

  void open(const CameraSettings& settings);
  void install_fake_fill(const FakeFill& fill);
  ArvFakeCamera* fake_camera();
  void set_fake_pixel_format(std::uint32_t pfnc);
  void ensure_control();
  static void fill_fake_buffer(ArvBuffer* buffer, void* self, guint32, guint32, ArvPixelFormat);
  void apply(const CameraSettings& settings);
  void start(const CameraSettings& settings);
  std::optional<Frame> take(ArvBuffer* buffer);
  bool watchdog_expired(std::chrono::steady_clock::time_point now);
  void track_complete_id(std::uint64_t id);
};

void Camera::Impl::open(const CameraSettings& settings) {
  label = settings.id.empty() ? "first found" : settings.id;
  // Not discovered (e.g. another subnet, or none at all): Aravis still tries the name itself.
  const auto found = discover(settings.id);
  const std::string id = found ? found->id : settings.id;
  ErrorSlot error;
  {
    const std::lock_guard lock(device_list_mutex());
    camera.reset(arv_camera_new(id.empty() ? nullptr : id.c_str(), error.out()));
  }
  error.throw_if_failed(label, "cannot open");
  if (!camera) throw std::runtime_error("camera '" + label + "': cannot open (not found)");
  if (found) {
    info = *found;
  } else {
    info.id = text(arv_camera_get_device_id(camera.get(), error.out()));
    info.vendor = text(arv_camera_get_vendor_name(camera.get(), error.out()));
    info.model = text(arv_camera_get_model_name(camera.get(), error.out()));
    info.serial = text(arv_camera_get_device_serial_number(camera.get(), error.out()));
  }
  if (settings.id.empty()) label = info.id;
  ensure_control();
  if (settings.fake_fill) install_fake_fill(settings.fake_fill);
  lost_handler = g_signal_connect(arv_camera_get_device(camera.get()), "control-lost",
                                  G_CALLBACK(on_control_lost), &lost);
}

// Aravis opens a GigE camera it could not take control of (a slow answer on a busy host, or
// another application holding it) read-only, without an error; streaming then fails with a
// vaguer one. Two more attempts, then an error that says what is wrong.
void Camera::Impl::ensure_control() {
  ArvDevice* device = arv_camera_get_device(camera.get());
  if (!ARV_IS_GV_DEVICE(device)) return;
  auto* gv = ARV_GV_DEVICE(device);
  for (int attempt = 0; attempt < 2 && !arv_gv_device_is_controller(gv); ++attempt) {
    ErrorSlot ignored;  // the check after the loop reports the outcome
    arv_gv_device_take_control(gv, ignored.out());
  }
  if (!arv_gv_device_is_controller(gv)) {
    throw std::runtime_error("camera '" + label +
                             "': cannot take control of it (is another application using it?)");
  }
}

ArvFakeCamera* Camera::Impl::fake_camera() {
  ArvDevice* device = arv_camera_get_device(camera.get());
  if (!ARV_IS_FAKE_DEVICE(device))
    throw std::runtime_error("camera '" + label + "' is not Aravis' in-process fake camera");
  return arv_fake_device_get_fake_camera(ARV_FAKE_DEVICE(device));
}

void Camera::Impl::install_fake_fill(const FakeFill& fill) {
  ArvFakeCamera* fake = fake_camera();
  fake_fill = fill;
  arv_fake_camera_set_fill_pattern(fake, fill_fake_buffer, this);
}

void Camera::Impl::set_fake_pixel_format(std::uint32_t pfnc) {
  if (!arv_fake_camera_write_register(fake_camera(), ARV_FAKE_CAMERA_REGISTER_PIXEL_FORMAT, pfnc))
    throw std::runtime_error("camera '" + label + "': cannot write the fake pixel format");
}

// Called by the fake camera for every frame, on its streaming thread, after it has set the
// buffer's geometry. Only Aravis' own patterns can set the received size, so with ours the buffer
// reports 0 bytes: its whole allocation (`payload`, fixed before acquisition started) is the image.
void Camera::Impl::fill_fake_buffer(ArvBuffer* buffer, void* self, guint32, guint32,
                                    ArvPixelFormat) {
  const auto* impl = static_cast<const Impl*>(self);
  auto* data = static_cast<std::byte*>(const_cast<void*>(arv_buffer_get_data(buffer, nullptr)));
  impl->fake_fill({data, impl->payload}, arv_buffer_get_image_width(buffer),
                  arv_buffer_get_image_height(buffer));
}

void Camera::Impl::apply(const CameraSettings& settings) {
  ErrorSlot error;
  ArvCamera* cam = camera.get();
  if (settings.fake_pixel_format != 0) {
    set_fake_pixel_format(settings.fake_pixel_format);  // instead of settings.pixel_format
  } else if (!settings.pixel_format.empty()) {
    arv_camera_set_pixel_format_from_string(cam, settings.pixel_format.c_str(), error.out());
    error.throw_if_failed(label, "cannot set pixel format " + settings.pixel_format);
  }
  const auto pfnc = static_cast<std::uint32_t>(arv_camera_get_pixel_format(cam, error.out()));
  error.throw_if_failed(label, "cannot read the pixel format");
  const auto supported = camera_format_from_code(pfnc);
  if (!supported) {
    throw std::runtime_error(
        "camera '" + label + "': pixel format " +
        text(arv_camera_get_pixel_format_as_string(cam, error.out())) + " (" + describe_pfnc(pfnc) +
        ") is not supported; use Mono8/10/12/14/16 (also packed), Bayer*8/10/12/16 "
        "(also packed), RGB8, BGR8 or YUV422");
  }
  format = *supported;
  if (settings.region) {
    const Region& r = *settings.region;
    arv_camera_set_region(cam, r.x, r.y, r.width, r.height, error.out());
    error.throw_if_failed(label, "cannot set region " + std::to_string(r.width) + "x" +
                                     std::to_string(r.height) + "+" + std::to_string(r.x) + "+" +
                                     std::to_string(r.y));
  }
  if (settings.frame_rate > 0) {
    arv_camera_set_frame_rate(cam, settings.frame_rate, error.out());
    error.throw_if_failed(label, "cannot set frame rate " + std::to_string(settings.frame_rate));
  }
  if (settings.exposure_us > 0) {
    arv_camera_set_exposure_time(cam, settings.exposure_us, error.out());
    error.throw_if_failed(label, "cannot set exposure " + std::to_string(settings.exposure_us));
  }
  if (settings.gain) {
    arv_camera_set_gain(cam, *settings.gain, error.out());
    error.throw_if_failed(label, "cannot set gain " + std::to_string(*settings.gain));
  }
}

void Camera::Impl::start(const CameraSettings& settings) {
  ErrorSlot error;
  ArvCamera* cam = camera.get();
  payload = arv_camera_get_payload(cam, error.out());
  error.throw_if_failed(label, "cannot read the payload size");
  const double rate = arv_camera_get_frame_rate(cam, error.out());
  if (error.failed()) error.out();  // cameras without a rate feature: size the pool for 30 fps
  buffers = pool_size(settings, rate > 0 ? rate : 30.0);
  stream.reset(arv_camera_create_stream(cam, nullptr, nullptr, error.out()));
  error.throw_if_failed(label, "cannot create a stream");
  if (!stream) throw std::runtime_error("camera '" + label + "': cannot create a stream");
  for (int i = 0; i < buffers; ++i) {
    arv_stream_push_buffer(stream.get(), arv_buffer_new(payload, nullptr));  // the stream owns it
  }
  arv_camera_set_acquisition_mode(cam, ARV_ACQUISITION_MODE_CONTINUOUS, error.out());
  error.throw_if_failed(label, "cannot set continuous acquisition");
  arv_camera_start_acquisition(cam, error.out());
  error.throw_if_failed(label, "cannot start acquisition");
  if (settings.loss_timeout.count() > 0) {
    const double period_ms = rate > 0 ? 1000.0 / rate : 0.0;
    loss_timeout = std::max<std::chrono::steady_clock::duration>(
        settings.loss_timeout,
        std::chrono::milliseconds(static_cast<std::int64_t>(std::ceil(10 * period_ms))));
  }
  last_buffer = std::chrono::steady_clock::now();
}

// Only complete frames' ids are trusted (a buffer that lost its leader may carry any id). Between
// two of them, the ids not seen, less the incomplete buffers already counted, were never seen at
// all. Ids far below the last one are a wrap (GigE Vision 1 block ids are 16 bits) or a restarted
// camera, and a frame completed late (after a packet resend) was never counted as missing.
void Camera::Impl::track_complete_id(std::uint64_t id) {
  constexpr std::uint64_t kReorderWindow = 256;
  if (!last_id || id + kReorderWindow < *last_id) {
    last_id = id;
  } else if (id > *last_id) {
    const std::uint64_t missing = id - *last_id - 1;
    counters.skipped_ids += missing > incomplete_since_last ? missing - incomplete_since_last : 0;
    last_id = id;
  }
  incomplete_since_last = 0;
}

std::optional<Frame> Camera::Impl::take(ArvBuffer* buffer) {
  if (arv_buffer_get_status(buffer) != ARV_BUFFER_STATUS_SUCCESS ||
      arv_buffer_get_payload_type(buffer) != ARV_BUFFER_PAYLOAD_TYPE_IMAGE) {
    ++counters.incomplete;
    ++incomplete_since_last;
    return std::nullopt;
  }
  const auto pfnc = static_cast<std::uint32_t>(arv_buffer_get_image_pixel_format(buffer));
  const auto buffer_format = camera_format_from_code(pfnc);
  if (!buffer_format)
    throw std::runtime_error("camera '" + label + "' sent " + describe_pfnc(pfnc) +
                             ", which is not supported");
  const int width = arv_buffer_get_image_width(buffer);
  const int height = arv_buffer_get_image_height(buffer);
  std::size_t size = 0;
  const void* data = arv_buffer_get_image_data(buffer, &size);
  if (size == 0 && fake_fill) size = payload;  // see fill_fake_buffer
  if (width <= 0 || height <= 0 || size < image_bytes(width, height, *buffer_format)) {
    ++counters.incomplete;  // geometry and bytes disagree: never pass such an image on
    ++incomplete_since_last;
    return std::nullopt;
  }
  track_complete_id(arv_buffer_get_frame_id(buffer));
  Frame frame;
  frame.image =
      convert_image({static_cast<const std::byte*>(data), size}, width, height, *buffer_format);
  frame.frame_id = arv_buffer_get_frame_id(buffer);
  frame.device_ns = static_cast<std::int64_t>(arv_buffer_get_timestamp(buffer));
  frame.system_ns = static_cast<std::int64_t>(arv_buffer_get_system_timestamp(buffer));
  if (frame.device_ns == 0) {
    frame.capture_ns = frame.system_ns;  // no device clock: arrival is the best we know
  } else {
    const std::int64_t offset = frame.system_ns - frame.device_ns;
    clock_offset = clock_offset ? std::min(*clock_offset, offset) : offset;
    frame.capture_ns = frame.device_ns + *clock_offset;
  }
  ++counters.delivered;
  return frame;
}

Camera::Camera(const CameraSettings& settings) : impl_(std::make_unique<Impl>()) {
  impl_->open(settings);
  impl_->apply(settings);
  impl_->start(settings);
}

Camera::~Camera() = default;

namespace {
// Gives a popped buffer back to the stream's pool on every way out of Camera::next.
class BufferReturn {
 public:
  BufferReturn(ArvStream* stream, ArvBuffer* buffer) : stream_(stream), buffer_(buffer) {}
  ~BufferReturn() { arv_stream_push_buffer(stream_, buffer_); }
  BufferReturn(const BufferReturn&) = delete;
  BufferReturn& operator=(const BufferReturn&) = delete;

 private:
  ArvStream* stream_;
  ArvBuffer* buffer_;
};
}  // namespace

std::optional<Frame> Camera::next(std::chrono::milliseconds timeout) {
  using Clock = std::chrono::steady_clock;
  const auto deadline = Clock::now() + timeout;
  while (!impl_->lost) {
    const auto now = Clock::now();
    if (impl_->watchdog_expired(now)) return std::nullopt;
    const auto left = std::chrono::duration_cast<std::chrono::microseconds>(deadline - now).count();
    if (left <= 0) return std::nullopt;
    ArvBuffer* buffer =
        arv_stream_timeout_pop_buffer(impl_->stream.get(), static_cast<guint64>(left));
    if (!buffer) continue;  // the loop checks the watchdog, then the deadline
    impl_->last_buffer = Clock::now();
    impl_->any_buffer = true;
    const BufferReturn giveback{impl_->stream.get(), buffer};
    if (auto frame = impl_->take(buffer)) return frame;
  }
  return std::nullopt;
}

// The stream watchdog: true (and the camera lost) when no buffer came for loss_timeout.
bool Camera::Impl::watchdog_expired(std::chrono::steady_clock::time_point now) {
  if (loss_timeout.count() == 0) return false;
  const auto limit =
      loss_timeout + (any_buffer ? std::chrono::seconds(0) : std::chrono::seconds(2));
  if (now - last_buffer < limit) return false;
  loss_reason =
      "no data for " +
      std::to_string(
          std::chrono::duration_cast<std::chrono::milliseconds>(now - last_buffer).count()) +
      " ms";
  lost = true;
  return true;
}

bool Camera::control_lost() const { return impl_->lost; }

std::string Camera::loss_reason() const {
  if (!impl_->lost) return "";
  return impl_->loss_reason.empty() ? "control-lost: the heartbeat failed" : impl_->loss_reason;
}

StreamCounters Camera::counters() const {
  StreamCounters counters = impl_->counters;
  guint64 completed = 0, failures = 0, underruns = 0;
  arv_stream_get_statistics(impl_->stream.get(), &completed, &failures, &underruns);
  counters.underruns = underruns;
  return counters;
}

const DeviceInfo& Camera::info() const { return impl_->info; }

std::string Camera::pixel_format() const { return std::string(name(impl_->format)); }

double Camera::frame_rate() const {
  ErrorSlot error;
  const double rate = arv_camera_get_frame_rate(impl_->camera.get(), error.out());
  return error.failed() ? 0.0 : rate;
}

Region Camera::region() const {
  Region r;
  ErrorSlot error;
  arv_camera_get_region(impl_->camera.get(), &r.x, &r.y, &r.width, &r.height, error.out());
  return r;
}

int Camera::buffer_count() const { return impl_->buffers; }

std::vector<std::string> Camera::available_pixel_formats() const {
  ErrorSlot error;
  guint n = 0;
  const char** names =
      arv_camera_dup_available_pixel_formats_as_strings(impl_->camera.get(), &n, error.out());
  std::vector<std::string> result;
  for (guint i = 0; names && i < n; ++i) result.push_back(text(names[i]));
  g_free(static_cast<gpointer>(names));
  return result;
}

}  // namespace mocap::aravis
