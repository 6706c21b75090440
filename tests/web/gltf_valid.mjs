// The glTF the product writes, checked by the Khronos glTF validator (gltf-validator from the npm
// registry, in web/node_modules): a remeshed sphere and its trivalent dual (polygons: triangle fans
// plus a LINES primitive), and the dual of one triangle (a POINTS primitive), each as .glb and as
// .gltf, written by the `remesh` CLI (the daemon's downloads are the same writer). Every file must have no error and no warning, and the validator's
// own count of triangles must be the mesh's (`remesh info --json` on the OBJ written beside it).
// Environment: REMESH (the CLI). Exits non-zero with one line per failed check.

import { execFileSync } from 'node:child_process';
import { createRequire } from 'node:module';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { icosphere_obj } from './meshes.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const validator = createRequire(path.resolve(here, '../../web/package.json'))('gltf-validator');
const remesh = process.env.REMESH || 'remesh';
const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'remesh-gltf-'));
const failures = [];
function check(ok, what) {
  console.log(ok ? 'ok  ' : 'FAIL', what);
  if (!ok) failures.push(what);
}
const file = (name) => path.join(tmp, name);
const run = (...args) => execFileSync(remesh, args, { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });

/// Triangles of an OBJ's faces once fan-triangulated (what the glTF writers draw).
function fan_triangles(obj_path) {
  let n = 0;
  for (const line of fs.readFileSync(obj_path, 'utf8').split('\n'))
    if (line.startsWith('f ')) n += line.trim().split(/\s+/).length - 3;
  return n;
}

async function validate(name, triangles) {
  const bytes = new Uint8Array(fs.readFileSync(file(name)));
  const report = await validator.validateBytes(bytes, { uri: name, maxIssues: 50 });
  const issues = report.issues.messages.map((m) => `${m.code} ${m.pointer || ''}: ${m.message}`);
  check(report.issues.numErrors === 0 && report.issues.numWarnings === 0,
    `${name}: no error, no warning (${report.issues.numErrors} errors, ${report.issues.numWarnings} warnings` +
    `${issues.length ? `: ${issues.slice(0, 5).join('; ')}` : ''})`);
  check(report.info?.totalTriangleCount === triangles,
    `${name}: ${triangles} triangles, the validator counts ${report.info?.totalTriangleCount}`);
  return report;
}

async function main() {
  fs.writeFileSync(file('sphere.obj'), icosphere_obj(2));  // radius 1, edges about 0.25
  for (const ext of ['glb', 'gltf']) {
    run(file('sphere.obj'), file(`remeshed.${ext}`), '--emin', '0.12', '--emax', '0.18', '--dual', file(`dual.${ext}`),
      '--quiet');
  }
  // The same run again as OBJ (deterministic): the meshes the glTF files hold.
  run(file('sphere.obj'), file('remeshed.obj'), '--emin', '0.12', '--emax', '0.18', '--dual', file('dual.obj'), '--quiet');
  const faces = JSON.parse(run('info', file('remeshed.obj'), '--json')).faces;
  check(fan_triangles(file('remeshed.obj')) === faces, `remeshed.obj has ${faces} triangles`);
  for (const ext of ['glb', 'gltf']) {
    await validate(`remeshed.${ext}`, faces);
    const dual = await validate(`dual.${ext}`, fan_triangles(file('dual.obj')));
    // The dual's polygons: a second primitive (LINES) for their true edges.
    check(dual.info?.drawCallCount === 2, `dual.${ext}: two primitives, fans and LINES (${dual.info?.drawCallCount})`);
  }
  // The dual of one triangle: an atom and no ring, a POINTS primitive (an empty scene was invalid).
  fs.writeFileSync(file('triangle.obj'), 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n');
  for (const ext of ['glb', 'gltf']) {
    run('dual', file('triangle.obj'), file(`atom.${ext}`));
    const report = await validate(`atom.${ext}`, 0);
    check(report.info?.totalVertexCount === 1, `atom.${ext}: one vertex (${report.info?.totalVertexCount})`);
  }
  // Text glTF carries its buffer inside: nothing beside it to load.
  const text = JSON.parse(fs.readFileSync(file('remeshed.gltf'), 'utf8'));
  check(text.buffers.length === 1 && text.buffers[0].uri.startsWith('data:application/octet-stream;base64,'),
    'remeshed.gltf: one buffer, a base64 data URI');
}

main()
  .catch((err) => failures.push(`unexpected: ${err.stack || err}`))
  .finally(() => {
    fs.rmSync(tmp, { recursive: true, force: true });
    if (failures.length) {
      console.error(`${failures.length} check(s) failed:\n${failures.join('\n')}`);
      process.exitCode = 1;
    }
  });
