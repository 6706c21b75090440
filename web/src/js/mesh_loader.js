/// Meshes for the 3D view, read off the page's thread: a local file (preview) or a GLB from the
/// server, with its edges and their lengths (see mesh_worker.js).

import { read_preview } from './preview.js';
import { parse_glb } from './glb.js';
import { triangle_edges, edge_lengths } from './edges.js';

/// Reads {file} or parses {glb} and extracts the edges in mesh_worker.js; on the page's thread
/// when workers are unavailable.
export function in_worker(message) {
  return new Promise((resolve, reject) => {
    let worker;
    try {
      worker = new Worker(new URL('./mesh_worker.js', import.meta.url), { type: 'module' });
    } catch {
      return resolve(on_this_thread(message));
    }
    worker.onmessage = ({ data }) => {
      worker.terminate();
      if (data.error) reject(new Error(data.error)); else resolve(data.mesh);
    };
    worker.onerror = (e) => { worker.terminate(); reject(new Error(e.message || 'mesh worker failed')); };
    worker.postMessage(message);
  });
}

async function on_this_thread(message) {
  const mesh = message.file ? await read_preview(message.file) : parse_glb(message.glb);
  const pairs = mesh.lines && mesh.lines.length ? mesh.lines
    : triangle_edges(mesh.triangles, mesh.positions.length / 3);
  return { ...mesh, pairs, lengths: edge_lengths(mesh.positions, pairs) };
}
