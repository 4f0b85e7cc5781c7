#pragma once
// An evaluation must not score a database on motion it was built from (../shared/docs/
// EVALUATION.md): `mocap eval virtual` runs on the held-out CMU subjects, `mocap eval humaneva`,
// `humaneva-fit` and `humaneva-multiview` on a HumanEva split. A database holding any of that
// motion is refused, naming the clips, or with --allow-leak evaluated anyway with a loud warning,
// recorded in the results.

#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "posedb/database.hpp"

namespace mocap::cli {

// The clips of `db` from a held-out CMU subject of `mocap_folder`'s splits.txt: names like
// "02_01.bvh" or "02_01.amc" (subject 02) whatever their family (cmu31, cmu_daz, ASF/AMC), e.g.
// "02_01.bvh (cmu31)".
std::vector<std::string> cmu_heldout_clips(const posedb::Database& db,
                                           const std::string& mocap_folder);

// Of the CMU clip files `files`, those whose subject has no clip in `db` (any family): scenes
// of train clips that a database of the other train subjects never saw (mocap eval multiview
// --split train).
std::vector<std::string> cmu_clips_of_unseen_subjects(const posedb::Database& db,
                                                      const std::vector<std::string>& files);

// The HumanEva clips of `db` from `split` ("Validate" or "Train": their names start "Validate/").
std::vector<std::string> humaneva_clips(const posedb::Database& db, std::string_view split);

// The leaks found in the databases of one evaluation, each with the database that holds it.
class LeakCheck {
 public:
  void add(const std::string& database, std::vector<std::string> clips);
  // Throws InputError naming the databases and clips when there are leaks and not `allowed`;
  // when allowed, prints a warning block on stderr and goes on (the report says it again).
  void enforce(bool allowed, const std::string& evaluated, const std::string& command) const;
  bool empty() const { return found_.empty(); }
  // {"allowed": true, "databases": {file: [clips]}} for the results, or null without leaks.
  nlohmann::json to_json() const;
  // A line for the Markdown report ("" without leaks).
  std::string markdown_warning() const;

 private:
  std::vector<std::pair<std::string, std::vector<std::string>>> found_;
};

}  // namespace mocap::cli
