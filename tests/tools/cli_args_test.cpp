// The command line's shared pieces: numeric options checked against their declared range when the
// line is parsed (NaN, infinities, negatives, zero, ports, lists, image sizes); an output that is
// an input found through symlinks, `..` and hard links; files written whole or not at all; JSON
// that stays valid whatever bytes a path holds; reconstruct's output files told by name.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include <nlohmann/json.hpp>

#include "cli_args.hpp"
#include "core/input_error.hpp"
#include "output_files.hpp"
#include "reconstruct_outputs.hpp"
#include "support/files.hpp"

namespace mocap::cli {
namespace {

namespace fs = std::filesystem;

// Parses `line` (space-separated) with an Args holding every kind of range; returns the exit code
// (-1 when parsing succeeded).
int parse(Args& args, const std::string& line) {
  std::vector<std::string> words;
  std::stringstream in(line);
  for (std::string w; in >> w;) words.push_back(w);
  std::vector<char*> argv;
  for (auto& w : words) argv.push_back(w.data());
  int code = -1;
  testing::internal::CaptureStderr();
  testing::internal::CaptureStdout();
  const bool ok = args.parse(static_cast<int>(argv.size()), argv.data(), code);
  testing::internal::GetCapturedStdout();
  const std::string err = testing::internal::GetCapturedStderr();
  if (!ok && code == 2) {
    EXPECT_NE(err.find("error: --"), std::string::npos) << err;
  }
  return ok ? -1 : code;
}

Args example() {
  Args args("test", "test");
  args.option("fps", "N", "rate", "24", Range::positive())
      .option("port", "P", "port", "8080", Range::count(0, 65535))
      .option("threads", "N", "threads", "2", Range::count(1, 64))
      .option("heights", "LIST", "heights", "1.5,2.5", Range::positive_list())
      .option("size", "WxH", "size", std::nullopt, Range::image_size())
      .option("scale", "auto|S", "scale", "auto", Range::positive().or_word("auto"))
      .option("hfov", "DEG", "fov", "60", Range::between(1.0, 179.0))
      .option("name", "TEXT", "unchecked");
  return args;
}

TEST(NumericOptions, NanInfinityNegativeAndZeroAreRefusedWhereTheyMakeNoSense) {
  for (const char* bad :
       {"--fps nan",     "--fps inf",     "--fps -inf",   "--fps -1",         "--fps 0",
        "--fps 1e999",   "--fps x",       "--fps=",       "--fps 3x",         "--heights nan",
        "--heights inf", "--heights -1",  "--heights 0",  "--heights 1.5,,2", "--heights 1.5,0",
        "--threads 0",   "--threads 1.5", "--threads 65", "--hfov 0",         "--hfov 180",
        "--hfov nan",    "--scale -1",    "--scale 0",    "--scale automatic"}) {
    Args args = example();
    EXPECT_EQ(parse(args, bad), 2) << bad;
  }
  Args args = example();
  ASSERT_EQ(parse(args,
                  "--fps 0.5 --heights 1,2.5,6 --threads 64 --hfov 179 --scale auto "
                  "--name nan"),
            -1);
  EXPECT_EQ(args.number("fps"), 0.5);
  EXPECT_EQ(args.numbers("heights"), (std::vector<double>{1.0, 2.5, 6.0}));
  EXPECT_EQ(args.integer("threads"), 64);
  EXPECT_EQ(args.get("scale"), "auto");
  EXPECT_EQ(args.get("name"), "nan");  // not a numeric option
  EXPECT_THROW(args.number("name"), InputError);
}

TEST(NumericOptions, PortsAreWithinTheTcpRange) {
  for (const char* bad : {"--port 99999", "--port 65536", "--port -1", "--port 80.5"}) {
    Args args = example();
    EXPECT_EQ(parse(args, bad), 2) << bad;
  }
  Args args = example();
  ASSERT_EQ(parse(args, "--port 65535"), -1);
  EXPECT_EQ(args.integer("port"), 65535);
}

TEST(NumericOptions, ImageSizesAreTwoPositiveWholeNumbers) {
  for (const char* bad : {"--size 0x10", "--size 10x0", "--size 10", "--size x10", "--size 10x",
                          "--size -5x10", "--size 1.5x10", "--size 70000x10", "--size nanxnan"}) {
    Args args = example();
    EXPECT_EQ(parse(args, bad), 2) << bad;
  }
  Args args = example();
  ASSERT_EQ(parse(args, "--size 1920x1080"), -1);
  EXPECT_EQ(args.image_size("size").width, 1920);
  EXPECT_EQ(args.image_size("size").height, 1080);
}

TEST(NumericOptions, HelpShowsEachRangeAndTheMessageNamesTheOption) {
  const Args args = example();
  const std::string help = args.help();
  EXPECT_NE(help.find("a whole number from 0 to 65535; default: 8080"), std::string::npos) << help;
  EXPECT_NE(help.find("comma-separated numbers, each > 0"), std::string::npos) << help;
  EXPECT_NE(help.find("auto or a number > 0"), std::string::npos) << help;
  EXPECT_EQ(Range::positive_list().check("1,nan"),
            "expected comma-separated numbers, each > 0, got '1,nan'");
}

TEST(OutputFiles, AnOutputIsAnInputThroughSymlinksDotDotAndHardLinks) {
  test::TempDir dir;
  const std::string input = dir.file("a.bvh");
  test::write_file(input, "HIERARCHY\n");
  fs::create_directories(dir.path() / "sub");
  fs::create_symlink(input, dir.file("link.bvh"));
  fs::create_hard_link(input, dir.file("hard.bvh"));
  EXPECT_TRUE(same_file(input, dir.file("sub/../a.bvh")));
  EXPECT_TRUE(same_file(input, dir.file("link.bvh")));
  EXPECT_TRUE(same_file(input, dir.file("hard.bvh")));
  EXPECT_FALSE(same_file(input, dir.file("b.bvh")));
  EXPECT_FALSE(same_file(input, dir.file("sub")));
  try {
    refuse_output_over_inputs({"--out", dir.file("link.bvh")}, {{"IN.bvh", input}});
    FAIL() << "not refused";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(dir.file("link.bvh")), std::string::npos) << what;
    EXPECT_NE(what.find("IN.bvh " + input), std::string::npos) << what;
  }
  EXPECT_NO_THROW(refuse_output_over_inputs({"--out", dir.file("b.bvh")}, {{"IN.bvh", input}}));
  EXPECT_EQ(test::read_file(input), "HIERARCHY\n");
}

TEST(OutputFiles, AFileIsWrittenWholeOrTheEarlierOneStays) {
  test::TempDir dir;
  const std::string file = dir.file("summary.json");
  write_file_atomically(file, "first\n");
  EXPECT_EQ(test::read_file(file), "first\n");
  write_file_atomically(file, "second\n");
  EXPECT_EQ(test::read_file(file), "second\n");
  EXPECT_FALSE(fs::exists(file + ".part"));
  // A folder that takes no new file: the write fails naming the file, the old one stays.
  if (geteuid() != 0) {
    fs::permissions(dir.path(), fs::perms::owner_read | fs::perms::owner_exec);
    try {
      write_file_atomically(file, "third\n");
      ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
    }
    fs::permissions(dir.path(), fs::perms::owner_all);
    EXPECT_EQ(test::read_file(file), "second\n");
  }
  // Not a regular file: written in place.
  EXPECT_NO_THROW(write_file_atomically("/dev/null", "x"));
}

TEST(OutputFiles, JsonStaysValidWithBytesThatAreNotUtf8) {
  const nlohmann::json j = {{"input", std::string("/tmp/caf\xe9/\xff.avi")}};
  const std::string text = json_text(j, 2);
  const auto back = nlohmann::json::parse(text);
  EXPECT_EQ(back.at("input").get<std::string>(), "/tmp/caf\xef\xbf\xbd/\xef\xbf\xbd.avi");
}

TEST(ReconstructOutputs, TheCommandsOwnFilesAreToldByName) {
  for (const char* name :
       {"poses.jsonl", "summary.json", "person_1.bvh", "person_12.bvh", "overlay.mp4",
        "overlay_000100.png", "person_3.bvh.part", "summary.json.part"})
    EXPECT_TRUE(is_reconstruct_output(name)) << name;
  for (const char* name : {"notes.txt", "person_.bvh", "person_x.bvh", "poses.jsonl.bak",
                           "camera.yml", "db.mdb", "me.bvh"})
    EXPECT_FALSE(is_reconstruct_output(name)) << name;
  test::TempDir dir;
  for (const char* name : {"person_10.bvh", "person_2.bvh", "notes.txt", "poses.jsonl"})
    test::write_file(dir.file(name), "x");
  const auto found = reconstruct_outputs_in(dir.path());
  ASSERT_EQ(found.size(), 3u);
  EXPECT_EQ(found[0].filename(), "person_2.bvh");  // natural order
  EXPECT_EQ(found[1].filename(), "person_10.bvh");
  const WrittenOutputs written = classify_outputs(found);
  EXPECT_EQ(written.bvh_ids, (std::vector<int>{2, 10}));
  EXPECT_EQ(written.poses.size(), 1u);
}

TEST(ReconstructOutputs, EarlierOutputIsRefusedOrSetAsideAndPutBackWhenTheRunWroteNothing) {
  test::TempDir dir;
  const fs::path out = dir.path() / "out";
  fs::create_directories(out);
  test::write_file((out / "poses.jsonl").string(), "{}\n");
  test::write_file((out / "notes.txt").string(), "mine");
  EXPECT_THROW(EarlierOutput::prepare(out, false), InputError);
  {
    EarlierOutput earlier = EarlierOutput::prepare(out, true);
    EXPECT_FALSE(fs::exists(out / "poses.jsonl"));  // aside while the run goes
    EXPECT_NE(earlier.settle(false).find("left as they were"), std::string::npos);
    EXPECT_EQ(test::read_file((out / "poses.jsonl").string()), "{}\n");
  }
  {
    EarlierOutput earlier = EarlierOutput::prepare(out, true);
    test::write_file((out / "person_1.bvh").string(), "new");
    EXPECT_NE(earlier.settle(true).find("replaced"), std::string::npos);
    EXPECT_FALSE(fs::exists(out / "poses.jsonl"));
    EXPECT_TRUE(fs::exists(out / "person_1.bvh"));
  }
  EXPECT_EQ(test::read_file((out / "notes.txt").string()), "mine");  // not an output: kept
  // A run killed while the earlier output was aside, having written nothing: put back next time.
  { EarlierOutput killed = EarlierOutput::prepare(out, true); }  // never settled
  EXPECT_FALSE(fs::exists(out / "person_1.bvh"));
  EXPECT_THROW(EarlierOutput::prepare(out, false), InputError);  // back, so refused
  EXPECT_EQ(test::read_file((out / "person_1.bvh").string()), "new");
}

}  // namespace
}  // namespace mocap::cli
