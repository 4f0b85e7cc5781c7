#include "eval_report.hpp"

#include <unistd.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <thread>

#include "output_files.hpp"

namespace mocap::cli {

nlohmann::json machine_description() {
  std::string cpu = "unknown";
  std::ifstream info("/proc/cpuinfo");
  for (std::string line; std::getline(info, line);) {
    if (line.rfind("model name", 0) == 0) {
      cpu = line.substr(line.find(':') + 2);
      break;
    }
  }
  char host[256] = "";
  gethostname(host, sizeof host - 1);
  return {{"nproc", std::thread::hardware_concurrency()}, {"cpu", cpu}, {"host", host}};
}

std::string git_commit() {
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen("git rev-parse --short HEAD 2>/dev/null", "r"),
                                             pclose);
  if (!pipe) return "unknown";
  std::array<char, 64> buf{};
  if (!fgets(buf.data(), buf.size(), pipe.get())) return "unknown";
  std::string s(buf.data());
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
  return s.empty() ? "unknown" : s;
}

std::string command_line(std::string_view program, int argc, char** argv) {
  std::string line(program);
  for (int i = 0; i < argc; ++i) line.append(" ").append(argv[i]);
  return line;
}

void write_results(nlohmann::json& results, const std::string& path,
                   std::chrono::steady_clock::time_point started) {
  results["seconds"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  write_file_atomically(path, json_text(results, 2) + "\n");
  std::cout << "\nAll numbers: " << path << "\n";
}

}  // namespace mocap::cli
