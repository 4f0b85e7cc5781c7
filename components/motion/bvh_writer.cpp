#include <charconv>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <string>

#include "core/input_error.hpp"
#include "motion/bvh.hpp"

namespace mocap::motion {
namespace {

// Shortest text that reads back as the same float.
void put_number(std::ostream& out, float v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  out.write(buf, end - buf);
}

void put_joint(std::ostream& out, const Skeleton& skel, int j, int depth) {
  const std::string indent(static_cast<size_t>(depth), '\t');
  const SkeletonJoint& joint = skel.joints[j];
  if (joint.end_site) {
    out << indent << "End Site\n";
  } else {
    out << indent << (joint.parent < 0 ? "ROOT " : "JOINT ") << joint.name << '\n';
  }
  out << indent << "{\n" << indent << "\tOFFSET ";
  put_number(out, joint.offset.x);
  out << ' ';
  put_number(out, joint.offset.y);
  out << ' ';
  put_number(out, joint.offset.z);
  out << '\n';
  if (!joint.end_site) {
    out << indent << "\tCHANNELS " << joint.channels.size();
    for (Channel c : joint.channels) out << ' ' << channel_name(c);
    out << '\n';
  }
  for (int child = j + 1; child < skel.joint_count(); ++child) {
    if (skel.joints[child].parent == j) put_joint(out, skel, child, depth + 1);
  }
  out << indent << "}\n";
}

}  // namespace

void write_bvh_hierarchy(const Skeleton& skeleton, std::ostream& out) {
  out << "HIERARCHY\n";
  for (int j = 0; j < skeleton.joint_count(); ++j) {
    if (skeleton.joints[j].parent < 0) put_joint(out, skeleton, j, 0);
  }
}

void append_bvh_frame_line(std::span<const float> values, std::string& line) {
  char buf[32];
  for (std::size_t c = 0; c < values.size(); ++c) {
    if (c) line += ' ';
    const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, values[c]);
    line.append(buf, end);
  }
  line += '\n';
}

void write_bvh(const Clip& clip, std::ostream& out) {
  const Skeleton& skel = clip.skeleton;
  write_bvh_hierarchy(skel, out);
  out << "MOTION\nFrames: " << clip.frame_count << "\nFrame Time: ";
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, clip.frame_time);
  out.write(buf, end - buf);
  out << '\n';
  std::string line;
  for (int f = 0; f < clip.frame_count; ++f) {
    line.clear();
    append_bvh_frame_line({clip.frame(f), static_cast<std::size_t>(skel.channel_count)}, line);
    out << line;
  }
}

void write_bvh(const Clip& clip, const std::string& path) {
  const std::string tmp = path + ".part";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(path, "cannot create file");
    write_bvh(clip, out);
    out.flush();
    if (!out) throw InputError(path, "write failed (disk full?)");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw InputError(path, "cannot move the finished file into place: " + ec.message());
}

}  // namespace mocap::motion
