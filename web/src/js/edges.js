/// Edge sets of a mesh as flat typed arrays (a million triangles stay cheap): unique edges of a
/// triangle list, their lengths, the short / inside / long classification and a histogram.

/// Unique undirected edges of a triangle index list, as pairs (Uint32Array of 2E). Half-edges are
/// bucketed by their smaller vertex (a counting sort, O(F)) and each small bucket deduplicated, so
/// a million triangles take a fraction of a second.
export function triangle_edges(triangles, vertex_count) {
  const start = new Uint32Array(vertex_count + 1);
  for (let t = 0; t < triangles.length; t += 3) {
    for (let k = 0; k < 3; ++k) {
      const a = triangles[t + k];
      const b = triangles[t + (k + 1) % 3];
      ++start[(a < b ? a : b) + 1];
    }
  }
  for (let v = 0; v < vertex_count; ++v) start[v + 1] += start[v];
  const cursor = start.slice(0, vertex_count);
  const other = new Uint32Array(triangles.length);
  for (let t = 0; t < triangles.length; t += 3) {
    for (let k = 0; k < 3; ++k) {
      const a = triangles[t + k];
      const b = triangles[t + (k + 1) % 3];
      if (a < b) other[cursor[a]++] = b; else other[cursor[b]++] = a;
    }
  }
  const out = new Uint32Array(triangles.length * 2);
  let o = 0;
  for (let a = 0; a < vertex_count; ++a) {
    const lo = start[a];
    const hi = start[a + 1];
    if (hi - lo > 16) other.subarray(lo, hi).sort();
    for (let i = lo; i < hi; ++i) {
      const b = other[i];
      let seen = false;
      if (hi - lo > 16) seen = i > lo && other[i - 1] === b;
      else for (let j = lo; j < i; ++j) if (other[j] === b) { seen = true; break; }
      if (seen || b === a) continue;
      out[o++] = a;
      out[o++] = b;
    }
  }
  return out.slice(0, o);
}

/// Length of each edge (Float32Array of E).
export function edge_lengths(positions, pairs) {
  const out = new Float32Array(pairs.length / 2);
  for (let e = 0; e < out.length; ++e) {
    const a = pairs[2 * e] * 3;
    const b = pairs[2 * e + 1] * 3;
    const dx = positions[a] - positions[b];
    const dy = positions[a + 1] - positions[b + 1];
    const dz = positions[a + 2] - positions[b + 2];
    out[e] = Math.sqrt(dx * dx + dy * dy + dz * dz);
  }
  return out;
}

/// Writes the edge pairs into `target` (Uint32Array of 2E) grouped short | inside | long with
/// respect to [emin, emax] and returns the group sizes {short, inside, long} (edges). Without a
/// valid interval every edge counts as inside.
export function classify(pairs, lengths, emin, emax, target) {
  const valid = Number.isFinite(emin) && Number.isFinite(emax) && emin > 0 && emax > emin;
  let nshort = 0;
  let nlong = 0;
  if (valid) for (let e = 0; e < lengths.length; ++e) {
    if (lengths[e] < emin) ++nshort; else if (lengths[e] > emax) ++nlong;
  }
  let s = 0;
  let i = nshort;
  let l = lengths.length - nlong;
  for (let e = 0; e < lengths.length; ++e) {
    const len = lengths[e];
    const slot = !valid ? i++ : len < emin ? s++ : len > emax ? l++ : i++;
    target[2 * slot] = pairs[2 * e];
    target[2 * slot + 1] = pairs[2 * e + 1];
  }
  return { short: nshort, inside: lengths.length - nshort - nlong, long: nlong };
}

/// Summary numbers of an edge-length array: {count, min, max, mean, deviation}.
export function length_stats(lengths) {
  let min = Infinity;
  let max = 0;
  let sum = 0;
  let sum2 = 0;
  for (let e = 0; e < lengths.length; ++e) {
    const v = lengths[e];
    if (v < min) min = v;
    if (v > max) max = v;
    sum += v;
    sum2 += v * v;
  }
  const n = lengths.length || 1;
  const mean = sum / n;
  return { count: lengths.length, min: lengths.length ? min : 0, max, mean,
    deviation: Math.sqrt(Math.max(0, sum2 / n - mean * mean)) };
}

/// Histogram of lengths over [lo, hi] in `bins` bins (values outside land in the end bins), one
/// count array per class of `classify` ({short, inside, long}, Uint32Array each), so a bar's
/// colours say exactly how many of its edges are short or long, whatever the bin edges.
/// Without a valid interval every edge counts as inside.
export function class_histogram(lengths, lo, hi, bins, emin, emax) {
  const out = { short: new Uint32Array(bins), inside: new Uint32Array(bins), long: new Uint32Array(bins) };
  const valid = Number.isFinite(emin) && Number.isFinite(emax) && emin > 0 && emax > emin;
  const scale = hi > lo ? bins / (hi - lo) : 0;
  for (let e = 0; e < lengths.length; ++e) {
    const len = lengths[e];
    let b = Math.floor((len - lo) * scale);
    if (b < 0) b = 0; else if (b >= bins) b = bins - 1;
    ++(!valid ? out.inside : len < emin ? out.short : len > emax ? out.long : out.inside)[b];
  }
  return out;
}
