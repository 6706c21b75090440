/// A small glTF 2.0 reader for what remeshd writes (and what users upload): every mesh primitive's
/// POSITION and indices, merged into one vertex array. Triangles (modes 4, 5, 6) become one
/// triangle index list; LINES (mode 1) primitives become a line index list (the dual's true polygon
/// edges). Node transforms are applied. Throws Error with a one-line message on malformed input.

const COMPONENTS = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4, MAT4: 16 };
const TYPED = { 5120: Int8Array, 5121: Uint8Array, 5122: Int16Array, 5123: Uint16Array,
  5125: Uint32Array, 5126: Float32Array };

/// Parses a .glb (ArrayBuffer). Returns {positions: Float32Array (xyz), triangles: Uint32Array,
/// lines: Uint32Array (pairs, may be empty)}.
export function parse_glb(buffer) {
  const view = new DataView(buffer);
  if (buffer.byteLength < 20 || view.getUint32(0, true) !== 0x46546c67) throw new Error('not a GLB file (bad magic)');
  if (view.getUint32(4, true) !== 2) throw new Error('unsupported glTF version (need 2)');
  let offset = 12;
  let doc = null;
  let bin = null;
  while (offset + 8 <= buffer.byteLength) {
    const length = view.getUint32(offset, true);
    const type = view.getUint32(offset + 4, true);
    const start = offset + 8;
    if (start + length > buffer.byteLength) throw new Error('GLB chunk runs past the end of the file');
    if (type === 0x4e4f534a) doc = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, start, length)));
    else if (type === 0x004e4942) bin = new Uint8Array(buffer, start, length);
    offset = start + length + ((4 - (length % 4)) % 4);
  }
  if (!doc) throw new Error('GLB without a JSON chunk');
  return parse_gltf(doc, [bin]);
}

/// Parses a glTF JSON document whose buffers are given (Uint8Array each); data: URIs are decoded.
export function parse_gltf(doc, buffers = []) {
  const bufs = (doc.buffers || []).map((b, i) => {
    if (b.uri && b.uri.startsWith('data:')) return decode_data_uri(b.uri);
    if (buffers[i]) return buffers[i];
    throw new Error(`buffer ${i} is external (${b.uri || 'no uri'}); only GLB and data: URIs are read`);
  });
  const read = (index) => read_accessor(doc, bufs, index);

  const pos_chunks = [];
  const tris = [];
  const lines = [];
  let base = 0;
  const bases = new Map();
  const visit = (node_index, parent) => {
    const node = doc.nodes[node_index];
    const m = multiply(parent, node_matrix(node));
    if (node.mesh !== undefined) {
      for (const prim of doc.meshes[node.mesh].primitives || []) {
        if (prim.attributes?.POSITION === undefined) continue;
        // Primitives sharing a POSITION accessor (the dual's fan and its LINES) share vertices.
        const key = `${prim.attributes.POSITION}|${m.join(',')}`;
        let start = bases.get(key);
        const count = doc.accessors[prim.attributes.POSITION].count;
        if (start === undefined) {
          start = base;
          bases.set(key, start);
          pos_chunks.push(transform(read(prim.attributes.POSITION), m));
          base += count;
        }
        const idx = prim.indices !== undefined ? read(prim.indices) : iota(count);
        const mode = prim.mode ?? 4;
        if (mode === 1) lines.push(offset_by(idx, start));
        else if (mode === 4) tris.push(offset_by(idx, start));
        else if (mode === 5 || mode === 6) tris.push(offset_by(unstrip(idx, mode), start));
      }
    }
    for (const child of node.children || []) visit(child, m);
  };
  const scene = doc.scenes?.[doc.scene ?? 0];
  const roots = scene ? scene.nodes : (doc.nodes || []).map((_, i) => i);
  if (doc.nodes) for (const r of roots) visit(r, IDENTITY);
  if (!pos_chunks.length) throw new Error('glTF holds no mesh with positions');
  return { positions: concat(Float32Array, pos_chunks), triangles: concat(Uint32Array, tris),
    lines: concat(Uint32Array, lines) };
}

function read_accessor(doc, bufs, index) {
  const acc = doc.accessors[index];
  const n = COMPONENTS[acc.type];
  const Type = TYPED[acc.componentType];
  if (!n || !Type) throw new Error(`accessor ${index}: unsupported type ${acc.type}/${acc.componentType}`);
  const out = new (Type === Float32Array ? Float32Array : Uint32Array)(acc.count * n);
  if (acc.bufferView === undefined) return out;
  const bv = doc.bufferViews[acc.bufferView];
  const buf = bufs[bv.buffer];
  const start = (bv.byteOffset || 0) + (acc.byteOffset || 0);
  const size = Type.BYTES_PER_ELEMENT;
  const stride = bv.byteStride || size * n;
  if (start + stride * (acc.count - 1) + size * n > buf.byteLength) throw new Error(`accessor ${index} runs past its buffer`);
  if (stride === size * n && (buf.byteOffset + start) % size === 0) {
    out.set(new Type(buf.buffer, buf.byteOffset + start, acc.count * n));
    return out;
  }
  const dv = new DataView(buf.buffer, buf.byteOffset);
  const get = { 5120: 'getInt8', 5121: 'getUint8', 5122: 'getInt16', 5123: 'getUint16',
    5125: 'getUint32', 5126: 'getFloat32' }[acc.componentType];
  for (let i = 0; i < acc.count; ++i)
    for (let c = 0; c < n; ++c) out[i * n + c] = dv[get](start + i * stride + c * size, true);
  return out;
}

function decode_data_uri(uri) {
  const comma = uri.indexOf(',');
  const bin = atob(uri.slice(comma + 1));
  const out = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; ++i) out[i] = bin.charCodeAt(i);
  return out;
}

function unstrip(idx, mode) {
  const out = [];
  for (let i = 2; i < idx.length; ++i) {
    if (mode === 6) out.push(idx[0], idx[i - 1], idx[i]);
    else if (i % 2) out.push(idx[i - 1], idx[i - 2], idx[i]);
    else out.push(idx[i - 2], idx[i - 1], idx[i]);
  }
  return Uint32Array.from(out);
}

const IDENTITY = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];
function node_matrix(node) {
  if (node.matrix) return node.matrix;
  const [x, y, z, w] = node.rotation || [0, 0, 0, 1];
  const [sx, sy, sz] = node.scale || [1, 1, 1];
  const [tx, ty, tz] = node.translation || [0, 0, 0];
  return [(1 - 2 * (y * y + z * z)) * sx, 2 * (x * y + z * w) * sx, 2 * (x * z - y * w) * sx, 0,
    2 * (x * y - z * w) * sy, (1 - 2 * (x * x + z * z)) * sy, 2 * (y * z + x * w) * sy, 0,
    2 * (x * z + y * w) * sz, 2 * (y * z - x * w) * sz, (1 - 2 * (x * x + y * y)) * sz, 0, tx, ty, tz, 1];
}
function multiply(a, b) { // column-major 4x4
  const o = new Array(16);
  for (let c = 0; c < 4; ++c)
    for (let r = 0; r < 4; ++r) {
      let s = 0;
      for (let k = 0; k < 4; ++k) s += a[k * 4 + r] * b[c * 4 + k];
      o[c * 4 + r] = s;
    }
  return o;
}
function transform(p, m) {
  if (m.every((v, i) => v === IDENTITY[i])) return p;
  const out = new Float32Array(p.length);
  for (let i = 0; i < p.length; i += 3) {
    const x = p[i], y = p[i + 1], z = p[i + 2];
    out[i] = m[0] * x + m[4] * y + m[8] * z + m[12];
    out[i + 1] = m[1] * x + m[5] * y + m[9] * z + m[13];
    out[i + 2] = m[2] * x + m[6] * y + m[10] * z + m[14];
  }
  return out;
}
function iota(n) { const a = new Uint32Array(n); for (let i = 0; i < n; ++i) a[i] = i; return a; }
function offset_by(idx, base) {
  if (!base) return idx;
  const out = new Uint32Array(idx.length);
  for (let i = 0; i < idx.length; ++i) out[i] = idx[i] + base;
  return out;
}
function concat(Type, parts) {
  if (parts.length === 1) return parts[0] instanceof Type ? parts[0] : Type.from(parts[0]);
  const out = new Type(parts.reduce((s, p) => s + p.length, 0));
  let o = 0;
  for (const p of parts) { out.set(p, o); o += p.length; }
  return out;
}
