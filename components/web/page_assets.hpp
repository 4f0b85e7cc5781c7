#pragma once
// The viewer's page (components/web/page/), compiled into the program at build time
// (embed_page.cmake), so the server needs no files beside the executable except three.js.

#include <span>
#include <string_view>

namespace mocap::web {

struct PageFile {
  std::string_view path;  // URL path: "/index.html", "/viewer.js"
  std::string_view content_type;
  std::string_view content;
};

std::span<const PageFile> page_files();

}  // namespace mocap::web
