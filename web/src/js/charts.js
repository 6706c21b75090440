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
      ctx.fillStyle = css(m.color);
      ctx.textAlign = 'left';
      ctx.textBaseline = 'bottom';
      ctx.fillText(m.label, pad.l + 3, yy - 1);
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

/// Draws a histogram: counts (Uint32Array) over [lo, hi]; bars coloured by class with respect to
/// [emin, emax] when `classes`, and the interval marked by vertical lines.
export function draw_histogram(canvas, counts, lo, hi, emin, emax, classes) {
  const fit = fit_canvas(canvas);
  if (!fit) return;
  const { ctx, w, h } = fit;
  const pad = { l: 8, r: 8, t: 4, b: 14 };
  const pw = w - pad.l - pad.r;
  const ph = h - pad.t - pad.b;
  const peak = Math.max(1, ...counts);
  const x = (v) => pad.l + ((v - lo) / (hi - lo || 1)) * pw;
  const bw = pw / counts.length;
  const interval = classes && emax > emin && emin > 0;
  for (let b = 0; b < counts.length; ++b) {
    const centre = lo + ((b + 0.5) / counts.length) * (hi - lo);
    ctx.fillStyle = css(!interval ? '--inside' : centre < emin ? '--short' : centre > emax ? '--long' : '--inside');
    const bh = Math.sqrt(counts[b] / peak) * ph; // sqrt scale: the tails stay visible
    ctx.fillRect(pad.l + b * bw, pad.t + ph - bh, Math.max(1, bw - 1), bh);
  }
  ctx.font = '10px system-ui, sans-serif';
  ctx.fillStyle = css('--muted');
  ctx.textBaseline = 'top';
  ctx.textAlign = 'left';
  ctx.fillText(fmt(lo), pad.l, h - pad.b + 2);
  ctx.textAlign = 'right';
  ctx.fillText(fmt(hi), w - pad.r, h - pad.b + 2);
  if (!(emax > emin && emin > 0)) return;
  for (const [v, label] of [[emin, 'e_min'], [emax, 'e_max']]) {
    if (v < lo || v > hi) continue;
    const xx = Math.round(x(v)) + 0.5;
    ctx.strokeStyle = css('--text');
    ctx.setLineDash([3, 2]);
    ctx.beginPath(); ctx.moveTo(xx, pad.t); ctx.lineTo(xx, pad.t + ph); ctx.stroke();
    ctx.setLineDash([]);
    ctx.fillStyle = css('--text');
    ctx.textAlign = 'center';
    ctx.fillText(`${label} ${fmt(v)}`, xx, h - pad.b + 2);
  }
}
