#pragma once
// Entry points of the `mocap` subcommands; each lives in its own file (<name>_command.cpp) and
// receives the arguments after its own name.

namespace mocap::cli {

int db_command(int argc, char** argv);
int run_command(int argc, char** argv);
int graph_command(int argc, char** argv);
int eval_command(int argc, char** argv);
// `mocap eval humaneva`, reached through eval_command.
int humaneva_eval_command(int argc, char** argv);
// `mocap eval humaneva-fit` and `mocap eval crossview`, reached through eval_command.
int humaneva_fit_command(int argc, char** argv);
int crossview_eval_command(int argc, char** argv);
// `mocap eval humaneva-multiview` (issue 19 report 3).
int humaneva_multiview_command(int argc, char** argv);
// `mocap eval multiview` and `mocap eval pose2sim` (issue 19 reports 2 and 1).
int multiview_eval_command(int argc, char** argv);
int pose2sim_eval_command(int argc, char** argv);
int reconstruct_command(int argc, char** argv);
int camera_command(int argc, char** argv);
int calibrate_command(int argc, char** argv);
int rig_command(int argc, char** argv);
int retarget_command(int argc, char** argv);
int keys_command(int argc, char** argv);
int view_command(int argc, char** argv);
int export_command(int argc, char** argv);

}  // namespace mocap::cli
