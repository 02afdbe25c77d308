// Validates glb files with the Khronos glTF validator (npm gltf-validator) and prints
// the counts of its messages by severity and code. Usage: node validate.mjs FILE.glb ...
// (The validator does not decode EXT_meshopt_compression: it reports the web profile
// as UNSUPPORTED_EXTENSION and checks its JSON only; load.mjs decodes it.)
import validator from 'gltf-validator';
import fs from 'fs';
for (const f of process.argv.slice(2)) {
  const data = new Uint8Array(fs.readFileSync(f));
  const r = await validator.validateBytes(data, {maxIssues: 0, writeTimestamp: false});
  const counts = {};
  for (const m of r.issues.messages) counts[`${m.severity}:${m.code}`] = (counts[`${m.severity}:${m.code}`]||0)+1;
  console.log(f.split('/').pop(), 'errors', r.issues.numErrors, 'warnings', r.issues.numWarnings, 'infos', r.issues.numInfos, JSON.stringify(counts));
}
