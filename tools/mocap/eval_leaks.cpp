#include "eval_leaks.hpp"

#include <cctype>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>

#include "core/input_error.hpp"

namespace mocap::cli {
namespace {

// The CMU subject of a clip name "SS_TT" with any extension ("02_01.bvh" -> "02"), or "".
std::string cmu_subject(std::string_view name) {
  const auto underscore = name.find('_');
  if (underscore == 0 || underscore == std::string_view::npos) return {};
  std::size_t end = underscore + 1;
  while (end < name.size() && std::isdigit(static_cast<unsigned char>(name[end]))) ++end;
  if (end == underscore + 1 || (end < name.size() && name[end] != '.')) return {};
  for (std::size_t i = 0; i < underscore; ++i)
    if (!std::isdigit(static_cast<unsigned char>(name[i]))) return {};
  // CMU writes subjects with two or three digits: 2 and 02 are the same subject.
  std::string subject(name.substr(0, underscore));
  while (subject.size() > 1 && subject[0] == '0') subject.erase(0, 1);
  return subject;
}

}  // namespace

std::vector<std::string> cmu_heldout_clips(const posedb::Database& db,
                                           const std::string& mocap_folder) {
  std::ifstream list(std::filesystem::path(mocap_folder) / "splits.txt");
  if (!list) {
    throw InputError(mocap_folder,
                     "no splits.txt here: give the cmu31 folder of the shared data (--mocap)");
  }
  std::set<std::string> heldout_subjects;
  std::string split, file;
  while (list >> split >> file) {
    if (split == "heldout") heldout_subjects.insert(cmu_subject(file));
  }
  heldout_subjects.erase("");
  std::vector<std::string> leaks;
  for (const posedb::ClipInfo& clip : db.clips()) {
    if (heldout_subjects.count(cmu_subject(clip.name)))
      leaks.push_back(clip.name + " (" + clip.family + ")");
  }
  return leaks;
}

std::vector<std::string> cmu_clips_of_unseen_subjects(const posedb::Database& db,
                                                      const std::vector<std::string>& files) {
  std::set<std::string> seen;
  for (const posedb::ClipInfo& clip : db.clips()) seen.insert(cmu_subject(clip.name));
  std::vector<std::string> out;
  for (const std::string& file : files) {
    const std::string subject = cmu_subject(std::filesystem::path(file).filename().string());
    if (!subject.empty() && !seen.count(subject)) out.push_back(file);
  }
  return out;
}

std::vector<std::string> humaneva_clips(const posedb::Database& db, std::string_view split) {
  const std::string prefix = std::string(split) + "/";
  std::vector<std::string> leaks;
  for (const posedb::ClipInfo& clip : db.clips()) {
    if (clip.family == "humaneva" && clip.name.starts_with(prefix)) leaks.push_back(clip.name);
  }
  return leaks;
}

void LeakCheck::add(const std::string& database, std::vector<std::string> clips) {
  if (!clips.empty()) found_.emplace_back(database, std::move(clips));
}

void LeakCheck::enforce(bool allowed, const std::string& evaluated,
                        const std::string& command) const {
  if (found_.empty()) return;
  std::string what;
  std::size_t count = 0;
  for (const auto& [database, clips] : found_) {
    what += "\n  " + database + ":";
    for (std::size_t i = 0; i < clips.size() && i < 12; ++i) what += (i ? ", " : " ") + clips[i];
    if (clips.size() > 12) what += " and " + std::to_string(clips.size() - 12) + " more";
    count += clips.size();
  }
  if (!allowed) {
    throw InputError(command, "the database holds " + std::to_string(count) + " clip(s) of " +
                                  evaluated + ", the motion this evaluates on:" + what +
                                  "\nscoring on its own training data says nothing; build the "
                                  "database from the train split (mocap db build ... --split "
                                  "train), or give --allow-leak to evaluate anyway");
  }
  std::cerr << "\n"
            << command << ": WARNING: --allow-leak: the database holds " << count << " clip(s) of "
            << evaluated << ", the motion this evaluates on:" << what << "\n"
            << command
            << ": WARNING: these results are measured on training data and are not an accuracy "
               "figure\n\n";
}

nlohmann::json LeakCheck::to_json() const {
  if (found_.empty()) return nullptr;
  nlohmann::json databases = nlohmann::json::object();
  for (const auto& [database, clips] : found_) databases[database] = clips;
  return {{"allowed", true},
          {"warning", "the database holds clips of the evaluated motion: not an accuracy figure"},
          {"databases", databases}};
}

std::string LeakCheck::markdown_warning() const {
  if (found_.empty()) return {};
  std::size_t count = 0;
  for (const auto& entry : found_) count += entry.second.size();
  return "> **WARNING (--allow-leak):** the database holds " + std::to_string(count) +
         " clip(s) of the evaluated motion; these numbers are measured on training data and are "
         "not an accuracy figure.\n\n";
}

}  // namespace mocap::cli
