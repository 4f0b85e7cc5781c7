#pragma once
// The files `mocap reconstruct` writes into its output folder, found by name: poses.jsonl,
// summary.json, person_<id>.bvh, overlay* (overlay.mp4, overlay_<frame>.png), and the .part
// files its writers create them under. A folder holding any of them holds an earlier run's output:
// the command refuses it without --force; with --force EarlierOutput sets them aside for the run
// and then discards them (the run wrote something) or puts them back (it wrote nothing: it failed
// before its first frame). Either way, after a run every such file in the folder is one run's,
// and the report lists this run's from there.

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace mocap::cli {

bool is_reconstruct_output(std::string_view file_name);

// The output files in `folder` (none when it does not exist), in natural order (person_2 before
// person_10). Throws InputError naming the folder when it cannot be listed.
std::vector<std::filesystem::path> reconstruct_outputs_in(const std::filesystem::path& folder);

// An earlier run's output in a folder about to be written. prepare() refuses it (InputError
// naming what is there) unless `force`, then moves it into DIR/.mocap-replaced/ (renames: same
// file system, nothing copied); settle() after the run removes it when the run wrote any output,
// or moves it back, byte for byte, when it wrote none. A run killed in between leaves the folder
// .mocap-replaced/, which the next prepare() puts back (the killed run wrote nothing) or removes
// (it did: --force had asked to replace them).
class EarlierOutput {
 public:
  static EarlierOutput prepare(const std::filesystem::path& folder, bool force);
  // What happened to the earlier output, one line ("" when there was none).
  std::string settle(bool run_wrote_output);
  std::size_t count() const { return names_.size(); }

 private:
  std::filesystem::path folder_, aside_;
  std::vector<std::filesystem::path> names_;  // file names, moved into aside_
};

// What a run left in its folder, sorted by kind.
struct WrittenOutputs {
  std::vector<std::filesystem::path> poses, bvh, videos, images, partial, other;
  std::vector<int> bvh_ids;  // of person_<id>.bvh, in the order of `bvh`
};
WrittenOutputs classify_outputs(const std::vector<std::filesystem::path>& files);

// What the files are, by kind, for messages: "poses.jsonl, summary.json, 10 person_<id>.bvh,
// overlay.mp4, 2 overlay images".
std::string describe_outputs(const std::vector<std::filesystem::path>& files);

// "a.png, b.png and 3 more" for messages.
std::string short_list(const std::vector<std::filesystem::path>& files, std::size_t show = 4);

}  // namespace mocap::cli
