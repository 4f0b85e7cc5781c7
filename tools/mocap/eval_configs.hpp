#pragma once
// What the `mocap eval` protocols share: the configurations compared side by side in one run
// (../shared/docs/EVALUATION.md), the paper's database, and the JSON and table row of a score.

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "eval/virtual_protocol.hpp"
#include "fit/monocular_prior.hpp"
#include "posedb/builder.hpp"
#include "posedb/database.hpp"
#include "recon/matcher.hpp"
#include "recon/sequence_reconstruction.hpp"

namespace mocap::cli {

// One configuration of the method, compared side by side with the others in one run.
struct Config {
  std::string name;
  std::string description;
  const posedb::Database* db;
  recon::MatchOptions match;
  recon::SequenceOptions sequence;
  // Turn every pose onto the ray through its root pixel, with the protocol's true intrinsics.
  bool align_to_ray = false;
  // Re-score the matcher's candidates on the person's own proportions (Matcher::set_person); in
  // the virtual protocol they are given, measured from the truth clip.
  bool person_bones = false;
  // The input's layout given to the matcher (Matcher::set_layout): candidates moved into the
  // layout's keypoint definition when re-scored.
  std::optional<recon::LayoutOffsets> candidate_layout = std::nullopt;
};

// The paper's configuration on `paper` (its yaw-only database), then per-frame nearest
// neighbour, greedy and the full configurations on `full`; `fps` is the databases' rate.
std::vector<Config> make_configs(const posedb::Database& full, const posedb::Database& paper,
                                 double fps);

// The paper's view set: the level 1.5 m camera only, at every yaw step.
posedb::BuildOptions paper_build_options(const std::string& command);

// Maps `contents` through a temporary file that is removed at once (the mapping stays valid).
posedb::Database open_temporary_database(const posedb::DatabaseContents& contents,
                                         const std::string& tag);

// The paper's database: the file `given`, or, when empty, one built from the train split of the
// cmu31 folder `mocap` (`command` is recorded in it).
posedb::Database open_paper_database(const std::string& given, const std::string& mocap,
                                     const std::string& command);

nlohmann::json scores_json(const eval::Scores& scores);

// One Markdown row: | name | what | MPJPE | PA-MPJPE | accel | jitter | coverage |.
void print_row(const std::string& name, const std::string& what, const eval::Scores& scores);

// `--prior-set NAME=VALUE`: one setting of the monocular prior (fit::MonocularPriorOptions), for
// choosing them on train data (mocap eval humaneva-multiview --split train, mocap eval multiview
// --split train). Throws InputError naming the option.
void set_prior_option(fit::MonocularPriorOptions& o, const std::string& assignment);

}  // namespace mocap::cli
