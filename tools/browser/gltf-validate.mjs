// tools/browser/gltf-validate.mjs: validates glTF 2.0 files (.glb or .gltf) with the Khronos glTF
// validator (the pinned npm package gltf-validator) and prints each of its messages, one line each:
// "FILE: SEVERITY CODE at POINTER: message". Errors fail; warnings, infos and hints are listed
// and allowed. External resources (.bin, images) are read relative to the file.
// Run it through tools/gltf-validate.sh, which installs what it needs.
// Usage: node gltf-validate.mjs FILE...   Exit: 0 no error, 1 an error in some file, 2 bad usage.
import { createRequire } from 'node:module';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const nodeDir = process.env.SHADOWLAB_NODE_DIR ? path.resolve(process.env.SHADOWLAB_NODE_DIR) : path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../../build/node');
const require = createRequire(path.join(nodeDir, 'node_modules', 'noop.js'));
const validator = require('gltf-validator');

const kSeverity = ['error', 'warning', 'info', 'hint'];

const files = process.argv.slice(2);
if (files.length === 0) {
  console.error('gltf-validate: usage: gltf-validate.mjs FILE...');
  process.exit(2);
}

let failed = false;
for (const file of files) {
  let bytes;
  try {
    bytes = new Uint8Array(fs.readFileSync(file));
  } catch (e) {
    console.error(`gltf-validate: error: ${file}: cannot read (${e.code || e.message})`);
    process.exit(2);
  }
  const dir = path.dirname(file);
  const report = await validator.validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 0,  // all of them
    externalResourceFunction: (uri) => new Promise((resolve, reject) => {
      fs.readFile(path.join(dir, decodeURIComponent(uri)), (err, data) => err ? reject(err.toString()) : resolve(new Uint8Array(data)));
    }),
  });
  const issues = report.issues;
  for (const m of issues.messages) {
    const where = m.pointer ? ` at ${m.pointer}` : (m.offset !== undefined ? ` at byte ${m.offset}` : '');
    console.log(`${file}: ${kSeverity[m.severity] || m.severity} ${m.code}${where}: ${m.message}`);
  }
  console.log(`${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ${issues.numInfos} infos, ${issues.numHints} hints (glTF validator ${report.validatorVersion})`);
  if (issues.numErrors > 0) failed = true;
}
process.exit(failed ? 1 : 0);
