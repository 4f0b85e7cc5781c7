// `mocap db build` over several mocap families in one run, --split and --body, and `db info`,
// driven as a user would: the built binary in a child process.

#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/mocap_process.hpp"
#include "support/shared_data.hpp"

namespace mocap {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

// A folder with a splits.txt (one train, one held-out CMU file) and one without (a Bandai
// file): --split train takes the first's train file and all of the second.
TEST(DbCommand, SplitTakesFoldersWithoutSplitsWholeAndRecordsFamiliesAndBody) {
  MOCAP_REQUIRE_SHARED("mocap/bandai/dataset-1/dataset-1_bow_normal_001.bvh");
  const fs::path mocap = test::shared_data() / "mocap";
  test::TempDir dir;
  fs::create_directories(dir.path() / "cmu");
  fs::create_directories(dir.path() / "other");
  fs::copy_file(mocap / "cmu31/08_01.bvh", dir.path() / "cmu/08_01.bvh");
  fs::copy_file(mocap / "cmu31/07_01.bvh", dir.path() / "cmu/07_01.bvh");
  test::write_file(dir.file("cmu/splits.txt"), "train 08_01.bvh\nheldout 07_01.bvh\n");
  fs::copy_file(mocap / "bandai/dataset-1/dataset-1_bow_normal_001.bvh",
                dir.path() / "other/bow.bvh");
  const std::vector<std::string> small = {"--yaw-steps", "2",          "--heights",
                                          "1.5",         "--clusters", "4"};

  auto build = [&](const std::string& name, std::vector<std::string> args) {
    args.insert(args.begin(), "build");
    args.insert(args.begin(), "db");
    args.insert(args.end(), small.begin(), small.end());
    args.insert(args.end(), {"--out", dir.file(name)});
    test::Mocap run(dir, name, args);
    EXPECT_EQ(run.wait(120s), 0) << run.err();
    test::Mocap info(dir, name + "-info", {"db", "info", dir.file(name), "--json"});
    EXPECT_EQ(info.wait(60s), 0) << info.err();
    return nlohmann::json::parse(info.out());
  };
  const auto j = build("mixed.mdb", {dir.file("cmu"), dir.file("other"), "--split", "train"});
  EXPECT_EQ(j.at("body"), "canonical");  // the default
  EXPECT_EQ(j.at("build").at("body"), "canonical");
  EXPECT_EQ(j.at("families").at("cmu31").at("clips"), 1);
  EXPECT_EQ(j.at("families").at("bandai").at("clips"), 1);
  for (const auto& clip : j.at("clip_list")) EXPECT_NE(clip.at("name"), "07_01.bvh");

  const auto s = build("source.mdb", {dir.file("cmu"), "--body", "source"});
  EXPECT_EQ(s.at("body"), "source");
  EXPECT_EQ(s.at("families").at("cmu31").at("clips"), 2);  // no --split: every file

  test::Mocap text(dir, "info-text", {"db", "info", dir.file("mixed.mdb")});
  EXPECT_EQ(text.wait(60s), 0);
  EXPECT_NE(text.out().find("body         canonical"), std::string::npos) << text.out();
  EXPECT_NE(text.out().find("bandai"), std::string::npos) << text.out();

  // cmu_daz holds trials of the held-out subjects: a database with them says so.
  fs::create_directories(dir.path() / "daz");
  fs::copy_file(mocap / "cmu_daz/07_01.bvh", dir.path() / "daz/07_01.bvh");
  test::Mocap daz(dir, "daz",
                  {"db", "build", dir.file("daz"), "--yaw-steps", "2", "--heights", "1.5",
                   "--clusters", "4", "--out", dir.file("daz.mdb")});
  EXPECT_EQ(daz.wait(120s), 0) << daz.err();
  EXPECT_NE(daz.err().find("held-out"), std::string::npos) << daz.err();

  test::Mocap bad(dir, "bad-body",
                  {"db", "build", dir.file("cmu"), "--body", "giant", "--out", dir.file("x.mdb")});
  EXPECT_EQ(bad.wait(60s), 1);
  EXPECT_NE(bad.err().find("--body"), std::string::npos) << bad.err();
  test::Mocap no_split(
      dir, "no-split",
      {"db", "build", dir.file("other"), "--split", "train", "--out", dir.file("y.mdb")});
  EXPECT_EQ(no_split.wait(60s), 1);
  EXPECT_NE(no_split.err().find("splits.txt"), std::string::npos) << no_split.err();
}

}  // namespace
}  // namespace mocap
