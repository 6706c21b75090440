/// Line and bar charts drawn on <canvas> (no chart library): the iteration plots of the thesis'
/// figures 4.7-4.11 and the edge-length histogram. Redraws are batched per animation frame.

/// Reads a CSS custom property of the root element (theme colours).
export function css(name) {
  return getComputedStyle(document.documentElement).getPropertyValue(name).trim();
}

/// Sizes the canvas backing store to its CSS box times devicePixelRatio; returns {ctx, w, h} in
/// CSS pixels, or null while the canvas is not laid out.
export function fit_canvas(canvas) {
  const w = canvas.clientWidth;
  const h = canvas.clientHeight;
  if (!w || !h) return null;
  const dpr = window.devicePixelRatio || 1;
  if (canvas.width !== Math.round(w * dpr) || canvas.height !== Math.round(h * dpr)) {
    canvas.width = Math.round(w * dpr);
    canvas.height = Math.round(h * dpr);
  }
  const ctx = canvas.getContext('2d');
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  ctx.clearRect(0, 0, w, h);
  return { ctx, w, h };
}

/// Short number for axis labels: 12.3k, 0.0123, 4.5e-7.
export function fmt(v) {
  if (!Number.isFinite(v)) return '–';
  const a = Math.abs(v);
  if (a === 0) return '0';
  if (a >= 1e6) return `${(v / 1e6).toPrecision(3)}M`;
  if (a >= 1e4) return `${(v / 1e3).toPrecision(3)}k`;
  if (a >= 1) return String(+v.toPrecision(4));
  if (a >= 1e-3) return String(+v.toPrecision(3));
  return v.toExponential(1);
}

function nice_ticks(lo, hi, count) {
  const span = hi - lo || Math.abs(hi) || 1;
  const raw = span / count;
  const mag = 10 ** Math.floor(Math.log10(raw));
  const step = [1, 2, 2.5, 5, 10].map((m) => m * mag).find((s) => span / s <= count) || 10 * mag;
  const ticks = [];
  for (let t = Math.ceil(lo / step) * step; t <= hi + step * 1e-9; t += step) ticks.push(t);
  return ticks;
}

/// A chart of several series against the iteration number.
/// series: [{key: row => value, label, color: css var name, bars?: true}]; marks: () => [{value,
/// label, color}] horizontal reference lines (e.g. e_min, e_max).
export class IterationChart {
  constructor(canvas, series, { marks = () => [], min_zero = true, percent = false } = {}) {
    this.canvas = canvas;
    this.series = series;
    this.marks = marks;
    this.min_zero = min_zero;
    this.percent = percent;
    this.rows = [];
    this.pending = false;
    new ResizeObserver(() => this.schedule()).observe(canvas);
  }

  set_rows(rows) { this.rows = rows; this.schedule(); }

  schedule() {
    if (this.pending) return;
    this.pending = true;
    requestAnimationFrame(() => { this.pending = false; this.draw(); });
  }

  draw() {
    const fit = fit_canvas(this.canvas);
    if (!fit) return;
    const { ctx, w, h } = fit;
    const rows = this.rows;
    const pad = { l: 44, r: 8, t: 16, b: 18 };
    const pw = w - pad.l - pad.r;
    const ph = h - pad.t - pad.b;
    ctx.font = '10px system-ui, sans-serif';
    const muted = css('--muted');
    const line = css('--line');

    let lo = Infinity;
    let hi = -Infinity;
    for (const s of this.series) for (const r of rows) {
      const v = s.key(r);
      if (Number.isFinite(v)) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
    }
    const marks = this.marks().filter((m) => Number.isFinite(m.value));
    for (const m of marks) { lo = Math.min(lo, m.value); hi = Math.max(hi, m.value); }
    if (!Number.isFinite(lo)) { lo = 0; hi = 1; }
    if (this.min_zero) lo = Math.min(0, lo);
    if (this.percent) { lo = Math.max(0, Math.min(lo, 0)); hi = Math.max(hi, 100); }
    if (hi === lo) hi = lo + (Math.abs(lo) || 1);
    hi += (hi - lo) * 0.04;
    const bars = this.series.some((s) => s.bars) ? 0.5 : 0;  // room for the first and last bar
    const n_max = (rows.length ? Math.max(rows[rows.length - 1].iteration, 1) : 1) + bars;
    const n_min = (rows.length ? Math.min(rows[0].iteration, n_max - 1) : 0) - bars;
    const x = (it) => pad.l + ((it - n_min) / (n_max - n_min || 1)) * pw;
    const y = (v) => pad.t + ph - ((v - lo) / (hi - lo)) * ph;

    ctx.strokeStyle = line;
    ctx.fillStyle = muted;
    ctx.lineWidth = 1;
    ctx.textAlign = 'right';
    ctx.textBaseline = 'middle';
    for (const t of nice_ticks(lo, hi, 4)) {
      const yy = Math.round(y(t)) + 0.5;
      ctx.beginPath(); ctx.moveTo(pad.l, yy); ctx.lineTo(w - pad.r, yy); ctx.stroke();
      ctx.fillText(fmt(t), pad.l - 4, yy);
    }
    ctx.textAlign = 'center';
    ctx.textBaseline = 'top';
    for (const t of nice_ticks(n_min, n_max, Math.max(2, Math.floor(pw / 60)))) {
      if (t !== Math.round(t)) continue;
      ctx.fillText(String(t), x(t), h - pad.b + 4);
    }
    for (const m of marks) {
      ctx.strokeStyle = css(m.color);
      ctx.setLineDash([4, 3]);
      const yy = Math.round(y(m.value)) + 0.5;
      ctx.beginPath(); ctx.moveTo(pad.l, yy); ctx.lineTo(w - pad.r, yy); ctx.stroke();
      ctx.setLineDash([]);
    }

    for (const s of this.series) {
      const color = css(s.color);
      ctx.strokeStyle = color;
      ctx.fillStyle = color;
      ctx.lineWidth = 1.5;
      if (s.bars) {
        const bw = Math.max(1, (pw / Math.max(rows.length, 1)) * 0.7);
        for (const r of rows) {
          const v = s.key(r);
          if (Number.isFinite(v)) ctx.fillRect(x(r.iteration) - bw / 2, y(v), bw, y(lo) - y(v));
        }
        continue;
      }
      ctx.beginPath();
      let started = false;
      for (const r of rows) {
        const v = s.key(r);
        if (!Number.isFinite(v)) continue;
        if (started) ctx.lineTo(x(r.iteration), y(v)); else ctx.moveTo(x(r.iteration), y(v));
        started = true;
      }
      ctx.stroke();
      if (rows.length === 1 && started) {
        ctx.beginPath(); ctx.arc(x(rows[0].iteration), y(s.key(rows[0])), 2.5, 0, 7); ctx.fill();
      }
    }
    // The reference lines' labels over the curves, on a patch of the canvas' colour (drawn under
    // them, the mean's curve ran through "e_min").
    // Each label sits above its line, or below it when the line above is too close (a narrow
    // interval: the e_min label and its patch covered the e_max line and label).
    ctx.textAlign = 'left';
    ctx.textBaseline = 'bottom';
    const lines = marks.map((m) => ({ m, yy: Math.round(y(m.value)) + 0.5 })).sort((a, b) => a.yy - b.yy);
    let above = -Infinity;  // the bottom of the last label drawn, higher up
    for (const { m, yy } of lines) {
      const tw = ctx.measureText(m.label).width;
      const top = yy - 13 >= above ? yy - 13 : yy + 1;
      ctx.fillStyle = css('--bg');
      ctx.fillRect(pad.l + 1, top, tw + 4, 12);
      ctx.fillStyle = css(m.color);
      ctx.fillText(m.label, pad.l + 3, top + 12);
      above = top + 12;
    }
    // Legend, top right.
    ctx.textAlign = 'right';
    ctx.textBaseline = 'top';
    let lx = w - pad.r;
    for (const s of [...this.series].reverse()) {
      ctx.fillStyle = muted;
      ctx.fillText(s.label, lx, 2);
      lx -= ctx.measureText(s.label).width + 4;
      ctx.fillStyle = css(s.color);
      ctx.fillRect(lx - 10, 6, 10, 3);
      lx -= 18;
    }
  }
}

/// Draws a histogram of edge lengths over [lo, hi]: `hist` = {short, inside, long} counts per bin
/// (edges.js class_histogram). With `classes` each bar is split by the classes of its edges (so a
/// result with no short or long edge shows no short or long colour), and [emin, emax] is marked
/// by vertical lines labelled e_min/e_max + `suffix` (e.g. '/√3' for the dual).
export function draw_histogram(canvas, hist, lo, hi, emin, emax, classes, suffix = '') {
  const fit = fit_canvas(canvas);
  if (!fit) return;
  const { ctx, w, h } = fit;
  const pad = { l: 8, r: 8, t: 4, b: 14 };
  const pw = w - pad.l - pad.r;
  const ph = h - pad.t - pad.b;
  const n = hist.inside.length;
  const total = (b) => hist.short[b] + hist.inside[b] + hist.long[b];
  let peak = 1;
  for (let b = 0; b < n; ++b) peak = Math.max(peak, total(b));
  const x = (v) => pad.l + ((v - lo) / (hi - lo || 1)) * pw;
  const bw = pw / n;
  const colour = { short: css('--short'), inside: css('--inside'), long: css('--long') };
  for (let b = 0; b < n; ++b) {
    const count = total(b);
    if (!count) continue;
    const bh = Math.sqrt(count / peak) * ph;  // sqrt scale: the tails stay visible
    let y = pad.t + ph;
    // Stacked from the base: short, inside, long, each its share of the bar.
    for (const cls of ['short', 'inside', 'long']) {
      const part = hist[cls][b];
      if (!part) continue;
      const ch = bh * part / count;
      ctx.fillStyle = classes ? colour[cls] : colour.inside;
      ctx.fillRect(pad.l + b * bw, y - ch, Math.max(1, bw - 1), ch);
      y -= ch;
    }
  }
  ctx.font = '10px system-ui, sans-serif';
  ctx.textBaseline = 'top';
  const ty = h - pad.b + 2;
  // e_min's label ends at its line and e_max's starts at its line, moved only to stay on the
  // canvas and apart; the axis ends are labelled only where they leave room.
  const labels = [];
  if (emax > emin && emin > 0) {
    for (const [v, name, before] of [[emin, 'e_min', true], [emax, 'e_max', false]]) {
      if (v < lo || v > hi) continue;
      const line = Math.round(x(v)) + 0.5;
      const text = `${name}${suffix} ${fmt(v)}`;
      const tw = ctx.measureText(text).width;
      const start = Math.min(Math.max(before ? line - 3 - tw : line + 3, 0), w - tw);
      labels.push({ line, text, start, end: start + tw });
    }
    if (labels.length === 2 && labels[1].start < labels[0].end + 6) {
      labels[1].start = labels[0].end + 6;
      labels[1].end = labels[1].start + ctx.measureText(labels[1].text).width;
    }
  }
  const free = (a, b) => labels.every((l) => b + 6 < l.start || a > l.end + 6);
  ctx.fillStyle = css('--muted');
  ctx.textAlign = 'left';
  const lo_text = fmt(lo);
  const hi_text = fmt(hi);
  const hi_start = w - pad.r - ctx.measureText(hi_text).width;
  if (free(pad.l, pad.l + ctx.measureText(lo_text).width)) ctx.fillText(lo_text, pad.l, ty);
  if (free(hi_start, w - pad.r)) ctx.fillText(hi_text, hi_start, ty);
  for (const l of labels) {
    ctx.strokeStyle = css('--text');
    ctx.setLineDash([3, 2]);
    ctx.beginPath(); ctx.moveTo(l.line, pad.t); ctx.lineTo(l.line, pad.t + ph); ctx.stroke();
    ctx.setLineDash([]);
    ctx.fillStyle = css('--text');
    ctx.fillText(l.text, l.start, ty);
  }
}
