// Validates .glb files with the Khronos glTF-Validator (npm gltf-validator) and prints one
// line per file: errors, warnings, infos, and the first messages. Exits 1 if any file has
// an error (or cannot be read), 2 on wrong use.
//   node validate-gltf.mjs FILE.glb...
import { readFile } from 'node:fs/promises';
import { createRequire } from 'node:module';

const require = createRequire(process.cwd() + '/');
const validator = require('gltf-validator');

const files = process.argv.slice(2);
if (files.length === 0) {
  console.error('usage: node validate-gltf.mjs FILE.glb...');
  process.exit(2);
}
let failed = false;
for (const file of files) {
  try {
    const report = await validator.validateBytes(new Uint8Array(await readFile(file)), { maxIssues: 50 });
    const i = report.issues;
    console.log(`${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos`);
    for (const m of i.messages.filter((m) => m.severity <= 1).slice(0, 10))
      console.log(`  ${m.severity === 0 ? 'error' : 'warning'} ${m.code} at ${m.pointer}: ${m.message}`);
    if (i.numErrors > 0) failed = true;
  } catch (e) {
    console.log(`${file}: cannot validate: ${e.message ?? e}`);
    failed = true;
  }
}
process.exit(failed ? 1 : 0);
