#pragma once
// A small skeleton with CMU's ASF bone names and proportions (subject-like lengths in ASF units)
// and a short AMC, for tests of the whole ASF/AMC path without CMU's files.

#include <string>

namespace mocap::test {

inline std::string cmu_like_asf() {
  struct Bone {
    const char* name;
    const char* direction;
    double length;
    const char* dof;
  };
  // Rest pose: standing, arms out along +-X, facing +Z, Y up (as CMU's ASF).
  const Bone bones[] = {
      {"lhipjoint", "0.57 -0.82 0", 2.2, ""},  {"lfemur", "0 -1 0", 7.2, "rx ry rz"},
      {"ltibia", "0 -1 0", 7.4, "rx"},         {"lfoot", "0 0 1", 2.2, "rx rz"},
      {"rhipjoint", "-0.57 -0.82 0", 2.2, ""}, {"rfemur", "0 -1 0", 7.2, "rx ry rz"},
      {"rtibia", "0 -1 0", 7.4, "rx"},         {"rfoot", "0 0 1", 2.2, "rx rz"},
      {"lowerback", "0 1 0", 2.0, "rx ry rz"}, {"upperback", "0 1 0", 2.0, "rx ry rz"},
      {"thorax", "0 1 0", 2.0, "rx ry rz"},    {"lowerneck", "0 1 0", 1.5, "rx ry rz"},
      {"upperneck", "0 1 0", 1.5, "rx ry rz"}, {"head", "0 1 0", 1.5, "rx ry rz"},
      {"lclavicle", "1 0 0", 3.3, "ry rz"},    {"lhumerus", "1 0 0", 5.0, "rx ry rz"},
      {"lradius", "1 0 0", 3.4, "rx"},         {"lwrist", "1 0 0", 1.7, "ry"},
      {"rclavicle", "-1 0 0", 3.3, "ry rz"},   {"rhumerus", "-1 0 0", 5.0, "rx ry rz"},
      {"rradius", "-1 0 0", 3.4, "rx"},        {"rwrist", "-1 0 0", 1.7, "ry"},
  };
  std::string s =
      ":version 1.10\n:name cmu_like\n:units\n  mass 1.0\n  length 0.45\n  angle deg\n"
      ":documentation\n  test skeleton with CMU bone names\n:root\n  order TX TY TZ RX RY RZ\n"
      "  axis XYZ\n  position 0 0 0\n  orientation 0 0 0\n:bonedata\n";
  int id = 1;
  for (const Bone& b : bones) {
    s += "  begin\n    id " + std::to_string(id++) + "\n    name " + b.name + "\n    direction " +
         b.direction + "\n    length " + std::to_string(b.length) + "\n    axis 0 0 0 XYZ\n";
    if (*b.dof) s += std::string("    dof ") + b.dof + "\n";
    s += "  end\n";
  }
  s += ":hierarchy\n  begin\n    root lhipjoint rhipjoint lowerback\n    lhipjoint lfemur\n    "
       "lfemur ltibia\n"
       "    ltibia lfoot\n    rhipjoint rfemur\n    rfemur rtibia\n    rtibia rfoot\n    lowerback "
       "upperback\n"
       "    upperback thorax\n    thorax lowerneck lclavicle rclavicle\n    lowerneck upperneck\n"
       "    upperneck head\n    lclavicle lhumerus\n    lhumerus lradius\n    lradius lwrist\n"
       "    rclavicle rhumerus\n    rhumerus rradius\n    rradius rwrist\n  end\n";
  return s;
}

// `frames` frames; the root walks along +Z and the left knee bends.
inline std::string cmu_like_amc(int frames) {
  std::string s = "#test motion\n:FULLY-SPECIFIED\n:DEGREES\n";
  for (int f = 1; f <= frames; ++f) {
    s += std::to_string(f) + "\nroot 0 16.5 " + std::to_string(0.1 * f) + " 0 0 0\n";
    for (const char* bone : {"lfemur", "rfemur", "lowerback", "upperback", "thorax", "lowerneck",
                             "upperneck", "head", "lhumerus", "rhumerus"}) {
      s += std::string(bone) + " 0 0 0\n";
    }
    s += "ltibia " + std::to_string(f % 30) +
         "\nrtibia 0\nlfoot 0 0\nrfoot 0 0\nlclavicle 0 0\nrclavicle 0 0\n";
    s += "lradius 10\nrradius 10\nlwrist 0\nrwrist 0\n";
  }
  return s;
}

}  // namespace mocap::test
