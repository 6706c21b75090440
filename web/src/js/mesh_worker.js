/// Heavy mesh work off the page's thread, so a million-triangle file never freezes the UI:
/// reading a local file for the preview, or parsing a GLB from the server, then extracting the
/// edges and their lengths. Message in: {file: File} or {glb: ArrayBuffer}. Message out:
/// {mesh: {positions, triangles, faces, pairs, lengths}} (buffers transferred) or {error}.

import { read_preview } from './preview.js';
import { parse_glb } from './glb.js';
import { triangle_edges, edge_lengths } from './edges.js';

self.onmessage = async ({ data }) => {
  try {
    const mesh = data.file ? await read_preview(data.file) : parse_glb(data.glb);
    const vertex_count = mesh.positions.length / 3;
    const pairs = mesh.lines && mesh.lines.length ? mesh.lines : triangle_edges(mesh.triangles, vertex_count);
    const lengths = edge_lengths(mesh.positions, pairs);
    const out = { positions: mesh.positions, triangles: mesh.triangles, faces: mesh.faces ?? mesh.triangles.length / 3,
      pairs, lengths };
    self.postMessage({ mesh: out }, [out.positions.buffer, out.triangles.buffer, pairs.buffer, lengths.buffer]);
  } catch (e) {
    self.postMessage({ error: e.message || String(e) });
  }
};
