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
// Formats of more than 8 bits per pixel become 8 bits: the top 8 bits of each value are kept
// (value >> (bits - 8); Mono16 and Bayer*16 keep their high byte), the rest is dropped; the
// detector and the overlay work on 8-bit images. Their layouts:
//   unpacked (Mono10/12/14/16, Bayer*10/12/16): one little-endian 16-bit word per pixel;
//   GigE Vision "Packed" (Mono10Packed, Mono12Packed, Bayer*10Packed/12Packed): two pixels in 3
//     bytes, byte 0 the first pixel's high 8 bits, byte 2 the second's, byte 1 their low bits;
//   PFNC "p" (Mono10p, Mono12p, Bayer*10p/12p): pixels back to back in one little-endian bit
//     stream (Mono10p: 4 pixels in 5 bytes, Mono12p: 2 pixels in 3 bytes).
// Packed pixels run on from one row into the next (rows are not padded to whole bytes).
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
  mono10 = 0x01100003u,
  mono12 = 0x01100005u,
  mono14 = 0x01100025u,
  mono16 = 0x01100007u,
  mono10_packed = 0x010c0004u,
  mono12_packed = 0x010c0006u,
  mono10p = 0x010a0046u,
  mono12p = 0x010c0047u,
  bayer_gr10 = 0x0110000cu,
  bayer_rg10 = 0x0110000du,
  bayer_gb10 = 0x0110000eu,
  bayer_bg10 = 0x0110000fu,
  bayer_gr12 = 0x01100010u,
  bayer_rg12 = 0x01100011u,
  bayer_gb12 = 0x01100012u,
  bayer_bg12 = 0x01100013u,
  bayer_gr16 = 0x0110002eu,
  bayer_rg16 = 0x0110002fu,
  bayer_gb16 = 0x01100030u,
  bayer_bg16 = 0x01100031u,
  bayer_gr10_packed = 0x010c0026u,
  bayer_rg10_packed = 0x010c0027u,
  bayer_gb10_packed = 0x010c0028u,
  bayer_bg10_packed = 0x010c0029u,
  bayer_gr12_packed = 0x010c002au,
  bayer_rg12_packed = 0x010c002bu,
  bayer_gb12_packed = 0x010c002cu,
  bayer_bg12_packed = 0x010c002du,
  bayer_gr10p = 0x010a0056u,
  bayer_rg10p = 0x010a0058u,
  bayer_gb10p = 0x010a0054u,
  bayer_bg10p = 0x010a0052u,
  bayer_gr12p = 0x010c0057u,
  bayer_rg12p = 0x010c0059u,
  bayer_gb12p = 0x010c0055u,
  bayer_bg12p = 0x010c0053u,
};

std::optional<CameraFormat> camera_format_from_code(std::uint32_t pfnc);
std::string_view name(CameraFormat format);  // the GenICam name, e.g. "BayerRG8"
// What the graph receives: gray8 for every Mono format, bgr8 for BGR8, rgb8 for everything in
// colour.
PixelFormat converted_format(CameraFormat format);
// "PixelFormat 0x01100005" for codes the driver does not convert.
std::string describe_pfnc(std::uint32_t pfnc);

// Significant bits per pixel value (8 for the 8-bit and colour formats; 10 for Mono10, ...).
int value_bits(CameraFormat format);
// Bytes of a packed image of this geometry and format (what convert_image needs).
std::size_t image_bytes(int width, int height, CameraFormat format);

// Converts one camera image (rows packed, as GVSP/U3V deliver them) into a new ImageBuffer.
// Throws std::invalid_argument when `bytes` is shorter than the geometry needs.
ImageBuffer convert_image(std::span<const std::byte> bytes, int width, int height,
                          CameraFormat format);

}  // namespace mocap::aravis
