/// A quick local reading of a mesh file, only for the instant preview and the input's mean edge
/// length before anything is uploaded. The server's reader stays the authority (its summary,
/// repairs and errors replace this after the upload). Polygons are fan-triangulated.
/// Returns {positions: Float32Array, triangles: Uint32Array, faces: polygon count}; throws Error.

import { parse_glb, parse_gltf } from './glb.js';

export function format_of(name) {
  const m = /\.([a-z0-9]+)$/i.exec(name || '');
  return m ? m[1].toLowerCase() : '';
}

export async function read_preview(file) {
  const format = format_of(file.name);
  const buffer = await file.arrayBuffer();
  switch (format) {
    case 'obj': return read_obj(text_of(buffer));
    case 'off': return read_off(text_of(buffer));
    case 'stl': return read_stl(buffer);
    case 'ply': return read_ply(buffer);
    case 'glb': return with_faces(parse_glb(buffer));
    case 'gltf': return with_faces(parse_gltf(JSON.parse(text_of(buffer))));
    default: throw new Error(`unknown format ".${format}" (expected obj, off, ply, stl, gltf or glb)`);
  }
}

const text_of = (buffer) => new TextDecoder().decode(buffer);
const with_faces = (m) => ({ ...m, faces: m.triangles.length / 3 });

class Builder {
  constructor() { this.pos = []; this.tri = []; this.faces = 0; }
  face(ids) {
    if (ids.length < 3) return;
    ++this.faces;
    for (let i = 1; i + 1 < ids.length; ++i) this.tri.push(ids[0], ids[i], ids[i + 1]);
  }
  done() {
    const n = this.pos.length / 3;
    for (const i of this.tri) if (!(i >= 0 && i < n)) throw new Error(`face refers to vertex ${i + 1}, but there are ${n}`);
    if (!this.tri.length) throw new Error(this.pos.length ? 'no faces' : 'no vertices and no faces');
    return { positions: Float32Array.from(this.pos), triangles: Uint32Array.from(this.tri), faces: this.faces };
  }
}

/// Values that are not numbers are named with their line, as the server's reader does (a vertex
/// line "v a b c" was read as NaN and reported as "face refers to vertex NaN").
function read_obj(text) {
  const b = new Builder();
  if (text.includes('\0')) throw new Error('binary data, not OBJ text');
  const lines = text.split('\n');
  for (let k = 0; k < lines.length; ++k) {
    const line = lines[k].replace(/#.*/, '');
    if (line.startsWith('v ') || line.startsWith('v\t')) {
      const p = line.trim().split(/\s+/).slice(1, 4);
      const c = p.map(Number);
      if (c.length < 3) throw new Error(`line ${k + 1}: a vertex with fewer than 3 coordinates`);
      if (!c.every(Number.isFinite))
        throw new Error(`line ${k + 1}: bad vertex coordinate "${p.find((t, i) => !Number.isFinite(c[i]))}"`);
      b.pos.push(...c);
    } else if (line.startsWith('f ') || line.startsWith('f\t')) {
      const n = b.pos.length / 3;
      const ids = line.trim().split(/\s+/).slice(1).map((t) => {
        const i = parseInt(t, 10);
        if (!Number.isInteger(i)) throw new Error(`line ${k + 1}: bad face index "${t}"`);
        return i < 0 ? n + i : i - 1;
      });
      b.face(ids);
    }
  }
  return b.done();
}

function read_off(text) {
  const lines = [];
  for (const raw of text.split('\n')) {
    const line = raw.replace(/#.*/, '').trim();
    if (line) lines.push(line);
  }
  const first = (lines[0] || '').split(/\s+/);
  if (!/^[A-Z]*OFF$/.test(first[0])) throw new Error('OFF header missing');
  let k = 1;
  const counts = first.length > 1 ? first.slice(1) : (lines[k++] || '').split(/\s+/);
  const nv = +counts[0];
  const nf = +counts[1];
  const b = new Builder();
  for (let i = 0; i < nv; ++i) {
    const p = (lines[k++] || '').split(/\s+/);
    b.pos.push(+p[0], +p[1], +p[2]);
  }
  for (let f = 0; f < nf; ++f) {
    const p = (lines[k++] || '').split(/\s+/).map(Number);
    b.face(p.slice(1, 1 + p[0]));
  }
  return b.done();
}

function read_stl(buffer) {
  const dv = new DataView(buffer);
  const binary = buffer.byteLength >= 84 && 84 + 50 * dv.getUint32(80, true) === buffer.byteLength;
  const b = new Builder();
  if (binary) {
    const n = dv.getUint32(80, true);
    for (let t = 0; t < n; ++t) {
      const o = 84 + t * 50 + 12;
      for (let c = 0; c < 9; ++c) b.pos.push(dv.getFloat32(o + 4 * c, true));
      b.face([3 * t, 3 * t + 1, 3 * t + 2]);
    }
    return weld(b.done());
  }
  const re = /vertex\s+(\S+)\s+(\S+)\s+(\S+)/g;
  let m;
  while ((m = re.exec(text_of(buffer)))) b.pos.push(+m[1], +m[2], +m[3]);
  for (let t = 0; 3 * t + 2 < b.pos.length / 3; ++t) b.face([3 * t, 3 * t + 1, 3 * t + 2]);
  return weld(b.done());
}

/// Merges bit-identical positions (STL is a triangle soup), so edges are shared for the preview.
function weld(mesh) {
  const map = new Map();
  const remap = new Uint32Array(mesh.positions.length / 3);
  const pos = [];
  for (let i = 0; i < remap.length; ++i) {
    const key = `${mesh.positions[3 * i]},${mesh.positions[3 * i + 1]},${mesh.positions[3 * i + 2]}`;
    let j = map.get(key);
    if (j === undefined) { j = pos.length / 3; map.set(key, j); pos.push(...mesh.positions.subarray(3 * i, 3 * i + 3)); }
    remap[i] = j;
  }
  return { positions: Float32Array.from(pos), triangles: mesh.triangles.map((i) => remap[i]), faces: mesh.faces };
}

const PLY_TYPES = { char: 'Int8', int8: 'Int8', uchar: 'Uint8', uint8: 'Uint8', short: 'Int16', int16: 'Int16',
  ushort: 'Uint16', uint16: 'Uint16', int: 'Int32', int32: 'Int32', uint: 'Uint32', uint32: 'Uint32',
  float: 'Float32', float32: 'Float32', double: 'Float64', float64: 'Float64' };
const PLY_SIZE = { Int8: 1, Uint8: 1, Int16: 2, Uint16: 2, Int32: 4, Uint32: 4, Float32: 4, Float64: 8 };

function read_ply(buffer) {
  const bytes = new Uint8Array(buffer);
  const head_end = find(bytes, 'end_header');
  if (head_end < 0 || !text_of(buffer.slice(0, 3)).startsWith('ply')) throw new Error('PLY header missing');
  let body = head_end + 'end_header'.length;
  while (bytes[body] === 13) ++body;
  ++body;  // the newline
  const header = text_of(buffer.slice(0, head_end)).split(/\r?\n/);
  const elements = [];
  let format = 'ascii';
  for (const line of header) {
    const p = line.trim().split(/\s+/);
    if (p[0] === 'format') format = p[1];
    else if (p[0] === 'element') elements.push({ name: p[1], count: +p[2], props: [] });
    else if (p[0] === 'property' && elements.length) {
      const e = elements[elements.length - 1];
      if (p[1] === 'list') e.props.push({ name: p[4], count: PLY_TYPES[p[2]], type: PLY_TYPES[p[3]] });
      else e.props.push({ name: p[2], type: PLY_TYPES[p[1]] });
    }
  }
  const b = new Builder();
  const little = format === 'binary_little_endian';
  const dv = new DataView(buffer);
  let tokens = null;
  let t = 0;
  if (format === 'ascii') tokens = text_of(buffer.slice(body)).split(/\s+/).filter(Boolean);
  let o = body;
  const next = (type) => {
    if (tokens) return +tokens[t++];
    const v = dv[`get${type}`](o, little);
    o += PLY_SIZE[type];
    return v;
  };
  for (const e of elements) {
    for (let i = 0; i < e.count; ++i) {
      const v = {};
      let ids = null;
      for (const p of e.props) {
        if (p.count) {
          const n = next(p.count);
          const list = [];
          for (let j = 0; j < n; ++j) list.push(next(p.type));
          if (p.name === 'vertex_indices' || p.name === 'vertex_index') ids = list;
        } else v[p.name] = next(p.type);
      }
      if (e.name === 'vertex') b.pos.push(v.x, v.y, v.z);
      else if (e.name === 'face' && ids) b.face(ids);
    }
  }
  return b.done();
}
function find(bytes, word) {
  const w = [...word].map((c) => c.charCodeAt(0));
  for (let i = 0; i + w.length <= Math.min(bytes.length, 65536); ++i)
    if (w.every((c, j) => bytes[i + j] === c)) return i;
  return -1;
}
