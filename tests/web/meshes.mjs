// Test meshes for the browser test, made in code, and an OBJ checker for downloaded results.

/// An icosphere of radius 1 as OBJ text: subdiv 0 = icosahedron (12 v), each level x4 faces
/// (subdiv 2: 162 vertices, 320 faces).
export function icosphere_obj(subdiv) {
  const t = (1 + Math.sqrt(5)) / 2;
  let v = [[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t], [0, 1, -t],
    [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]].map(unit);
  let f = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2],
    [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11],
    [6, 2, 10], [8, 6, 7], [9, 8, 1]];
  for (let s = 0; s < subdiv; ++s) {
    const mid = new Map();
    const m = (a, b) => {
      const key = a < b ? `${a},${b}` : `${b},${a}`;
      if (!mid.has(key)) { mid.set(key, v.length); v.push(unit(v[a].map((x, i) => x + v[b][i]))); }
      return mid.get(key);
    };
    f = f.flatMap(([a, b, c]) => { const ab = m(a, b), bc = m(b, c), ca = m(c, a); return [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]; });
  }
  return `# icosphere subdiv ${subdiv}\n${v.map((p) => `v ${p.join(' ')}`).join('\n')}\n` +
    `${f.map((t3) => `f ${t3.map((i) => i + 1).join(' ')}`).join('\n')}\n`;
}

function unit(p) { const n = Math.hypot(...p); return p.map((x) => x / n); }

/// Counts an OBJ's vertices, faces and unique edges; `error` names the first problem ('' = none):
/// a non-finite coordinate, a face with < 3 corners or an index out of range.
export function parse_obj(text) {
  let vertices = 0;
  let faces = 0;
  let error = '';
  const edges = new Set();
  for (const line of text.split('\n')) {
    const p = line.trim().split(/\s+/);
    if (p[0] === 'v') {
      if (p.length < 4 || !p.slice(1, 4).every((x) => Number.isFinite(+x))) error ||= `bad vertex line "${line}"`;
      ++vertices;
    } else if (p[0] === 'f') {
      const ids = p.slice(1).map((x) => parseInt(x, 10)).map((i) => (i < 0 ? vertices + i + 1 : i));
      if (ids.length < 3) error ||= `face with ${ids.length} corners`;
      for (const i of ids) if (!(i >= 1 && i <= vertices)) error ||= `face index ${i} out of 1..${vertices}`;
      for (let k = 0; k < ids.length; ++k) {
        const a = ids[k], b = ids[(k + 1) % ids.length];
        edges.add(a < b ? `${a},${b}` : `${b},${a}`);
      }
      ++faces;
    }
  }
  if (!vertices || !faces) error ||= 'no vertices or no faces';
  return { vertices, faces, edges: edges.size, error };
}
