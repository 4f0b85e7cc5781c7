#include "posedb/database.hpp"

#include <filesystem>
#include <fstream>
#include <random>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "core/input_error.hpp"
#include "motion/canonical_body.hpp"
#include "motion/cmu_asf_fixture.hpp"
#include "posedb/builder.hpp"
#include "posedb/cluster_search.hpp"
#include "posedb/database_format.hpp"
#include "posedb/exact_search.hpp"
#include "support/shared_data.hpp"

namespace mocap::posedb {
namespace {

namespace fs = std::filesystem;

// One small database shared by the tests of this file: two CMU clips and one Bandai clip.
class DatabaseTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const fs::path mocap = test::shared_data() / "mocap";
    if (!fs::exists(mocap / "bandai/dataset-1/dataset-1_bow_normal_001.bvh")) return;
    dir_ = std::make_unique<test::TempDir>();
    BuildOptions options;
    options.clusters = 64;
    options.views.yaw_steps = 12;
    BuildReport report;
    contents_ = std::make_unique<DatabaseContents>(
        build_database({(mocap / "cmu31/08_01.bvh").string(), (mocap / "cmu31/09_10.bvh").string(),
                        (mocap / "bandai/dataset-1/dataset-1_bow_normal_001.bvh").string(),
                        (mocap / "missing.bvh").string()},
                       options, {}, report));
    report_ = report;
    path_ = dir_->file("small.mdb");
    write_database(*contents_, path_);
  }
  static void TearDownTestSuite() {
    contents_.reset();
    dir_.reset();
  }
  void SetUp() override {
    if (!contents_) GTEST_SKIP() << "shared mocap data absent (../shared/data/mocap)";
  }

  static std::string corrupted_copy(const std::string& name,
                                    const std::function<void(std::string&)>& edit) {
    std::ifstream in(path_, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), {});
    edit(bytes);
    const std::string out = dir_->file(name);
    std::ofstream(out, std::ios::binary)
        .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return out;
  }

  static inline std::unique_ptr<test::TempDir> dir_;
  static inline std::unique_ptr<DatabaseContents> contents_;
  static inline BuildReport report_;
  static inline std::string path_;
};

TEST_F(DatabaseTest, BuildDropsReferenceAndBlankFramesAndReportsBadFiles) {
  EXPECT_EQ(report_.files_read, 3u);
  ASSERT_EQ(report_.skipped.size(), 1u);
  EXPECT_NE(report_.skipped[0].find("missing.bvh"), std::string::npos);
  EXPECT_EQ(report_.blank_frames_dropped, 4u);      // 09_10 frames 1-4 are all zero
  EXPECT_EQ(report_.reference_frames_dropped, 2u);  // the two cgspeed T-poses; Bandai has none
  // 08_01: 277 motion frames at 120 fps -> 56 at 24 fps; 09_10: frames 5..132 -> 26;
  // Bandai bow normal: frames @24 from clips.tsv.
  const auto& clips = contents_->clips;
  ASSERT_EQ(clips.size(), 3u);
  EXPECT_EQ(clips[0].frame_count, 56u);
  EXPECT_EQ(clips[1].frame_count, 26u);
  EXPECT_EQ(clips[1].source_first_frame, 5u);
  EXPECT_EQ(clips[2].family, "bandai");
}

TEST_F(DatabaseTest, OpensWithEverythingItWasBuiltWith) {
  const Database db = Database::open(path_);
  EXPECT_EQ(db.clips().size(), 3u);
  EXPECT_EQ(db.views().size(), 48u);
  EXPECT_EQ(db.projections().rows, contents_->projection_records.size());
  EXPECT_EQ(db.projections().rows, db.frames().size() * 48);
  EXPECT_EQ(db.centroids().rows, 64u);
  EXPECT_EQ(db.clips()[0].skeleton.joint_count(), contents_->clips[0].skeleton.joint_count());
  EXPECT_EQ(db.build_info().views.yaw_steps, 12);
  // Root-relative joints: the root is at the origin, and the body faces +Z (left hip on +X).
  for (std::uint32_t f = 0; f < db.frames().size(); f += 17) {
    const auto j = db.joints(f);
    EXPECT_NEAR(j[3 * index(Joint::root)], 0.0f, 1e-6);
    EXPECT_GT(j[3 * index(Joint::left_hip)], j[3 * index(Joint::right_hip)]);
    EXPECT_EQ(db.rotations(f).size(), 4u * db.clips()[db.frames()[f].clip].skeleton.joint_count());
  }
}

TEST_F(DatabaseTest, EveryProjectionFindsItself) {
  const Database db = Database::open(path_);
  const ExactSearch exact(db.projections());
  const ClusterSearch clusters(db.projections(), db.centroids(), db.cluster_begin(), 1);
  std::vector<Neighbor> found;
  std::mt19937 rng(1);
  for (int trial = 0; trial < 300; ++trial) {
    const std::size_t i = rng() % db.projections().rows;
    for (const SearchIndex* index :
         {static_cast<const SearchIndex*>(&exact), static_cast<const SearchIndex*>(&clusters)}) {
      index->search(db.projections().row(i), nullptr, 1, found);
      ASSERT_EQ(found.size(), 1u);
      EXPECT_EQ(found[0].distance, 0.0f) << index->name();
      // Identical rows may exist (a still pose); then any of them is a correct answer.
      if (found[0].index != i) {
        EXPECT_TRUE(std::equal(db.projections().row(i), db.projections().row(i) + kPoseDims,
                               db.projections().row(found[0].index)));
      }
    }
  }
}

void expect_refused(const std::string& path, const std::string& fragment) {
  try {
    Database::open(path);
    ADD_FAILURE() << "opened a bad file, expected: " << fragment;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST_F(DatabaseTest, CorruptedTruncatedAndForeignFilesAreRefused) {
  expect_refused(corrupted_copy("trunc.mdb", [](std::string& b) { b.resize(b.size() / 2); }),
                 "truncated");
  expect_refused(corrupted_copy("empty.mdb", [](std::string& b) { b.clear(); }), "too small");
  expect_refused(corrupted_copy("magic.mdb", [](std::string& b) { b[0] = 'X'; }),
                 "not a mocap pose database");
  expect_refused(corrupted_copy("version.mdb", [](std::string& b) { b[8] = 9; }), "newer");
  expect_refused(corrupted_copy("flip.mdb", [](std::string& b) { b[b.size() - 100] ^= 0x40; }),
                 "checksum");
  expect_refused(corrupted_copy("table.mdb", [](std::string& b) { b[40] ^= 1; }), "checksum");
  expect_refused(dir_->file("absent.mdb"), "cannot open");
  const std::string bvh = (test::shared_data() / "mocap/cmu31/08_01.bvh").string();
  expect_refused(bvh, "not a mocap pose database");
}

TEST_F(DatabaseTest, RandomDamageNeverCrashes) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 40; ++trial) {
    const std::string p = corrupted_copy("random.mdb", [&](std::string& b) {
      for (int e = 0; e < 4; ++e) b[rng() % b.size()] = static_cast<char>(rng());
    });
    try {
      Database::open(p);
    } catch (const InputError&) {
    }
  }
}

TEST(DatabaseFiles, CollectFindsBvhAndRejectsOthers) {
  MOCAP_REQUIRE_SHARED("mocap/cmu_daz");
  const auto files = collect_motion_files({(test::shared_data() / "mocap/cmu_daz").string()});
  EXPECT_EQ(files.size(), 5u);
  EXPECT_THROW(collect_motion_files({"/nonexistent/folder"}), InputError);
  EXPECT_THROW(collect_motion_files({(test::shared_data() / "mocap/README.md").string()}),
               InputError);
}

}  // namespace
}  // namespace mocap::posedb

namespace mocap::posedb {
namespace {

// A folder of CMU-style ASF/AMC files builds like BVH: the .amc finds its subject's .asf.
TEST(DatabaseFiles, AsfAmcFolderBuilds) {
  test::TempDir dir;
  std::filesystem::create_directories(dir.path() / "42");
  std::ofstream(dir.path() / "42" / "42.asf") << test::cmu_like_asf();
  std::ofstream(dir.path() / "42" / "42_01.amc") << test::cmu_like_amc(240);
  std::ofstream(dir.path() / "42" / "42_02.amc") << "garbage\n";
  const auto files = collect_motion_files({dir.path().string()});
  ASSERT_EQ(files.size(), 2u);
  BuildOptions options;
  options.clusters = 8;
  BuildReport report;
  const DatabaseContents db = build_database(files, options, {}, report);
  ASSERT_EQ(report.skipped.size(), 1u);
  EXPECT_NE(report.skipped[0].find("42_02.amc"), std::string::npos) << report.skipped[0];
  ASSERT_EQ(db.clips.size(), 1u);
  EXPECT_EQ(db.clips[0].family, "cmu_asf");
  EXPECT_EQ(db.clips[0].frame_count, 48u);  // 240 frames at 120 fps -> 48 at 24 fps
  EXPECT_EQ(db.projection_records.size(), 48u * 120u);
}

}  // namespace
}  // namespace mocap::posedb

namespace mocap::posedb {
namespace {

// --body canonical: CMU and Bandai clips on one body, every bone at its canonical length, the
// source rotations and frame bookkeeping as with --body source; the choice survives the file.
TEST(CanonicalDatabase, EveryFamilyOnTheCanonicalBodyWithItsRotationsKept) {
  const fs::path mocap = test::shared_data() / "mocap";
  MOCAP_REQUIRE_SHARED("mocap/bandai/dataset-1/dataset-1_bow_normal_001.bvh");
  const std::vector<std::string> files = {
      (mocap / "cmu31/08_01.bvh").string(),
      (mocap / "bandai/dataset-1/dataset-1_bow_normal_001.bvh").string()};
  BuildOptions options;
  options.clusters = 16;
  options.views.yaw_steps = 4;
  BuildReport report;
  const DatabaseContents source = build_database(files, options, {}, report);
  options.body = BodyChoice::canonical;
  const DatabaseContents canonical = build_database(files, options, {}, report);
  EXPECT_EQ(source.build.body, BodyChoice::source);
  ASSERT_EQ(canonical.frames.size(), source.frames.size());
  EXPECT_EQ(canonical.rotations, source.rotations);
  const motion::BodyProportions& c = motion::canonical_proportions();
  float bandai_source_shoulders = 0.0f;
  for (std::size_t f = 0; f < canonical.frames.size(); ++f) {
    motion::Body15 body, src;
    for (int j = 0; j < kBodyJoints; ++j) {
      const std::size_t at = (f * kBodyJoints + j) * 3;
      body[j] = {canonical.joints[at], canonical.joints[at + 1], canonical.joints[at + 2]};
      src[j] = {source.joints[at], source.joints[at + 1], source.joints[at + 2]};
    }
    const motion::BodyProportions got = motion::proportions_of(body);
    for (int j = 0; j < kBodyJoints; ++j) ASSERT_NEAR(got.bone_m[j], c.bone_m[j], 1e-4f) << f;
    if (canonical.frames[f].clip == 1)
      bandai_source_shoulders =
          glm::distance(src[index(Joint::left_shoulder)], src[index(Joint::right_shoulder)]);
  }
  EXPECT_LT(bandai_source_shoulders, 0.25f);  // the source body differs: Bandai's 205 mm
  for (const auto& clip : canonical.clips)
    EXPECT_NE(clip.mapping.find("canonical body"), std::string::npos) << clip.mapping;

  test::TempDir dir;
  write_database(canonical, dir.file("canonical.mdb"));
  const Database db = Database::open(dir.file("canonical.mdb"));
  EXPECT_EQ(db.build_info().body, BodyChoice::canonical);
  EXPECT_EQ(db.clips()[1].family, "bandai");
}

// Files written before the body choice existed have no "body" entry: they are on the source
// body. An unknown body name is refused.
TEST(CanonicalDatabase, OptionsWithoutBodyReadAsSource) {
  BuildInfo info;
  info.body = BodyChoice::canonical;
  nlohmann::json j = nlohmann::json::parse(format::build_info_to_json(info));
  EXPECT_EQ(j.at("body"), "canonical");
  EXPECT_EQ(format::build_info_from_json(j.dump()).body, BodyChoice::canonical);
  j.erase("body");
  EXPECT_EQ(format::build_info_from_json(j.dump()).body, BodyChoice::source);
  j["body"] = "giant";
  EXPECT_THROW(format::build_info_from_json(j.dump()), std::exception);
}

}  // namespace
}  // namespace mocap::posedb
