// Runs the official Khronos glTF-Validator (npm gltf-validator) on glTF files and fails on any
// error or warning. Used by the Rust tests (tests/it/gltf_export.rs) and the browser test.
//
//   node web/validate-gltf.mjs FILE.glb [FILE.gltf ...]
//
// Prints one JSON line per file: {"file", "errors", "warnings", "infos", "hints", "messages"}
// and exits 1 if any file has an error or a warning (2 if the validator itself failed).
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import { createRequire } from 'node:module';

const require = createRequire(import.meta.url);
const validator = require('gltf-validator');

/** The validator's report for the bytes of `name` (external buffers read beside `file`). */
export async function validate(bytes, file) {
  return validator.validateBytes(new Uint8Array(bytes), {
    uri: path.basename(file),
    maxIssues: 200,
    externalResourceFunction: async (uri) =>
      new Uint8Array(await readFile(path.resolve(path.dirname(file), decodeURIComponent(uri)))),
  });
}

/** A one-line summary of a report. */
export function summary(file, report) {
  const issues = report.issues;
  return {
    file,
    errors: issues.numErrors,
    warnings: issues.numWarnings,
    infos: issues.numInfos,
    hints: issues.numHints,
    messages: issues.messages.map((m) => `${m.severity === 0 ? 'error' : m.severity === 1 ? 'warning' : m.severity === 2 ? 'info' : 'hint'} ${m.code} ${m.pointer ?? ''}: ${m.message}`),
  };
}

if (process.argv[1] && path.resolve(process.argv[1]) === path.resolve(new URL(import.meta.url).pathname)) {
  const files = process.argv.slice(2);
  if (files.length === 0) {
    console.error('usage: node web/validate-gltf.mjs FILE.glb [FILE.gltf ...]');
    process.exit(2);
  }
  let failed = false;
  for (const file of files) {
    try {
      const s = summary(file, await validate(await readFile(file), file));
      console.log(JSON.stringify(s));
      failed ||= s.errors > 0 || s.warnings > 0;
    } catch (e) {
      console.error(`${file}: the validator failed: ${e}`);
      process.exit(2);
    }
  }
  process.exit(failed ? 1 : 0);
}
