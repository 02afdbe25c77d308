// Loads glb files with three.js r187 (GLTFLoader + MeshoptDecoder) in Node and prints,
// per file, meshes, triangles, vertices, out-of-range indices or non-finite positions
// ("bad", must be 0), primitives with _FEATURE_ID_0, world bounds and a checksum of the
// world-space triangle corners and normals (equal checksums: the same geometry, e.g. a
// web file before and after a layout change). Images are not decoded (Node has no
// image decoder; createImageBitmap is stubbed). Usage: node load.mjs FILE.glb ...
import fs from 'fs';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { MeshoptDecoder } from 'three/examples/jsm/libs/meshopt_decoder.module.js';
import * as THREE from 'three';
const realFetch = globalThis.fetch;
const blobs = new Map();
const origCreate = URL.createObjectURL;
URL.createObjectURL = (b) => { const u = origCreate(b); blobs.set(u, b); return u; };
globalThis.fetch = async (u, o) => blobs.has(u) ? new Response(blobs.get(u)) : realFetch(u, o);
globalThis.createImageBitmap = async () => ({ width: 1, height: 1, close() {} });
globalThis.self = globalThis;
for (const f of process.argv.slice(2)) {
  const buf = fs.readFileSync(f);
  const ab = buf.buffer.slice(buf.byteOffset, buf.byteOffset + buf.byteLength);
  const loader = new GLTFLoader();
  loader.setMeshoptDecoder(MeshoptDecoder);
  const t = performance.now();
  const gltf = await new Promise((res, rej) => loader.parse(ab, '', res, rej));
  let sum = 0, nsum = 0; let meshes = 0, tris = 0, verts = 0, bad = 0, feature = 0;
  const box = new THREE.Box3();
  gltf.scene.updateMatrixWorld(true);
  gltf.scene.traverse((o) => {
    if (!o.isMesh) return;
    meshes++;
    const g = o.geometry;
    const p = g.attributes.position;
    verts += p.count;
    const idx = g.index;
    tris += idx.count / 3;
    for (let i = 0; i < idx.count; i++) if (idx.getX(i) >= p.count) bad++;
    for (let i = 0; i < p.count; i++) if (!Number.isFinite(p.getX(i) + p.getY(i) + p.getZ(i))) bad++;
    if (g.attributes._feature_id_0) feature++;
    const v = new THREE.Vector3();
    for (let i = 0; i < idx.count; i++) { v.fromBufferAttribute(p, idx.getX(i)).applyMatrix4(o.matrixWorld); sum += v.x + 3 * v.y + 7 * v.z; }
    const nr = g.attributes.normal; for (let i = 0; i < nr.count; i++) nsum += nr.getX(i) + 3 * nr.getY(i) + 7 * nr.getZ(i);
    const b = new THREE.Box3().setFromObject(o);
    box.union(b);
  });
  console.log(f.split('/').pop(), 'meshes', meshes, 'triangles', tris, 'vertices', verts, 'bad', bad,
    'with feature ids', feature, 'bounds', box.min.toArray().map(Math.round), box.max.toArray().map(Math.round),
    'checksum', sum.toFixed(1), nsum.toFixed(2), 'ms', Math.round(performance.now() - t));
}
