// What the reference makers (make_*_reference.js) share: reading the frame, cutting windows,
// loading a TF.js graph model from the model cache with the hashes of its files, and comparing a
// new reference with an earlier one. Loaded with require('./tfjs_common') (NODE_PATH set by
// tfjs_env.sh finds @tensorflow/tfjs and pngjs).
'use strict';

const crypto = require('crypto');
const fs = require('fs');
const tf = require('@tensorflow/tfjs');
const { PNG } = require('pngjs');

const sha256 = (bytes) => crypto.createHash('sha256').update(bytes).digest('hex');

// The RGB bytes of a PNG (alpha dropped), row-major.
function readRgb(file) {
  const png = PNG.sync.read(fs.readFileSync(file));
  const rgb = Buffer.alloc(png.width * png.height * 3);
  for (let i = 0; i < png.width * png.height; ++i) png.data.copy(rgb, 3 * i, 4 * i, 4 * i + 3);
  return { width: png.width, height: png.height, rgb };
}

// The square window c = {id, x, y, size} of a frame, whole pixels, unchanged.
function cutWindow(frame, c) {
  if (c.x + c.size > frame.width || c.y + c.size > frame.height) throw new Error(`${c.id}: outside the frame`);
  const out = Buffer.alloc(c.size * c.size * 3);
  for (let r = 0; r < c.size; ++r) {
    const from = ((c.y + r) * frame.width + c.x) * 3;
    frame.rgb.copy(out, r * c.size * 3, from, from + c.size * 3);
  }
  return out;
}

// A graph model from JSON_PATH and BIN_PATH (one weight file), executed unchanged by tfjs, with
// the model JSON (for generatedBy / convertedBy) and the sha256 of both files.
async function loadGraphModel(jsonPath, binPath) {
  const jsonBytes = fs.readFileSync(jsonPath);
  const json = JSON.parse(jsonBytes.toString('utf8'));
  const bin = fs.readFileSync(binPath);
  const weightData = bin.buffer.slice(bin.byteOffset, bin.byteOffset + bin.byteLength);
  const model = await tf.loadGraphModel(tf.io.fromMemory({
    modelTopology: json.modelTopology, weightSpecs: json.weightsManifest[0].weights, weightData,
    format: json.format, generatedBy: json.generatedBy, convertedBy: json.convertedBy,
  }));
  return { model, json, jsonSha256: sha256(jsonBytes), binSha256: sha256(bin) };
}

// Largest difference between two JSON trees' numbers (Infinity when their shapes differ).
function maxDiff(a, b) {
  if (typeof a === 'number' && typeof b === 'number') return Math.abs(a - b);
  if (Array.isArray(a) && Array.isArray(b) && a.length === b.length)
    return a.reduce((m, v, i) => Math.max(m, maxDiff(v, b[i])), 0);
  if (a && b && typeof a === 'object' && typeof b === 'object')
    return Object.keys(a).reduce((m, k) => (k in b ? Math.max(m, maxDiff(a[k], b[k])) : m), 0);
  return a === b || typeof a === 'string' ? 0 : Infinity;
}

// The command line every maker takes: INPUT_A INPUT_B OUT.json [--check OLD.json]; exits with
// the usage line when it is wrong.
function parseArgs(usage) {
  const [first, second, out, flag, old] = process.argv.slice(2);
  if (!out || (flag && flag !== '--check') || (flag && !old)) {
    console.error(`usage: ${usage}`);
    process.exit(2);
  }
  return { first, second, out, old: flag ? old : null };
}

// Writes the reference; with an earlier one, prints per case the largest difference that
// `differences(new, old)` finds (a number or an object of numbers) and fails above 1e-5.
function writeAndCheck(reference, out, old, differences) {
  fs.writeFileSync(out, JSON.stringify(reference, null, 1) + '\n');
  console.log(`wrote ${out}`);
  if (!old) return;
  const before = JSON.parse(fs.readFileSync(old, 'utf8'));
  for (const c of reference.cases) {
    const o = before.cases.find((b) => b.id === c.id);
    const d = o ? differences(c, o) : null;
    console.log(`${c.id}: max |difference| to ${old}:`, d);
    const values = d === null ? [Infinity] : typeof d === 'number' ? [d] : Object.values(d);
    if (values.some((v) => !(v <= 1e-5))) process.exitCode = 1;
  }
}

module.exports = { tf, sha256, readRgb, cutWindow, loadGraphModel, maxDiff, parseArgs, writeAndCheck };
