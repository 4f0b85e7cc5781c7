// Person proposals (detect/person_proposals.hpp): the tiles a frame is cut into, and the real
// MB3-CenterNet on a real frame, stretched and on tiles.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "detect/centernet.hpp"
#include "detect/image_tensor.hpp"
#include "detect/model_files.hpp"
#include "detect/person_proposals.hpp"
#include "found_again.hpp"
#include "support/images.hpp"

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

TEST(PersonProposalTiles, TheWholeFrameComesLastWhenAdded) {
  const auto tiles = proposal_tiles(1280, 720, 2, true);
  ASSERT_EQ(tiles.size(), 3u);
  EXPECT_FLOAT_EQ(tiles[0].side, 720);
  EXPECT_FLOAT_EQ(tiles[1].side, 720);
  EXPECT_EQ(tiles[2].side, 0.0f);
  EXPECT_EQ(proposal_tiles(1280, 720, 1, true).size(), 1u);  // one tile is the whole frame
}

// The real CenterNet and a picture, or a skip naming what is absent.
TEST(CenternetAtAspect, TheShortSideAt512TheLongSideScaledToTheStride) {
  EXPECT_EQ(centernet_input_at_aspect(1280, 720), std::pair(512, 896));  // video.avi
  EXPECT_EQ(centernet_input_at_aspect(768, 576), std::pair(512, 672));   // vtest.avi
  EXPECT_EQ(centernet_input_at_aspect(480, 640), std::pair(672, 512));   // portrait
  EXPECT_EQ(centernet_input_at_aspect(600, 600), std::pair(512, 512));
}

class PersonProposals : public ::testing::Test {
 protected:
  void load(const fs::path& image_file) {
    fs::path model;
    try {
      model = cached_model_json("centernet");
    } catch (const ModelMissing& e) {
      GTEST_SKIP() << e.what();
    }
    if (!fs::exists(image_file)) GTEST_SKIP() << "picture absent: " << image_file;
    const cv::Mat pixels = cv::imread(image_file.string());
    ASSERT_FALSE(pixels.empty()) << image_file;
    frame = test::image_of(pixels);
    network.emplace(model);
  }
  std::vector<Detection> propose(const ProposalOptions& options) {
    return propose_people(*network, frame, options, input);
  }

  ImageBuffer frame;
  std::optional<CenternetNetwork> network;
  GraphTensor input;
};

// The graph fed at the frame's aspect (its frozen upsampling sizes scaled): heads of the input's
// quarter size, and the walkers of vtest frame 300 the squeezed frame finds at 0.5 found again
// there (768 × 576 at 512 × 672). Sides that are not multiples of the graph's stride are refused.
TEST_F(PersonProposals, CenternetAtTheFramesAspectFindsWhatTheSqueezedFrameFinds) {
  ASSERT_NO_FATAL_FAILURE(load(test::kVtestFrame300));
  if (IsSkipped()) return;
  ProposalOptions confident;
  confident.min_score = 0.5f;
  const auto squeezed = propose(confident);
  ASSERT_GE(squeezed.size(), 3u) << "the walkers of frame 300 score 0.55-0.67";
  const auto [height, width] = centernet_input_at_aspect(frame.width(), frame.height());
  CenternetNetwork at_aspect(cached_model_json("centernet"), height, width);
  image_batch(input, 1, height, width);
  fill_stretched(frame, input, 0);
  const auto& heads = at_aspect.run(input);
  EXPECT_EQ(heads[0].shape, (std::vector<std::int64_t>{1, height / 4, width / 4, 80}));
  ProposalOptions low = confident;
  low.min_score = 0.3f;  // scores move with the scale; the boxes must be there
  const auto found = propose_people(at_aspect, frame, low, input);
  for (const Detection& s : squeezed) {
    EXPECT_TRUE(test::found_again(s.box, found))
        << "a person at x " << s.box.x << ", y " << s.box.y << " lost at aspect";
  }
  ProposalOptions tiled;
  tiled.tiles = 2;
  EXPECT_THROW(propose_people(at_aspect, frame, tiled, input), std::invalid_argument);
  EXPECT_THROW(CenternetNetwork(cached_model_json("centernet"), 500, 896), std::invalid_argument);
}

TEST_F(PersonProposals, TilesFindThePeopleTheStretchedFrameFinds) {
  ASSERT_NO_FATAL_FAILURE(load(test::kVtestFrame300));
  if (IsSkipped()) return;
  ProposalOptions whole;
  whole.min_score = 0.5f;
  const auto stretched = propose(whole);
  ASSERT_GE(stretched.size(), 3u) << "the walkers of frame 300 score 0.55-0.67";
  ProposalOptions tiled;
  tiled.tiles = 2;
  const auto found = propose(tiled);
  for (const Detection& s : stretched) {
    EXPECT_TRUE(test::found_again(s.box, found))
        << "a person at x " << s.box.x << ", y " << s.box.y << " lost on the tiles";
  }
  for (const Detection& t : found) {  // boxes in frame pixels, best first
    EXPECT_GE(t.score, tiled.min_score);
    EXPECT_GT(t.box.x + t.box.width, 0);
    EXPECT_LT(t.box.x, frame.width());
  }
  for (std::size_t i = 1; i < found.size(); ++i) EXPECT_GE(found[i - 1].score, found[i].score);
}

// COCO_val2014_000000000241 (480 x 640, portrait): the man in front is 612 px tall, taller than
// a 480-px tile, so each tile sees only part of him; the whole-frame pass sees him whole, and
// the merged proposals keep that box and what either pass found.
TEST_F(PersonProposals, TheWholeFramePassBringsBackAPersonLargerThanTheTiles) {
  ASSERT_NO_FATAL_FAILURE(load(fs::path("..") / "shared" / "data" / "eval" /
                               "openpose_examples_media" / "COCO_val2014_000000000241.jpg"));
  if (IsSkipped()) return;
  ProposalOptions whole, tiled, both;
  tiled.tiles = both.tiles = 2;
  both.whole_frame = true;
  const auto from_whole = propose(whole);
  const auto from_tiles = propose(tiled);
  const auto merged = propose(both);
  const Box2D front{126, 4, 206, 612};  // the hand-checked box (tests/data/detection)
  const auto finds = [&](const std::vector<Detection>& found, const Box2D& box) {
    return std::any_of(found.begin(), found.end(),
                       [&](const Detection& d) { return iou(d.box, box) >= 0.5f; });
  };
  // Each tile outlines the part of him it sees (two boxes, IoU 0.66 and 0.70 with his); the
  // whole frame outlines all of him, and NMS keeps that box alone.
  const auto near_him = [&](const std::vector<Detection>& found) {
    std::vector<float> overlaps;
    for (const Detection& d : found)
      if (iou(d.box, front) >= 0.3f) overlaps.push_back(iou(d.box, front));
    return overlaps;
  };
  const auto cut = near_him(from_tiles);
  EXPECT_GE(cut.size(), 2u) << "the tiles alone should see him in parts";
  for (const float v : cut) EXPECT_LT(v, 0.8f);
  const auto whole_man = near_him(merged);
  ASSERT_EQ(whole_man.size(), 1u);
  EXPECT_GT(whole_man.front(), 0.8f);
  EXPECT_TRUE(finds(from_whole, front));
  EXPECT_TRUE(finds(merged, front));
  for (const auto* found : {&from_whole, &from_tiles})
    for (const Detection& d : *found)
      EXPECT_TRUE(finds(merged, d.box)) << d.box.x << " " << d.box.y;
  for (std::size_t i = 1; i < merged.size(); ++i) EXPECT_GE(merged[i - 1].score, merged[i].score);
}

}  // namespace
}  // namespace mocap::detect
