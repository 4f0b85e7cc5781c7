#pragma once
// Camera pixel formats (GenICam PFNC codes, the values GigE Vision and USB3 Vision cameras report)
// converted to the frame types of ImageBuffer. Free of Aravis headers, so it is tested on its own.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "core/image_buffer.hpp"

namespace mocap::aravis {

// The PFNC codes this driver converts; any other code is refused with its name or number.
enum class CameraFormat : std::uint32_t {
  mono8 = 0x01080001u,
  bayer_gr8 = 0x01080008u,
  bayer_rg8 = 0x01080009u,
  bayer_gb8 = 0x0108000au,
  bayer_bg8 = 0x0108000bu,
  rgb8 = 0x02180014u,
  bgr8 = 0x02180015u,
  yuv422_uyvy = 0x0210001fu,  // "YUV422Packed": U Y V Y
  yuv422_yuyv = 0x02100032u,  // "YUV422_YUYV_Packed": Y U Y V
};

std::optional<CameraFormat> camera_format_from_code(std::uint32_t pfnc);
std::string_view name(CameraFormat format);  // the GenICam name, e.g. "BayerRG8"
// What the graph receives: gray8 for Mono8, bgr8 for BGR8, rgb8 for everything in colour.
PixelFormat converted_format(CameraFormat format);
// "PixelFormat 0x01100005" for codes the driver does not convert.
std::string describe_pfnc(std::uint32_t pfnc);

// Bytes of a packed image of this geometry and format (what convert_image needs).
std::size_t image_bytes(int width, int height, CameraFormat format);

// Converts one camera image (rows packed, as GVSP/U3V deliver them) into a new ImageBuffer.
// Throws std::invalid_argument when `bytes` is shorter than the geometry needs.
ImageBuffer convert_image(std::span<const std::byte> bytes, int width, int height,
                          CameraFormat format);

}  // namespace mocap::aravis
