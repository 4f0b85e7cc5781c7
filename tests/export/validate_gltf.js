// Runs the Khronos glTF validator (npm gltf-validator) on glTF/GLB files and prints, per file,
// one line "MOCAP_GLTF_VALIDATOR {json}" with the issue counts and every message, for the tests.
//   node validate_gltf.js NODE_MODULES_DIR FILE.glb [FILE.glb ...]
// Exit status: 0 when the validator ran on every file (whatever it found), 2 on a usage error.
"use strict";
const fs = require("fs");
const path = require("path");

const [modules, ...files] = process.argv.slice(2);
if (!modules || files.length === 0) {
  console.error("usage: node validate_gltf.js NODE_MODULES_DIR FILE.glb [FILE.glb ...]");
  process.exit(2);
}
const validator = require(path.join(modules, "gltf-validator"));

(async () => {
  for (const file of files) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
      uri: path.basename(file),
      maxIssues: 100,
    });
    const issues = report.issues;
    console.log(
      "MOCAP_GLTF_VALIDATOR " +
        JSON.stringify({
          file: path.basename(file),
          validator: report.validatorVersion,
          errors: issues.numErrors,
          warnings: issues.numWarnings,
          infos: issues.numInfos,
          hints: issues.numHints,
          messages: issues.messages.map((m) => `${m.severity}:${m.code} ${m.pointer || ""} ${m.message}`),
          info: report.info,
        })
    );
  }
})().catch((error) => {
  console.error("validator failed: " + error);
  process.exit(1);
});
