// detect::TopDownDetector on both cores: the crops of a frame shared by two single-thread copies
// of the keypoint network, CenterNet beside the followed people's crops, must find what one copy
// finds (same people, same keypoints); SinglePoseNetwork's run over part of a batch equals that
// part of the whole run; the profile counts what ran. Real models, a real vtest frame moving a
// few pixels per frame so that people are followed between detector runs.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "detect/model_files.hpp"
#include "detect/person_proposals.hpp"
#include "detect/topdown_detector.hpp"
#include "found_again.hpp"
#include "support/images.hpp"

namespace mocap::detect {
namespace {

namespace fs = std::filesystem;

const fs::path& kFrame = test::kVtestFrame300;

struct Models {
  fs::path lightning, centernet;
};

// The models and frame, or the reason to skip.
std::optional<Models> models(std::string& why) {
  try {
    Models m{cached_model_json(model_name(SinglePoseModel::lightning)),
             cached_model_json("centernet")};
    if (!fs::exists(kFrame)) {
      why = "reference frame absent: " + kFrame.string();
      return std::nullopt;
    }
    return m;
  } catch (const ModelMissing& e) {
    why = e.what();
    return std::nullopt;
  }
}

// The frame moved right by `shift` pixels, as a bgr8 ImageBuffer owning its pixels.
ImageBuffer shifted_frame(int shift) {
  const cv::Mat frame = cv::imread(kFrame.string());
  cv::Mat moved;
  const cv::Mat m = (cv::Mat_<double>(2, 3) << 1, 0, shift, 0, 1, 0);
  cv::warpAffine(frame, moved, m, frame.size());
  return test::image_of(moved);
}

struct Frames {
  std::vector<std::vector<MovenetPerson>> people;  // per frame
  TopDownProfile profile;
};

// The first `frames` frames of the moving picture (`step` px a frame) through a detector with `o`.
Frames run(const Models& m, const TopDownOptions& o, int frames, int step = 2) {
  TopDownDetector detector(o, m.lightning, m.centernet);
  if (o.workers > 1) detector.warm_up();  // one copy builds its shapes on the frames
  Frames out;
  for (int i = 0; i < frames; ++i) out.people.push_back(detector.detect(shifted_frame(step * i)));
  out.profile = detector.profile();
  return out;
}

TEST(TopDownDetector, TwoWorkersFindWhatOneFinds) {
  std::string why;
  const auto m = models(why);
  if (!m) GTEST_SKIP() << why;
  TopDownOptions o;
  o.detect_every = 3;
  o.workers = 1;
  const Frames one_run = run(*m, o, 5);
  o.workers = 2;
  const Frames two_run = run(*m, o, 5);
  const auto &one = one_run.people, &two = two_run.people;
  ASSERT_EQ(one.size(), two.size());
  for (std::size_t f = 0; f < one.size(); ++f) {
    SCOPED_TRACE(f);
    EXPECT_GE(one[f].size(), 4u);  // the pedestrians of frame 300
    ASSERT_EQ(one[f].size(), two[f].size());
    for (std::size_t p = 0; p < one[f].size(); ++p) {
      EXPECT_GT(iou(one[f][p].box, two[f][p].box), 0.98f) << p;
      for (int k = 0; k < kMovenetKeypoints; ++k) {
        const Keypoint2D &a = one[f][p].keypoints[k], &b = two[f][p].keypoints[k];
        EXPECT_EQ(std::isfinite(a.x), std::isfinite(b.x)) << p << " " << k;
        if (std::isfinite(a.x) && std::isfinite(b.x)) {
          EXPECT_LT(std::hypot(a.x - b.x, a.y - b.y), 0.5) << p << " " << k;
        }
      }
    }
  }
  for (const TopDownProfile* p : {&one_run.profile, &two_run.profile}) {
    EXPECT_EQ(p->frames, 5);
    EXPECT_EQ(p->detector_runs, 2);  // frames 0 and 3: nobody is lost
    EXPECT_GE(p->crops, 20);
    EXPECT_GT(p->keypoints, 0.0);
    EXPECT_GT(p->centernet, 0.0);
    EXPECT_GE(p->total, p->keypoints + p->crop_fill);
  }
}

// The person test made strict (all 17 keypoints at 0.6), so that the crops of frame 300 fail
// it: with sure_box_score the boxes CenterNet scores at least that stay people, with the
// detector's box and only their confident keypoints, and are followed to the next detector run.
TEST(TopDownDetector, ABoxTheDetectorIsSureOfIsAPersonWhateverItsKeypoints) {
  std::string why;
  const auto m = models(why);
  if (!m) GTEST_SKIP() << why;
  TopDownOptions o;
  o.min_keypoints = 17;
  o.min_keypoint_score = 0.6f;
  o.detect_every = 10;
  const Frames strict = run(*m, o, 3);
  o.sure_box_score = 0.5f;
  const Frames sure_run = run(*m, o, 3);
  const auto& sure = sure_run.people;
  EXPECT_LE(strict.people.front().size(), 1u) << "the strict test should reject frame 300's crops";
  // CenterNet's own boxes scoring 0.5 or more on the first frame.
  CenternetNetwork network(m->centernet);
  GraphTensor input;
  ProposalOptions confident;
  confident.min_score = 0.5f;
  const auto boxes = propose_people(network, shifted_frame(0), confident, input);
  ASSERT_GE(boxes.size(), 3u) << "the walkers of frame 300 score 0.55-0.67";
  ASSERT_GE(sure.front().size(), boxes.size());
  for (const Detection& d : boxes) {
    const bool kept =
        std::any_of(sure.front().begin(), sure.front().end(),
                    [&](const MovenetPerson& p) { return iou(p.box, d.box) > 0.99f; });
    EXPECT_TRUE(kept) << "the box at x " << d.box.x << " is not a person";
  }
  for (const auto& frame : sure) {
    EXPECT_GE(frame.size(), boxes.size()) << "followed between detector runs";
    for (const MovenetPerson& p : frame)
      for (const Keypoint2D& k : p.keypoints)
        EXPECT_TRUE(std::isnan(k.x) || k.confidence >= o.min_keypoint_score);
  }
  EXPECT_EQ(sure_run.profile.detector_runs, 1) << "nobody sure is lost between detector runs";
}

TEST(TopDownDetector, PartOfABatchEqualsThatPartOfTheWholeRun) {
  std::string why;
  const auto m = models(why);
  if (!m) GTEST_SKIP() << why;
  SinglePoseNetwork network(SinglePoseModel::lightning, m->lightning);
  GraphTensor batch;
  batch.shape = {5, 192, 192, 3};
  batch.values.resize(batch.size());
  for (std::size_t i = 0; i < batch.values.size(); ++i)
    batch.values[i] = static_cast<float>((i * 7919) % 256);
  const std::vector<SinglePose> whole = network.run(batch);
  std::vector<SinglePose> part(3);
  network.run(batch, 2, 3, part);
  for (int n = 0; n < 3; ++n)
    for (int k = 0; k < kMovenetKeypoints; ++k)
      for (int i = 0; i < 3; ++i)
        EXPECT_NEAR(part[static_cast<std::size_t>(n)].keypoints[k][i],
                    whole[static_cast<std::size_t>(n + 2)].keypoints[k][i], 1e-5);
  EXPECT_THROW(network.run(batch, 4, 2, part), std::invalid_argument);
}

// The person test of a crop (judge_crop): MoveNet's keypoints, or a presence flag instead.
TEST(TopDownDetector, APresenceFlagIsThePersonTestOfTheModelsThatHaveOne) {
  TopDownOptions o;  // 6 keypoints at 0.3, mean 0.35; flag 0.5
  SinglePose pose;
  for (int k = 0; k < kMovenetKeypoints; ++k) pose.keypoints[k] = {0.5f, 0.5f, k < 6 ? 0.4f : 0.1f};
  EXPECT_TRUE(judge_crop(pose, o).posed);
  EXPECT_EQ(judge_crop(pose, o).passing, 6);
  EXPECT_NEAR(judge_crop(pose, o).score, 0.4f, 1e-6);
  pose.keypoints[0][2] = 0.2f;  // five keypoints pass: not a person for MoveNet
  EXPECT_FALSE(judge_crop(pose, o).posed);
  pose.presence = 0.7f;  // the flag decides
  EXPECT_TRUE(judge_crop(pose, o).posed);
  EXPECT_FLOAT_EQ(judge_crop(pose, o).score, 0.7f);
  pose.presence = 0.3f;
  EXPECT_FALSE(judge_crop(pose, o).posed);
  pose.presence = 0.9f;  // a confident flag, but too few keypoints to span a box
  for (int k = 1; k < kMovenetKeypoints; ++k) pose.keypoints[k][2] = 0.1f;
  EXPECT_FALSE(judge_crop(pose, o).posed);
}

// BlazePose's person box (posed_box): the landmarks whose presence passes, blurred legs included,
// while the keypoints emitted keep their visibility; MoveNet's, or too few present landmarks, the
// kept keypoints'. Synthetic outputs of one 256-px crop, so that every number is known.
TEST(TopDownDetector, ABlazePoseBoxReachesTheFeetItsLandmarksPlace) {
  constexpr int kSize = 256;
  GraphTensor landmarks{{1, kBlazePoseLandmarks * 5}, {}}, flag{{1, 1, 1, 1}, {0.9f}};
  landmarks.values.assign(landmarks.size(), 0.0f);
  const auto set = [&](int k, float x, float y, float visibility, float presence) {
    float* l = landmarks.values.data() + k * 5;
    l[0] = x, l[1] = y, l[3] = visibility, l[4] = presence;  // logits
  };
  // A standing person along x = 128 px, landmark k at y = 40 + 5 k (toes at 200); the legs from
  // the knees down (25-32) are blurred (visibility σ(-3)) but present (σ(3)).
  for (int k = 0; k < kBlazePoseBody; ++k) set(k, 128, 40 + 5.0f * k, k >= 25 ? -3 : 3, 3);
  set(19, 250, 135, -3, -3);  // a hand outside the picture: not present, left out
  set(20, 20, 140, -3, 3);    // a hand hidden but present: in the box, not a keypoint
  const SinglePose pose = decode_blazepose(landmarks, flag, kSize, 0);
  EXPECT_EQ(pose.body_landmarks, kBlazePoseBody);
  EXPECT_NEAR(pose.body[32][2], 1 / (1 + std::exp(-3.0f)), 1e-6);
  EXPECT_LT(pose.keypoints[15][2], 0.3f);  // the ankles keep their visibility: not emitted
  EXPECT_GT(pose.keypoints[11][2], 0.3f);

  const SquareRegion region{500, 300, kSize};  // crop pixel (x, y) is frame (372 + x, 172 + y)
  const auto expect_box = [](const Box2D& got, Box2D want) {
    EXPECT_NEAR(got.x, want.x, 1e-3);
    EXPECT_NEAR(got.y, want.y, 1e-3);
    EXPECT_NEAR(got.width, want.width, 1e-3);
    EXPECT_NEAR(got.height, want.height, 1e-3);
  };
  TopDownOptions o;  // box_landmark_presence 0.5, anatomical_landmark_box
  // The landmarks span x 392 (hand 20) to 500, y 212 (nose) to 372 (toes): 160 px tall. Grown by
  // 0.07 of that above (11.2 px), 0.03 on each side (4.8 px), nothing below the toes.
  expect_box(posed_box(pose, region, o, 1000, 1000), {387.2f, 200.8f, 117.6f, 171.2f});
  // Cut to a 640 x 360 picture: the feet below its bottom edge are left out.
  expect_box(posed_box(pose, region, o, 640, 360), {387.2f, 200.8f, 117.6f, 159.2f});
  // The same person at the picture's top left corner (frame = crop - 28 px): x from -12.8 cut to 0.
  expect_box(posed_box(pose, {100, 100, kSize}, o, 640, 360), {0, 0.8f, 104.8f, 171.2f});
  // The next crop's box: the keypoints' widening, 0.12 × 160 above, half below and aside, not
  // cut; with anatomical_landmark_box off the person's box too.
  const Box2D widened{382.4f, 192.8f, 127.2f, 188.8f};
  expect_box(posed_crop_box(pose, region, o), widened);
  o.anatomical_landmark_box = false;
  expect_box(posed_box(pose, region, o, 640, 360), widened);
  o.anatomical_landmark_box = true;
  // The kept keypoints, nose (212) to hips (24: 332), 120 px, widened as before: 14.4 px above,
  // 7.2 below and aside, not cut.
  const Box2D keypoints_box{492.8f, 197.6f, 14.4f, 141.6f};
  o.box_landmark_presence = 2;  // off
  expect_box(posed_box(pose, region, o, 640, 300), keypoints_box);
  o.box_landmark_presence = 0.5f;
  SinglePose one = pose;  // a single landmark present spans no box: the keypoints' again
  for (auto& l : one.body) l[2] = 0.1f;
  one.body[32][2] = 0.9f;
  expect_box(posed_box(one, region, o, 640, 300), keypoints_box);
  SinglePose movenet = pose;  // no landmarks: the keypoints'
  movenet.body_landmarks = 0;
  movenet.presence = kNoPresence;
  expect_box(posed_box(movenet, region, o, 640, 300), keypoints_box);
  expect_box(posed_crop_box(movenet, region, o), keypoints_box);
}

// The head's margin from the eyes' height above the shoulders (head_margin_from_shoulders): the
// same when the legs leave the picture, where 0.07 of the landmarks' extent shrinks with them.
TEST(TopDownDetector, TheHeadMarginFromTheShouldersStaysWhenTheLegsLeave) {
  constexpr int kSize = 256;
  GraphTensor landmarks{{1, kBlazePoseLandmarks * 5}, {}}, flag{{1, 1, 1, 1}, {0.9f}};
  landmarks.values.assign(landmarks.size(), 0.0f);
  const auto set = [&](int k, float x, float y, float presence) {
    float* l = landmarks.values.data() + k * 5;
    l[0] = x, l[1] = y, l[3] = 3, l[4] = presence;  // logits
  };
  // Landmark k at y = 40 + 5 k (nose 40, eyes 2 and 5 at 50 and 65, shoulders 11 and 12 at 95
  // and 100: the eyes 40 px above the shoulders), x = 128 but landmark 20 at x 20.
  for (int k = 0; k < kBlazePoseBody; ++k) set(k, k == 20 ? 20 : 128, 40 + 5.0f * k, 3);
  const SinglePose whole = decode_blazepose(landmarks, flag, kSize, 0);
  for (int k = 23; k < kBlazePoseBody; ++k) set(k, 128, 40 + 5.0f * k, -3);  // legs outside
  const SinglePose no_legs = decode_blazepose(landmarks, flag, kSize, 0);
  const SquareRegion region{500, 300, kSize};  // crop pixel (x, y) is frame (372 + x, 172 + y)
  TopDownOptions o;
  // Without: the top 0.07 × the extent above the nose (frame y 212): 160 px whole (11.2), 110
  // px without the legs (nose to landmark 22 at 322: 7.7).
  EXPECT_NEAR(posed_box(whole, region, o, 1000, 1000).y, 200.8f, 1e-3);
  EXPECT_NEAR(posed_box(no_legs, region, o, 1000, 1000).y, 204.3f, 1e-3);
  // With: 0.54 × 40 = 21.6 px above the nose either way; the bottom does not move.
  o.head_margin_from_shoulders = true;
  const Box2D box = posed_box(whole, region, o, 1000, 1000);
  EXPECT_NEAR(box.y, 190.4f, 1e-3);
  EXPECT_NEAR(box.y + box.height, 372.0f, 1e-3);
  EXPECT_NEAR(posed_box(no_legs, region, o, 1000, 1000).y, 190.4f, 1e-3);
  // Eyes not present: the extent's margin again.
  for (const int k : {2, 5}) set(k, 128, 40 + 5.0f * k, -3);
  EXPECT_NEAR(posed_box(decode_blazepose(landmarks, flag, kSize, 0), region, o, 1000, 1000).y,
              204.3f, 1e-3);
}

// Boxes shorter than small_box_height get crops of small_crop_padding, the others crop_padding.
TEST(TopDownDetector, SmallBoxesGetCropsWithMoreContext) {
  TopDownOptions o;
  o.small_box_height = 100;
  o.small_crop_padding = 1.5f;
  const SquareRegion small = crop_region({10, 20, 30, 80}, o);
  EXPECT_FLOAT_EQ(small.side, 120.0f);
  EXPECT_FLOAT_EQ(small.cx, 25.0f);
  EXPECT_FLOAT_EQ(small.cy, 60.0f);
  EXPECT_FLOAT_EQ(crop_region({10, 20, 30, 100}, o).side, 125.0f);
  o.small_box_height = 0;  // off
  EXPECT_FLOAT_EQ(crop_region({10, 20, 30, 80}, o).side, 100.0f);
}

// BlazePose lite in the crops: the pedestrians of vtest frame 300, each with a presence flag of
// at least MediaPipe's 0.5 as the person score, their keypoints confident ones only.
TEST(TopDownDetector, BlazePoseFindsThePedestriansOfFrame300) {
  std::string why;
  const auto m = models(why);
  if (!m) GTEST_SKIP() << why;
  fs::path blazepose;
  try {
    blazepose = cached_model_json(model_name(SinglePoseModel::blazepose_lite));
  } catch (const ModelMissing& e) {
    GTEST_SKIP() << e.what();
  }
  TopDownOptions o;
  o.pose_model = SinglePoseModel::blazepose_lite;
  o.detect_every = 3;
  TopDownDetector detector(o, blazepose, m->centernet);
  TopDownDetector movenet(TopDownOptions{}, m->lightning, m->centernet);
  for (int i = 0; i < 3; ++i) {
    SCOPED_TRACE(i);
    const auto people = detector.detect(shifted_frame(2 * i));
    const auto reference = movenet.detect(shifted_frame(2 * i));
    EXPECT_GE(people.size(), 4u);  // the walkers of frame 300
    for (const MovenetPerson& p : people) {
      EXPECT_GE(p.score, o.min_pose_presence);
      EXPECT_GT(p.box.height, 40.0f);
      for (const Keypoint2D& k : p.keypoints)
        EXPECT_TRUE(std::isnan(k.x) || k.confidence >= o.min_keypoint_score);
    }
    // The same people as MoveNet's: each of Lightning's finds has a BlazePose find on it.
    for (const MovenetPerson& r : reference) {
      EXPECT_TRUE(test::found_again(r.box, people))
          << "Lightning's person at x " << r.box.x << " not found by BlazePose";
    }
  }
}

// newcomer_agreement: a newcomer is a person only when its posed box overlaps its detector box
// by that IoU. At 0.99 no posed box agrees that closely, so the first frame of frame 300's
// walkers (all newcomers; found with the option off in the tests above) finds nobody.
TEST(TopDownDetector, NewcomersWhosePoseDisagreesWithTheirBoxAreNotPeople) {
  std::string why;
  const auto m = models(why);
  if (!m) GTEST_SKIP() << why;
  TopDownOptions o;
  o.newcomer_agreement = 0.99f;
  EXPECT_TRUE(TopDownDetector(o, m->lightning, m->centernet).detect(shifted_frame(0)).empty());
  o.newcomer_agreement = 1.5f;
  EXPECT_THROW(TopDownDetector(o, m->lightning, m->centernet), std::invalid_argument);
}

// The rules for people followed as one box (one_box_per_followed, duplicate_similarity) and
// CenterNet at the frame's aspect only add people on frame 300's walkers, who stand apart: each
// person found without them is found with them, on a detector run and a followed frame.
TEST(TopDownDetector, TheRulesForPeopleAsOneBoxKeepThePeopleFoundApart) {
  std::string why;
  const auto m = models(why);
  if (!m) GTEST_SKIP() << why;
  TopDownOptions o;
  o.detect_every = 2;
  const Frames plain = run(*m, o, 2);
  o.one_box_per_followed = true;
  o.split_followed = true;
  o.duplicate_similarity = 0.9f;
  o.detector_aspect = true;
  const Frames ruled = run(*m, o, 2);
  ASSERT_EQ(plain.people.size(), ruled.people.size());
  for (std::size_t f = 0; f < plain.people.size(); ++f) {
    SCOPED_TRACE(f);
    EXPECT_GE(plain.people[f].size(), 3u);
    for (const MovenetPerson& p : plain.people[f]) {
      EXPECT_TRUE(test::found_again(p.box, ruled.people[f]))
          << "the person at x " << p.box.x << " lost";
    }
  }
  o.duplicate_similarity = 1.5f;
  EXPECT_THROW(TopDownDetector(o, m->lightning, m->centernet), std::invalid_argument);
}

// The trace says what became of each box: on the first frame every detector box is a newcomer
// with its own crop, and the crops kept are the people returned; on the next (no detector run)
// every crop is a followed person's.
TEST(TopDownDetector, TheTraceAccountsForEveryBox) {
  std::string why;
  const auto m = models(why);
  if (!m) GTEST_SKIP() << why;
  TopDownDetector detector(TopDownOptions{}, m->lightning, m->centernet);
  using Fate = TopDownTrace::Fate;
  const auto kept = [](const TopDownTrace& t) {
    return std::count_if(t.crops.begin(), t.crops.end(),
                         [](const TopDownTrace::Crop& c) { return c.fate == Fate::kept; });
  };
  const auto first = detector.detect(shifted_frame(0));
  const TopDownTrace t0 = detector.trace();
  EXPECT_TRUE(t0.detector_ran);
  ASSERT_EQ(t0.taken_for.size(), t0.detections.size());
  EXPECT_EQ(t0.crops.size(), t0.detections.size());
  for (const int taken : t0.taken_for) EXPECT_EQ(taken, -1);
  for (const auto& c : t0.crops) EXPECT_TRUE(c.newcomer);
  EXPECT_EQ(kept(t0), static_cast<long>(first.size()));
  const auto second = detector.detect(shifted_frame(2));
  const TopDownTrace t1 = detector.trace();
  EXPECT_FALSE(t1.detector_ran);
  EXPECT_TRUE(t1.detections.empty());
  EXPECT_EQ(t1.crops.size(), first.size());
  for (const auto& c : t1.crops) EXPECT_FALSE(c.newcomer);
  EXPECT_EQ(kept(t1), static_cast<long>(second.size()));
}

// Frames 0..5 of the moving picture with the keypoint network every frame, then every third.
TEST(TopDownDetector, KeypointsCarriedByFlowStayWithTheNetworksBetweenPasses) {
  std::string why;
  const auto m = models(why);
  if (!m) GTEST_SKIP() << why;
  TopDownOptions o;
  o.detect_every = 3;
  o.keypoint_every = 1;
  const Frames every_run = run(*m, o, 6);
  o.keypoint_every = 3;
  const Frames carried_run = run(*m, o, 6);
  const auto &every = every_run.people, &carried = carried_run.people;
  const TopDownProfile &every_profile = every_run.profile, &carried_profile = carried_run.profile;
  EXPECT_EQ(every_profile.carried, 0);
  EXPECT_EQ(every_profile.flow, 0.0);
  // Passes on frames 0 and 3, flow on 1, 2, 4 and 5 for everyone the flow keeps.
  EXPECT_GE(carried_profile.carried, 4 * 3);
  EXPECT_LT(carried_profile.crops, every_profile.crops * 2 / 3);
  EXPECT_GT(carried_profile.flow, 0.0);
  std::vector<float> distances;
  for (std::size_t f = 0; f < every.size(); ++f) {
    SCOPED_TRACE(f);
    EXPECT_EQ(carried[f].size(), every[f].size());
    for (const MovenetPerson& a : carried[f]) {
      // The same person of the every-frame run.
      const MovenetPerson* b = nullptr;
      for (const MovenetPerson& candidate : every[f])
        if (iou(a.box, candidate.box) > 0.5f) b = &candidate;
      ASSERT_NE(b, nullptr);
      for (int k = 0; k < kMovenetKeypoints; ++k)
        if (std::isfinite(a.keypoints[k].x) && std::isfinite(b->keypoints[k].x))
          distances.push_back(std::hypot(a.keypoints[k].x - b->keypoints[k].x,
                                         a.keypoints[k].y - b->keypoints[k].y));
    }
  }
  ASSERT_FALSE(distances.empty());
  std::sort(distances.begin(), distances.end());
  // The picture moves exactly; what differs is the network's own jitter from crop to crop.
  EXPECT_LT(distances[distances.size() / 2], 1.5f);
}

// With a keypoint pass every 3 frames, the people posed together on the detector's frame get
// their next passes spread over the 3 frames after it (each frame about a third of them), not
// all on the third: a live frame's time stays even.
TEST(TopDownDetector, KeypointPassesAreSpreadOverTheFramesBetween) {
  std::string why;
  const auto m = models(why);
  if (!m) GTEST_SKIP() << why;
  TopDownOptions o;
  o.detect_every = 100;
  o.keypoint_every = 3;
  TopDownDetector detector(o, m->lightning, m->centernet);
  const std::size_t people = detector.detect(shifted_frame(0)).size();
  ASSERT_GE(people, 4u);
  std::vector<long long> crops;  // per frame after the first
  long long before = detector.profile().crops;
  for (int i = 1; i <= 6; ++i) {
    EXPECT_EQ(detector.detect(shifted_frame(2 * i)).size(), people) << i;
    crops.push_back(detector.profile().crops - before);
    before = detector.profile().crops;
  }
  EXPECT_EQ(detector.profile().flow_failed, 0);  // the picture moves as a whole: no crop added
  const long long most = static_cast<long long>((people + 2) / 3);
  for (std::size_t f = 0; f < crops.size(); ++f) {
    SCOPED_TRACE(f + 1);
    EXPECT_GE(crops[f], static_cast<long long>(people / 3));
    EXPECT_LE(crops[f], most);
  }
  EXPECT_EQ(crops[0] + crops[1] + crops[2], static_cast<long long>(people));  // each once
}

// The person detector in the background (live): the first frame, with nobody to follow, runs it
// itself and finds the people the foreground detector finds; the frames after follow them; a
// run due while they are followed goes on beside the frames and its boxes are taken in once it
// has ended, on the frame after it started or on the next (frames never wait for it), without
// a second crop on anybody already followed; and the frame passed to detect() may be gone while
// the run goes on (it runs on a copy).
TEST(TopDownDetector, ADetectorInTheBackgroundLetsTheFramesGoOn) {
  std::string why;
  const auto m = models(why);
  if (!m) GTEST_SKIP() << why;
  TopDownOptions o;
  o.detect_every = 3;
  // 12 px a frame: the run's boxes of frame 2 lie 12-24 px off the walkers (25-40 px wide) when
  // taken in, too far to overlap where they are now.
  constexpr int kStep = 12;
  const Frames foreground = run(*m, o, 5, kStep);
  o.detector_in_background = true;
  TopDownDetector detector(o, m->lightning, m->centernet);
  int background_runs = 0;
  std::vector<MovenetPerson> at_run;  // the people of frame 2, whose picture the run looks at
  for (int i = 0; i < 5; ++i) {
    SCOPED_TRACE(i);
    // The run started after frame 2 (3 frames after frame 0's) has ended before frame 4.
    if (i == 4) detector.wait_for_detector();
    const std::vector<MovenetPerson> people = detector.detect(shifted_frame(kStep * i));
    const TopDownTrace& trace = detector.trace();
    if (i == 0) {
      EXPECT_TRUE(trace.detector_ran);
    } else if (i < 3) {
      EXPECT_FALSE(trace.detector_ran);
    } else if (trace.detector_ran) {
      ++background_runs;
      // A crop of its own only for a box on nobody followed on the run's frame (its boxes are
      // compared with where the people were then, not with where they are now).
      const auto newcomers = std::count_if(trace.crops.begin(), trace.crops.end(),
                                           [](const auto& c) { return c.newcomer; });
      const auto on_nobody =
          std::count_if(trace.detections.begin(), trace.detections.end(), [&](const auto& d) {
            return std::none_of(at_run.begin(), at_run.end(),
                                [&](const auto& p) { return iou(p.box, d.box) > 0.3f; });
          });
      EXPECT_LE(newcomers, on_nobody);
    }
    if (i == 2) at_run = people;
    EXPECT_GE(people.size(), 4u);
    for (const MovenetPerson& p : foreground.people[static_cast<std::size_t>(i)])
      EXPECT_TRUE(test::found_again(p.box, people)) << p.box.x << " " << p.box.y;
  }
  EXPECT_EQ(background_runs, 1);
  EXPECT_EQ(detector.profile().detector_runs, 2);
  EXPECT_GT(detector.profile().centernet, 0.0);
}

TEST(TopDownDetector, APersonWhoseFlowFailsGetsAKeypointPass) {
  std::string why;
  const auto m = models(why);
  if (!m) GTEST_SKIP() << why;
  TopDownOptions o;
  o.detect_every = 100;
  o.keypoint_every = 5;
  TopDownDetector detector(o, m->lightning, m->centernet);
  const auto first = detector.detect(shifted_frame(0));
  ASSERT_GE(first.size(), 4u);
  // A blank picture (the camera covered): no point can be followed, so nobody is carried; each
  // gets a crop instead (which shows nobody).
  const auto second =
      detector.detect(test::image_of(cv::Mat(576, 768, CV_8UC3, cv::Scalar(128, 128, 128))));
  EXPECT_TRUE(second.empty());
  const TopDownProfile& p = detector.profile();
  EXPECT_EQ(p.carried, 0);
  // All but those whose pass was due on this frame (spread over the 5 frames after the first)
  // were to be carried.
  const auto n = static_cast<long long>(first.size());
  EXPECT_GE(p.flow_failed, n - (n + 4) / 5);
  EXPECT_LE(p.flow_failed, n);
  EXPECT_GE(p.crops, 2 * static_cast<long long>(first.size()));
}

// The file default (BlazePose full in the crops) on both cores in passes of 2 crops against one
// core in passes of 8: on frames 100-102 of video.avi (1280 x 720, a crowd), with the person
// detector on frames 0 and 2 (beside the followed people's crops on the helper), every person
// and keypoint is the same to 1e-4 px.
TEST(TopDownDetector, TwoWorkersAndSmallPassesFindTheDefaultsPeopleToATenThousandthOfAPixel) {
  std::string why;
  const auto m = models(why);
  if (!m) GTEST_SKIP() << why;
  fs::path blazepose;
  try {
    blazepose = cached_model_json(model_name(SinglePoseModel::blazepose_full));
  } catch (const ModelMissing& e) {
    GTEST_SKIP() << e.what();
  }
  const fs::path clip =
      fs::path("..") / "shared" / "data" / "eval" / "openpose_examples_media" / "video.avi";
  cv::VideoCapture video(clip.string());
  if (!video.isOpened()) GTEST_SKIP() << "cannot read " << clip;
  video.set(cv::CAP_PROP_POS_FRAMES, 100);  // the crowd in the middle of the clip
  std::vector<ImageBuffer> frames;
  for (cv::Mat frame; frames.size() < 3 && video.read(frame);)
    frames.push_back(test::image_of(frame.clone()));
  ASSERT_EQ(frames.size(), 3u);
  TopDownOptions o;
  o.pose_model = SinglePoseModel::blazepose_full;
  o.detect_every = 2;
  std::vector<std::vector<MovenetPerson>> found[2];
  TopDownProfile profile[2];
  for (const int workers : {1, 2}) {
    o.workers = workers;
    o.crops_per_pass = workers == 1 ? 8 : 2;
    TopDownDetector detector(o, blazepose, m->centernet);
    for (const ImageBuffer& frame : frames) found[workers - 1].push_back(detector.detect(frame));
    profile[workers - 1] = detector.profile();
  }
  const auto &one = found[0], &two = found[1];
  for (std::size_t f = 0; f < frames.size(); ++f) {
    SCOPED_TRACE(f);
    EXPECT_GE(one[f].size(), 4u);
    ASSERT_EQ(one[f].size(), two[f].size());
    for (std::size_t p = 0; p < one[f].size(); ++p) {
      EXPECT_NEAR(one[f][p].score, two[f][p].score, 1e-6) << p;
      EXPECT_NEAR(one[f][p].box.x, two[f][p].box.x, 1e-4) << p;
      EXPECT_NEAR(one[f][p].box.y, two[f][p].box.y, 1e-4) << p;
      EXPECT_NEAR(one[f][p].box.height, two[f][p].box.height, 1e-4) << p;
      for (int k = 0; k < kMovenetKeypoints; ++k) {
        const Keypoint2D &a = one[f][p].keypoints[k], &b = two[f][p].keypoints[k];
        ASSERT_EQ(std::isfinite(a.x), std::isfinite(b.x)) << p << " " << k;
        if (std::isfinite(a.x)) {
          EXPECT_LT(std::hypot(a.x - b.x, a.y - b.y), 1e-4) << p << " " << k;
        }
      }
    }
  }
  EXPECT_EQ(profile[0].detector_runs, 2);  // frames 0 and 2
  EXPECT_EQ(profile[1].detector_runs, 2);
  EXPECT_EQ(profile[0].crops, profile[1].crops);
}

// The frame with its right half grey: whoever was followed there is lost.
ImageBuffer right_half_grey() {
  cv::Mat frame = cv::imread(kFrame.string());
  frame(cv::Rect(frame.cols / 2, 0, frame.cols - frame.cols / 2, frame.rows)).setTo(128);
  return test::image_of(frame);
}

// Which of frames 0..5 ran the person detector: frame 0 whole, then the right half grey, which
// loses somebody on frame 1.
std::vector<bool> detector_runs_after_a_loss(const Models& m, int rerun_gap) {
  TopDownOptions o;
  o.rerun_gap = rerun_gap;
  TopDownDetector detector(o, m.lightning, m.centernet);
  std::vector<bool> ran;
  const auto whole = detector.detect(shifted_frame(0));
  ran.push_back(detector.trace().detector_ran);
  for (int i = 1; i < 6; ++i) {
    const auto people = detector.detect(right_half_grey());
    if (i == 1) {
      EXPECT_LT(people.size(), whole.size()) << "nobody lost on frame 1";
    }
    ran.push_back(detector.trace().detector_ran);
  }
  return ran;
}

TEST(TopDownDetector, ARerunAfterALossWaitsForTheGap) {
  std::string why;
  const auto m = models(why);
  if (!m) GTEST_SKIP() << why;
  EXPECT_EQ(detector_runs_after_a_loss(*m, 0),
            (std::vector<bool>{true, false, true, false, false, false}));
  EXPECT_EQ(detector_runs_after_a_loss(*m, 5),
            (std::vector<bool>{true, false, false, false, false, true}));
  TopDownOptions o;
  o.rerun_gap = -1;
  EXPECT_THROW(TopDownDetector(o, m->lightning, m->centernet), std::invalid_argument);
}

TEST(TopDownDetector, WorkersAndPassesOutsideTheRangeAreRefused) {
  std::string why;
  const auto m = models(why);
  if (!m) GTEST_SKIP() << why;
  TopDownOptions o;
  o.workers = 0;
  EXPECT_THROW(TopDownDetector(o, m->lightning, m->centernet), std::invalid_argument);
  o.workers = 1;
  o.keypoint_every = 0;
  EXPECT_THROW(TopDownDetector(o, m->lightning, m->centernet), std::invalid_argument);
  o.keypoint_every = 1;
  for (const int pass : {0, 3, 16}) {
    o.crops_per_pass = pass;
    EXPECT_THROW(TopDownDetector(o, m->lightning, m->centernet), std::invalid_argument) << pass;
  }
}

}  // namespace
}  // namespace mocap::detect
