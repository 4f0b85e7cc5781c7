// The MoveNet decoder on hand-made head tensors: centre peaks and their order, boxes, joints
// found near the regressed position inside the box, scores, and the mapping to image pixels.

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "detect/movenet_decoder.hpp"

namespace mocap::detect {
namespace {

constexpr int kGrid = 16;  // a 64×64 input tensor
constexpr float kLow = -10.0f;

float sigmoid(float v) { return 1.0f / (1.0f + std::exp(-v)); }

struct Builder {
  MovenetHeads h;
  Builder() {
    h.height = h.width = kGrid;
    const std::size_t cells = kGrid * kGrid;
    h.center.assign(cells, kLow);
    h.box_scale.assign(2 * cells, 0.0f);
    h.box_offset.assign(2 * cells, 0.0f);
    h.heatmap.assign(kMovenetKeypoints * cells, kLow);
    h.regress.assign(2 * kMovenetKeypoints * cells, 0.0f);
    h.offset.assign(2 * kMovenetKeypoints * cells, 0.0f);
  }
  // NHWC: the channel count is the head's size over the cells.
  static void set(std::vector<float>& head, int c, int y, int x, float v) {
    const std::size_t channels = head.size() / (kGrid * kGrid);
    head[(static_cast<std::size_t>(y) * kGrid + x) * channels + c] = v;
  }
  // A person centred on cell (cy, cx) with a box of bh × bw cells and every joint regressed to
  // (cy + dy, cx + dx) where its heatmap peaks.
  void person(int cy, int cx, float logit, float bh, float bw, int dy, int dx) {
    set(h.center, 0, cy, cx, logit);
    set(h.box_scale, 0, cy, cx, bh);
    set(h.box_scale, 1, cy, cx, bw);
    for (int k = 0; k < kMovenetKeypoints; ++k) {
      set(h.regress, 2 * k, cy, cx, static_cast<float>(dy));
      set(h.regress, 2 * k + 1, cy, cx, static_cast<float>(dx));
      set(h.heatmap, k, cy + dy, cx + dx, 3.0f);
      set(h.offset, 2 * k, cy + dy, cx + dx, 0.25f);
      set(h.offset, 2 * k + 1, cy + dy, cx + dx, -0.5f);
    }
  }
};

constexpr int kScore = 3 * kMovenetKeypoints + 4;

TEST(MovenetDecoder, OnePersonGivesItsBoxJointsAndScore) {
  Builder b;
  b.person(8, 6, 2.0f, 8.0f, 6.0f, 2, 1);
  b.set(b.h.box_offset, 0, 8, 6, 0.5f);  // the box centre sits half a cell lower
  const auto rows = decode_movenet(b.h);
  const MovenetRow& r = rows[0];
  const int box = 3 * kMovenetKeypoints;
  EXPECT_FLOAT_EQ(r[box + 0], (8.5f - 4.0f) / kGrid);
  EXPECT_FLOAT_EQ(r[box + 1], (6.0f - 3.0f) / kGrid);
  EXPECT_FLOAT_EQ(r[box + 2], (8.5f + 4.0f) / kGrid);
  EXPECT_FLOAT_EQ(r[box + 3], (6.0f + 3.0f) / kGrid);
  for (int k = 0; k < kMovenetKeypoints; ++k) {
    EXPECT_FLOAT_EQ(r[3 * k], (10.0f + 0.25f) / kGrid);
    EXPECT_FLOAT_EQ(r[3 * k + 1], (7.0f - 0.5f) / kGrid);
    EXPECT_FLOAT_EQ(r[3 * k + 2], sigmoid(3.0f));  // exactly on the regressed cell: weight 1
  }
  EXPECT_NEAR(r[kScore], sigmoid(2.0f) * sigmoid(3.0f), 1e-6);
}

TEST(MovenetDecoder, AlwaysSixRowsInCentreScoreOrderTiesToTheLowerIndex) {
  Builder b;
  b.person(12, 12, 1.0f, 4.0f, 4.0f, 0, 0);
  b.person(4, 4, 2.0f, 4.0f, 4.0f, 0, 0);
  const auto rows = decode_movenet(b.h);
  const int box = 3 * kMovenetKeypoints;
  EXPECT_FLOAT_EQ(rows[0][box], 2.0f / kGrid);   // the (4, 4) person: box from row 2
  EXPECT_FLOAT_EQ(rows[1][box], 10.0f / kGrid);  // then the (12, 12) one
  // The flat background peaks everywhere away from the people; the first flat cells by index
  // win: (0, 0) .. (0, 3), with empty boxes at their corners.
  for (int i = 2; i < 6; ++i) {
    EXPECT_FLOAT_EQ(rows[i][box + 1], static_cast<float>(i - 2) / kGrid);
    EXPECT_FLOAT_EQ(rows[i][box], 0.0f);
    EXPECT_FLOAT_EQ(rows[i][kScore], 0.0f);  // no joint inside an empty box
  }
}

TEST(MovenetDecoder, OnlyTheLargestCentreWithinFiveByFiveSurvives) {
  Builder b;
  b.person(8, 8, 2.0f, 4.0f, 4.0f, 0, 0);
  b.person(8, 10, 1.0f, 4.0f, 4.0f, 0, 0);  // two cells away: suppressed
  b.person(8, 13, 0.5f, 4.0f, 4.0f, 0, 0);  // three beyond that: its own peak
  const auto rows = decode_movenet(b.h);
  const int box = 3 * kMovenetKeypoints;
  EXPECT_FLOAT_EQ(rows[0][box + 1], 6.0f / kGrid);
  EXPECT_FLOAT_EQ(rows[1][box + 1], 11.0f / kGrid);
  EXPECT_GT(rows[1][kScore], 0.1f);
  EXPECT_LT(rows[2][kScore], 1e-3f);  // the background
}

TEST(MovenetDecoder, JointsFarFromTheRegressedPositionScoreLessAndOutsideTheBoxNotAtAll) {
  Builder b;
  b.person(8, 8, 2.0f, 6.0f, 6.0f, 0, 0);
  b.set(b.h.regress, 0, 8, 8, 2.0f);  // the nose regressed two cells lower than its peak
  b.set(b.h.heatmap, 1, 8, 8, kLow);  // left eye: its only strong peak is outside the box
  b.set(b.h.heatmap, 1, 0, 15, 5.0f);
  const auto r = decode_movenet(b.h)[0];
  const float denom = 0.30004883f * kGrid;
  EXPECT_NEAR(r[2], sigmoid(3.0f) * std::exp(-4.0f / denom), 1e-6);
  EXPECT_NEAR(r[3 * 1 + 2], sigmoid(kLow), 1e-6);  // the best it finds inside is the background
}

TEST(MovenetDecoder, NegativeBoxScaleGivesAnEmptyBoxAndJointsAtCellZero) {
  Builder b;
  b.person(8, 8, 2.0f, -3.0f, 4.0f, 0, 0);
  const auto r = decode_movenet(b.h)[0];
  EXPECT_FLOAT_EQ(r[0], 0.0f);
  EXPECT_FLOAT_EQ(r[1], 0.0f);
  EXPECT_FLOAT_EQ(r[kScore], 0.0f);
}

TEST(MovenetDecoder, RefusesHeadsOfTheWrongSize) {
  Builder b;
  b.h.heatmap.pop_back();
  EXPECT_THROW(decode_movenet(b.h), std::invalid_argument);
}

TEST(MovenetDecoder, SelectPeopleAppliesThresholdsSortsAndMapsToPixels) {
  std::array<MovenetRow, kMovenetInstances> rows{};
  rows[0][kScore] = 0.3f;
  rows[1][kScore] = 0.5f;
  rows[2][kScore] = 0.1f;  // below the person threshold
  rows[1][0] = 0.5f;       // nose y, x normalised
  rows[1][1] = 0.25f;
  rows[1][2] = 0.9f;
  rows[1][5] = 0.2f;  // left eye below the keypoint threshold
  const int box = 3 * kMovenetKeypoints;
  rows[1][box] = 0.25f;
  rows[1][box + 1] = 0.5f;
  rows[1][box + 2] = 0.75f;
  rows[1][box + 3] = 1.0f;
  // A 256×192 tensor from a 768×576 frame (scale 1/3) padded 10 px on the left.
  const TensorMapping mapping{256, 192, 1.0f / 3.0f, 1.0f / 3.0f, 10.0f, 0.0f};
  const auto people =
      select_people(rows, mapping, {.min_person_score = 0.25f, .min_keypoint_score = 0.3f});
  ASSERT_EQ(people.size(), 2u);
  EXPECT_FLOAT_EQ(people[0].score, 0.5f);
  EXPECT_FLOAT_EQ(people[1].score, 0.3f);
  EXPECT_NEAR(people[0].keypoints[0].x, (64.0f - 10.0f) * 3.0f, 1e-3);
  EXPECT_NEAR(people[0].keypoints[0].y, 96.0f * 3.0f, 1e-3);
  EXPECT_FLOAT_EQ(people[0].keypoints[0].confidence, 0.9f);
  EXPECT_TRUE(std::isnan(people[0].keypoints[1].x));
  EXPECT_EQ(people[0].keypoints[1].confidence, 0.0f);
  EXPECT_NEAR(people[0].box.x, (128.0f - 10.0f) * 3.0f, 1e-3);
  EXPECT_NEAR(people[0].box.y, 48.0f * 3.0f, 1e-3);
  EXPECT_NEAR(people[0].box.width, 128.0f * 3.0f, 1e-3);
  EXPECT_NEAR(people[0].box.height, 96.0f * 3.0f, 1e-3);
}

}  // namespace
}  // namespace mocap::detect
