#!/usr/bin/env node
// SPDX-License-Identifier: MIT
// Validates glTF 2.0 files (.glb or .gltf) with the Khronos glTF validator and prints a summary per
// file and every issue. Usage: node tools/validate_gltf.mjs [--no-warnings] FILE...
// Exit: 0 valid; 1 an error (or a warning, with --no-warnings); 2 usage or an unreadable file;
// 77 the validator is not installed (tools/setup.sh validator puts it in build/npm; the variable
// VKCLOTH_GLTF_VALIDATOR_DIR names another npm prefix).
import { readFile } from "node:fs/promises";
import { createRequire } from "node:module";
import path from "node:path";
import { fileURLToPath } from "node:url";

const repo = path.resolve(path.dirname(fileURLToPath(import.meta.url)), "..");
const prefix = process.env.VKCLOTH_GLTF_VALIDATOR_DIR || path.join(repo, "build", "npm");
const severities = ["error", "warning", "info", "hint"];

function loadValidator() {
  try {
    return createRequire(path.join(prefix, "package.json"))("gltf-validator");
  } catch {
    console.error(`validate_gltf: gltf-validator is not installed in ${prefix} (run tools/setup.sh validator)`);
    process.exit(77);
  }
}

// External buffers and images are read beside the file (the exporter embeds its own).
function externalResources(file) {
  return async (uri) => new Uint8Array(await readFile(path.resolve(path.dirname(file), decodeURIComponent(uri))));
}

async function validate(validator, file, failOnWarnings) {
  let bytes;
  try {
    bytes = new Uint8Array(await readFile(file));
  } catch (e) {
    console.error(`validate_gltf: cannot read ${file}: ${e.message}`);
    return 2;
  }
  const report = await validator.validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 0,
    writeTimestamp: false,
    externalResourceFunction: externalResources(file),
  });
  const n = report.issues;
  console.log(
    `${file}: ${n.numErrors} errors, ${n.numWarnings} warnings, ${n.numInfos} infos, ${n.numHints} hints ` +
      `(glTF validator ${report.validatorVersion})`,
  );
  for (const m of n.messages)
    console.log(`  ${severities[m.severity] ?? m.severity} ${m.code} at ${m.pointer ?? "-"}: ${m.message}`);
  return n.numErrors > 0 || (failOnWarnings && n.numWarnings > 0) ? 1 : 0;
}

const args = process.argv.slice(2);
const failOnWarnings = args.includes("--no-warnings");
const files = args.filter((a) => a !== "--no-warnings");
if (files.length === 0 || files.some((f) => f.startsWith("--"))) {
  console.error("usage: node tools/validate_gltf.mjs [--no-warnings] FILE...");
  process.exit(2);
}
const validator = loadValidator();
let status = 0;
for (const file of files) status = Math.max(status, await validate(validator, file, failOnWarnings));
process.exit(status);
