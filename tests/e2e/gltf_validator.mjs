// Validates glTF files with the Khronos glTF-Validator (npm gltf-validator); exit 1 on any error.
// With --counts first: one line "ERRORS<tab>FILE" per file on stdout (the report on stderr), exit 0.
import fs from 'fs';
import path from 'path';
import { createRequire } from 'module';
const require = createRequire(import.meta.url);
const validator = require(process.env.GLTF_VALIDATOR || 'gltf-validator');
const counts = process.argv[2] === '--counts';
const log = counts ? console.error : console.log;
let failed = 0;
for (const file of process.argv.slice(counts ? 3 : 2)) {
  const dir = path.dirname(file);
  const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
    uri: path.basename(file),
    externalResourceFunction: (uri) => new Promise((ok, bad) => {
      const p = path.resolve(dir, decodeURIComponent(uri));
      fs.readFile(p, (err, data) => err ? bad(err.toString()) : ok(new Uint8Array(data)));
    }),
  });
  const i = report.issues;
  if (counts) console.log(`${i.numErrors}\t${file}`);
  log(`${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos, ${i.numHints} hints`);
  for (const m of i.messages.filter((m) => m.severity <= 1).slice(0, 5)) log(`  ${m.code}: ${m.message} (${m.pointer || ''})`);
  if (i.numErrors > 0) failed = 1;
}
process.exit(counts ? 0 : failed);
