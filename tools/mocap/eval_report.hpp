#pragma once
// What every evaluation output records besides its numbers (../shared/docs/EVALUATION.md): the
// command line, the git commit, the machine.

#include <string>

#include <nlohmann/json.hpp>

namespace mocap::cli {

nlohmann::json machine_description();
std::string git_commit();  // "unknown" outside a checkout

}  // namespace mocap::cli
