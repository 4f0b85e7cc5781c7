// Person proposals (detect/person_proposals.hpp): the tiles a frame is cut into, and the real
// MB3-CenterNet on a real frame, stretched and on tiles.

#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>

#include "detect/model_files.hpp"
#include "detect/person_proposals.hpp"

namespace mocap::detect {
namespace {

namespace fs = std::filesystem;

TEST(PersonProposalTiles, SquareTilesOfTheShortSideSpreadAlongTheLongSide) {
  const auto two = proposal_tiles(1280, 720, 2);
  ASSERT_EQ(two.size(), 2u);
  EXPECT_FLOAT_EQ(two[0].cx, 360);
  EXPECT_FLOAT_EQ(two[1].cx, 920);
  for (const auto& t : two) {
    EXPECT_FLOAT_EQ(t.cy, 360);
    EXPECT_FLOAT_EQ(t.side, 720);
  }
  const auto three = proposal_tiles(1280, 720, 3);
  ASSERT_EQ(three.size(), 3u);
  EXPECT_FLOAT_EQ(three[1].cx, 640);
  const auto tall = proposal_tiles(480, 640, 2);  // portrait: tiles down the frame
  ASSERT_EQ(tall.size(), 2u);
  EXPECT_FLOAT_EQ(tall[0].cy, 240);
  EXPECT_FLOAT_EQ(tall[1].cy, 400);
  EXPECT_FLOAT_EQ(tall[1].cx, 240);
}

TEST(PersonProposalTiles, OneTileOrASquareFrameIsTheWholeFrameStretched) {
  for (const auto& tiles : {proposal_tiles(1280, 720, 1), proposal_tiles(600, 600, 3)}) {
    ASSERT_EQ(tiles.size(), 1u);
    EXPECT_EQ(tiles[0].side, 0.0f);
  }
  EXPECT_THROW(proposal_tiles(1280, 720, 0), std::invalid_argument);
}

// vtest.avi frame 300 (768 x 576, walkers 60-110 px tall), the golden tests' frame.
TEST(PersonProposals, TilesFindThePeopleTheStretchedFrameFinds) {
  const fs::path frame_file =
      fs::path("..") / "shared" / "docs" / "models" / "movenet-multipose" / "vtest-f300.png";
  fs::path model;
  try {
    model = cached_model_json("centernet");
  } catch (const ModelMissing& e) {
    GTEST_SKIP() << e.what();
  }
  if (!fs::exists(frame_file)) GTEST_SKIP() << "reference frame absent: " << frame_file;
  auto pixels = std::make_shared<cv::Mat>(cv::imread(frame_file.string()));
  ASSERT_FALSE(pixels->empty());
  const ImageBuffer frame(pixels->cols, pixels->rows, static_cast<int>(pixels->step[0]),
                          PixelFormat::bgr8, pixels,
                          reinterpret_cast<const std::byte*>(pixels->data));
  CenternetNetwork network(model);
  GraphTensor input;
  ProposalOptions whole;
  whole.min_score = 0.5f;
  const auto stretched = propose_people(network, frame, whole, input);
  ASSERT_GE(stretched.size(), 3u) << "the walkers of frame 300 score 0.55-0.67";
  ProposalOptions tiled;
  tiled.tiles = 2;
  const auto found = propose_people(network, frame, tiled, input);
  for (const Detection& s : stretched) {
    bool again = false;
    for (const Detection& t : found) again = again || iou(s.box, t.box) > 0.5f;
    EXPECT_TRUE(again) << "a person at x " << s.box.x << ", y " << s.box.y << " lost on the tiles";
  }
  for (const Detection& t : found) {  // boxes in frame pixels, best first
    EXPECT_GE(t.score, tiled.min_score);
    EXPECT_GT(t.box.x + t.box.width, 0);
    EXPECT_LT(t.box.x, frame.width());
  }
  for (std::size_t i = 1; i < found.size(); ++i) EXPECT_GE(found[i - 1].score, found[i].score);
}

}  // namespace
}  // namespace mocap::detect
