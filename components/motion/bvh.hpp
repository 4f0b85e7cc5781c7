#pragma once
// BVH (Biovision hierarchy) reading and writing: any hierarchy, any channel order, End Sites,
// tabs or CRLF, exponent notation. Errors are mocap::InputError naming the file and line.

#include <iosfwd>
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
// Writes to `path` through a temporary file renamed into place, so a reader never sees half a file.
void write_bvh(const Clip& clip, const std::string& path);

}  // namespace mocap::motion
