// Validates every GLB a build wrote with Khronos' glTF-Validator: 0 errors and 0 warnings,
// or the exit code is 1 and each message is printed with its file and JSON pointer.
// Usage: node test/validate.mjs <build directory>
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import validator from 'gltf-validator';

const out = process.argv[2];
if (!out) {
  console.error('usage: node test/validate.mjs <build directory>');
  process.exit(2);
}
const manifest = JSON.parse(await readFile(path.join(out, 'manifest.json'), 'utf8'));
// The leaves, and the parents above them (the levels of detail, in the build's files).
const glbs = manifest.tiles.filter((t) => t.glb).map((t) => t.glb.path)
  .concat(manifest.files.map((f) => f.path).filter((p) => p.startsWith('tiles/lod/')));
if (glbs.length === 0) {
  console.error(`${out}: the manifest lists no GLB tile (build with --format glb)`);
  process.exit(1);
}
let bad = 0;
const infos = new Map();
for (const rel of glbs) {
  const file = path.join(out, rel);
  const bytes = new Uint8Array(await readFile(file));
  const report = await validator.validateBytes(bytes, {
    uri: rel,
    maxIssues: 0,
    externalResourceFunction: (uri) =>
      readFile(path.join(path.dirname(file), decodeURIComponent(uri))).then((b) => new Uint8Array(b)),
  });
  const { numErrors, numWarnings, messages } = report.issues;
  for (const m of messages) {
    if (m.severity <= 1) {
      console.error(`${rel}: ${m.severity === 0 ? 'error' : 'warning'} ${m.code} at ${m.pointer}: ${m.message}`);
    } else {
      infos.set(m.code, (infos.get(m.code) ?? 0) + 1);
    }
  }
  if (numErrors > 0 || numWarnings > 0) bad += 1;
}
const info = [...infos].map(([c, n]) => `${c} x${n}`).join(', ');
console.log(`${glbs.length} GLB(s) validated, ${bad} with errors or warnings${info ? `; info: ${info}` : ''}`);
process.exit(bad > 0 ? 1 : 0);
