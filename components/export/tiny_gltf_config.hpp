#pragma once
// The one way this project includes tinygltf (Debian's libtinygltf-dev 2.7): image loading and
// writing are compiled out (no textures are written, and Debian ships stb separately), JSON is
// nlohmann's. The implementation is compiled once, in gltf_writer.cpp (TINYGLTF_IMPLEMENTATION);
// tests that read GLB files back include this header and link mocap_export. Never include it from
// a public header: tinygltf stays an implementation detail.

#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>
