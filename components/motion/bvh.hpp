#pragma once
// BVH (Biovision hierarchy) reading and writing: any hierarchy, any channel order, End Sites,
// tabs or CRLF, exponent notation. Errors are mocap::InputError naming the file and line.

#include <iosfwd>
#include <span>
#include <string>
#include <string_view>

#include "motion/skeleton.hpp"

namespace mocap::motion {

// Reads a BVH file. Throws InputError (file:line: reason) on anything malformed.
Clip read_bvh(const std::string& path);
// Parses BVH text; `source` names it in error messages.
Clip parse_bvh(std::string_view text, const std::string& source);

// Writes the clip's channel values as they are (shortest exact float text), so reading the file
// back gives the same values.
void write_bvh(const Clip& clip, std::ostream& out);
// The pieces of write_bvh, for writers that stream frames (bvh_stream_writer.hpp): the
// HIERARCHY section up to, not including, "MOTION"; and one frame's values as one line (shortest
// exact float text, space-separated, ending in '\n') appended to `line`.
void write_bvh_hierarchy(const Skeleton& skeleton, std::ostream& out);
void append_bvh_frame_line(std::span<const float> values, std::string& line);
// Writes to `path` through a temporary file renamed into place, so a reader never sees half a file.
void write_bvh(const Clip& clip, const std::string& path);

}  // namespace mocap::motion
