// Runs the Khronos glTF Validator (npm `gltf-validator`, pinned by web/package-lock.json)
// over every .glb/.gltf under the folders given, printing one line per file and every
// error; exits 1 when any file has an error (warnings and infos are counted, not fatal).
// Usage: node validate_gltf.cjs NODE_MODULES_DIR FOLDER...
"use strict";
const fs = require("fs");
const path = require("path");
const validator = require(path.resolve(process.argv[2], "gltf-validator"));

function files(dir) {
  const out = [];
  for (const e of fs.readdirSync(dir, { withFileTypes: true })) {
    const p = path.join(dir, e.name);
    if (e.isDirectory()) out.push(...files(p));
    else if (/\.(glb|gltf)$/i.test(e.name)) out.push(p);
  }
  return out.sort();
}

async function main() {
  const all = process.argv.slice(3).flatMap(files);
  let failed = 0;
  for (const f of all) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(f)), {
      uri: path.basename(f),
      maxIssues: 0,
      externalResourceFunction: (uri) =>
        Promise.resolve(new Uint8Array(fs.readFileSync(path.resolve(path.dirname(f), decodeURIComponent(uri))))),
    });
    const n = report.issues;
    console.log(`${f}: ${n.numErrors} errors, ${n.numWarnings} warnings, ${n.numInfos} infos`);
    for (const m of n.messages) {
      if (m.severity === 0) console.log(`    ${m.code} ${m.pointer || ""}: ${m.message}`);
    }
    if (n.numErrors > 0) failed += 1;
  }
  console.log(`${all.length} glTF files validated, ${failed} with errors`);
  if (all.length === 0 || failed > 0) process.exit(1);
}

main().catch((e) => {
  console.error(e);
  process.exit(1);
});
