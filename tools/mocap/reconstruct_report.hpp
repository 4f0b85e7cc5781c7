#pragma once
// What the monocular and the multi-view `mocap reconstruct` share (reconstruct_command.cpp): the
// checks before a graph runs and the report of what it wrote.

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "graph/graph_spec.hpp"
#include "graph/stats.hpp"
#include "graph_runner.hpp"
#include "progress_bar.hpp"
#include "reconstruct_outputs.hpp"

namespace mocap::cli {

// A graph with detector nodes on the cached models: a missing model is reported before anything
// runs, naming the command that fetches it.
void check_detector_model(const graph::GraphSpec& spec);

// What the run produced, read back from poses.jsonl: frames, people, track lengths.
nlohmann::json summarize_output(const std::filesystem::path& jsonl);
// The files with their sizes, for summary.json.
nlohmann::json files_json(const std::vector<std::filesystem::path>& files);
// "wrote ..." lines for the files of this run.
void print_written(const std::filesystem::path& out, const WrittenOutputs& written,
                   const nlohmann::json& summary, double frames_per_second);
// For a run that did not complete but wrote something: what it kept, and what it did not write.
std::string incomplete_note(const WrittenOutputs& written, const nlohmann::json& summary,
                            std::int64_t input_frames);
// A reconstruct graph run into `out` and what it left there. Every output file in `out` is then
// this run's (earlier ones were refused or set aside by `earlier`, settled here); the statistics
// table is printed unless `quiet`.
struct ReconstructRun {
  graph::RunResult result;
  double seconds = 0.0;                      // from `started` to the end of the run
  std::vector<std::filesystem::path> files;  // this run's outputs, summary.json aside
  WrittenOutputs written;
  std::string outcome;  // "failed: ERROR", "interrupted", or empty for a run that completed
  // Set when the run wrote nothing (its messages are printed): the exit code. The folder stays
  // as it was, an earlier output back with its summary.json, so no summary is written.
  std::optional<int> nothing_written;
};
ReconstructRun run_reconstruct_graph(const graph::ResolvedGraph& graph,
                                     const graph::RunOptions& options,
                                     const ProgressCallback& progress, ProgressBar& bar,
                                     EarlierOutput& earlier, const std::filesystem::path& out,
                                     bool quiet, std::chrono::steady_clock::time_point started);

// The end of a run that wrote something: `summary` (the command's own fields already in) gains
// the run's time, rate, node statistics, outcome and files and is written as out/summary.json;
// the files are listed, an incomplete run says what it kept. Returns the exit code (0, 1 failed,
// 130 interrupted).
int finish_reconstruct(const ReconstructRun& run, nlohmann::json& summary,
                       const std::filesystem::path& out, std::int64_t input_frames);

// Per node: in, out, drops, latency.
nlohmann::json node_latency(const graph::GraphStats& stats);

// `mocap reconstruct --calibration RIG VIEW...` (reconstruct_multiview.cpp).
bool asks_for_multiview(int argc, char** argv);
int reconstruct_multiview_command(int argc, char** argv);

}  // namespace mocap::cli
