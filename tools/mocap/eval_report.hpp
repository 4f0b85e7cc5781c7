#pragma once
// What every evaluation output records besides its numbers (../shared/docs/EVALUATION.md): the
// command line, the git commit, the machine.

#include <chrono>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace mocap::cli {

nlohmann::json machine_description();
std::string git_commit();  // "unknown" outside a checkout

// The command as typed: `program` ("mocap eval humaneva") and its arguments.
std::string command_line(std::string_view program, int argc, char** argv);

// Adds the seconds since `started` to `results`, writes them (indented JSON, through a temporary
// file) to `path` and says where on standard output.
void write_results(nlohmann::json& results, const std::string& path,
                   std::chrono::steady_clock::time_point started);

}  // namespace mocap::cli
