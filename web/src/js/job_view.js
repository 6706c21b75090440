/// Watching one job: its document, every statistics row (GET /stats first, then the event stream
/// from the last row held, so a reload misses nothing), the progress line, the charts, the table
/// and the download buttons.

import * as api from './api.js';
import { IterationChart } from './charts.js';

const $ = (id) => document.getElementById(id);
export const FINAL = new Set(['succeeded', 'failed', 'cancelled']);
const RESULT_FORMATS = {
  remeshed: ['obj', 'glb', 'gltf', 'ply', 'off', 'stl', 'lammps'],
  dual: ['obj', 'glb', 'gltf', 'ply', 'off', 'xyz', 'lammps'],
};
const TABLE = [
  ['iteration', (v) => v], ['vertices', int], ['edges', int], ['mean', num], ['deviation', num],
  ['regular_percent', (v) => fixed(v, 1)], ['small', int], ['big', int],
  ['inside_fraction', (v) => fixed(100 * v, 1)], ['splits', int], ['collapses', int], ['flips', int],
  ['seconds', (v) => fixed(v, 3)], ['max_projection_distance', num]];

/// The steps of seconds_by_step in the order of a run (the JSON object's keys come sorted).
const STEPS = ['stellar', 'flips', 'filter', 'projection', 'guards', 'cleanup', 'snap', 'untangle', 'setup', 'other',
  'total'];

/// Within a few pixels of the bottom of the scrolled element.
function at_bottom(el) { return el.scrollHeight - el.scrollTop - el.clientHeight < 24; }

function int(v) { return Number.isFinite(v) ? v.toLocaleString('en-US') : '–'; }
function num(v) { return Number.isFinite(v) ? String(+v.toPrecision(5)) : '–'; }
function fixed(v, d) { return Number.isFinite(v) ? v.toFixed(d) : '–'; }

/// The result's dual as an atom lattice (the job's `dual`), one line; '' before it exists.
/// "dual: 12,704 atoms, 19,056 bonds · rings 344 × 5, 5,680 × 6, 328 × 7 · bond length 0.875 ± 0.0613
/// (0.524 to 1.21) · 99.3 % inside [0.693, 1.04] = [emin, emax] / √3 (36 short, 106 long)"
export function dual_text(d) {
  if (!d) return '';
  const rings = Object.entries(d.rings || {}).map(([sides, n]) => `${int(n)} × ${sides}`).join(', ');
  const b = d.bond_length || {};
  // Three significant digits; a missing length shows as '–', not NaN.
  const p = (x) => (x == null || !Number.isFinite(Number(x)) ? '–' : String(+Number(x).toPrecision(3)));
  let text = `dual: ${int(d.atoms)} atoms, ${int(d.bonds)} bonds · rings ${rings || 'none'} · bond length ${p(b.mean)} ± ${p(b.deviation)} (${p(b.min)} to ${p(b.max)})`;
  const [lo, hi] = d.bond_interval || [0, 0];
  if (hi > 0)
    text += ` · ${fixed(100 * d.bonds_inside_fraction, 1)} % inside [${p(lo)}, ${p(hi)}] = [emin, emax] / √3 (${int(d.short_bonds)} short, ${int(d.long_bonds)} long)`;
  return text;
}

export class JobView {
  /// hooks: on_job(job) after every document refresh, on_end(job) once when the job is final,
  /// on_progress(job, done, total) whenever the progress line is drawn (rows as they arrive).
  constructor(hooks) {
    this.hooks = hooks;
    this.job = null;
    this.rows = [];
    this.source = null;
    this.retry = null;
    this.generation = 0;
    this.refreshes = 0;
    const params = () => this.job?.params || {};
    this.charts = [
      new IterationChart($('chart-length'), [
        { key: (r) => r.mean, label: 'mean', color: '--accent' },
        { key: (r) => r.deviation, label: 'deviation', color: '--warn' }],
      { marks: () => [{ value: params().emin, label: 'e_min', color: '--short' },
        { value: params().emax, label: 'e_max', color: '--long' }] }),
      new IterationChart($('chart-out'), [
        // The 3D view's and histogram's colours: short (< e_min) and long (> e_max); the total neutral.
        { key: (r) => r.small + r.big, label: 'outside', color: '--text' },
        { key: (r) => r.small, label: 'small', color: '--short' },
        { key: (r) => r.big, label: 'big', color: '--long' }]),
      new IterationChart($('chart-vertices'), [{ key: (r) => r.vertices, label: 'vertices', color: '--accent' }],
        { min_zero: false }),
      new IterationChart($('chart-regular'), [{ key: (r) => r.regular_percent, label: 'regular %', color: '--ok' }],
        { percent: true }),
      new IterationChart($('chart-seconds'), [{ key: (r) => r.seconds, label: 'seconds', color: '--accent', bars: true }]),
    ];
    this.queued = [];       // rows held but not yet in the table (drawn once per animation frame)
    this.frame = 0;         // the pending requestAnimationFrame, 0 = none
    this.follow = true;     // the table scrolls to the newest row while the user is at its bottom
    this.batches = 0;       // table renders so far (the browser test checks rows arrive in batches)
    const wrap = $('rows').closest('.tablewrap');
    // Growing content fires no scroll event, so `follow` changes only when the user (or our own
    // scroll to the bottom) moves the table; a reload starts at the top with follow still on.
    wrap.addEventListener('scroll', () => { this.follow = at_bottom(wrap); });
    $('cancel').addEventListener('click', () => this.cancel());
  }

  /// Starts watching job `id` (stops watching the previous one).
  async watch(id) {
    this.stop();
    const generation = ++this.generation;
    this.ended_id = null;
    this.streamed = 0;  // rows that arrived over the event stream (the rest came from /stats)
    this.clear_rows();
    $('job-id').textContent = id;
    $('job-error').textContent = '';
    $('dual-summary').textContent = '';  // the last job's, until this one's document arrives
    try {
      const job = await api.get_job(id);
      // Stopped meanwhile (a file chosen, the job deleted, another watched): this document is stale.
      if (generation !== this.generation) return;
      this.set_job(job);
      const rows = await api.get_stats(id);
      if (generation !== this.generation) return;
      this.add_rows(rows);
    } catch (e) {
      if (generation !== this.generation) return;
      if (e.status === 404) { this.show_error(`Job ${id} does not exist (it may have expired).`); return; }
      this.show_error(e.message);
      if (e.status !== 401) this.retry = setTimeout(() => this.watch(id), 3000);
      return;
    }
    if (FINAL.has(this.job.state)) { this.finish(); return; }
    this.open_stream(generation);
  }

  open_stream(generation) {
    const id = this.job.id;
    const last = this.rows.length ? this.rows[this.rows.length - 1].iteration : 0;
    const es = api.events(id, last);
    this.source = es;
    es.addEventListener('iteration', (e) => { this.streamed += this.add_rows([JSON.parse(e.data)]); });
    es.addEventListener('state', (e) => {
      const { state } = JSON.parse(e.data);
      if (this.job && state) { this.job.state = state; this.render_head(); }
      this.refresh(generation);
    });
    es.addEventListener('end', () => { es.close(); this.refresh(generation, true); });
    es.onerror = () => {
      // EventSource retries by itself (with Last-Event-ID) unless the server refused the stream.
      if (es.readyState !== EventSource.CLOSED || generation !== this.generation) return;
      this.source = null;
      this.retry = setTimeout(() => this.resume(generation), 2000);
    };
  }

  /// After a refused or broken stream: catch up through /stats, then stream again.
  async resume(generation) {
    if (generation !== this.generation || !this.job) return;
    try {
      this.set_job(await api.get_job(this.job.id));
      this.add_rows(await api.get_stats(this.job.id));
      if (FINAL.has(this.job.state)) this.finish(); else this.open_stream(generation);
    } catch (e) {
      this.show_error(`Lost the connection to the job: ${e.message}. Retrying…`);
      if (e.status !== 401 && e.status !== 404) this.retry = setTimeout(() => this.resume(generation), 3000);
    }
  }

  async refresh(generation, ended = false) {
    // Refreshes overlap (a 'state' event each): an answer overtaken by a later request is dropped
    // unless the job had ended by then, so an answer sent while the job was running cannot land
    // after the one that says it succeeded (seen in the e2e test under load: 'running' shown last).
    const request = ++this.refreshes;
    try {
      const job = await api.get_job(this.job.id);
      if (generation !== this.generation) return;
      if (request !== this.refreshes && !FINAL.has(job.state)) return;
      this.set_job(job);
      if (ended || FINAL.has(job.state)) {
        this.add_rows(await api.get_stats(job.id));  // rows sent just before the end, if any raced
        this.finish();
      }
    } catch (e) { this.show_error(e.message); }
  }

  stop() {
    ++this.generation;
    if (this.source) this.source.close();
    this.source = null;
    clearTimeout(this.retry);
  }

  finish() {
    if (this.source) { this.source.close(); this.source = null; }
    if (this.ended_id === this.job.id) return;
    this.ended_id = this.job.id;
    this.hooks.on_end(this.job);
  }

  set_job(job) {
    // A job that ended stays ended: an older document of it (a slow answer) is not applied.
    if (this.job && job.id === this.job.id && FINAL.has(this.job.state) && !FINAL.has(job.state)) return;
    this.job = job;
    this.render_head();
    this.render_downloads();
    this.hooks.on_job(job);
    for (const c of this.charts) c.schedule();
  }

  /// Forgets every row (a new job, or none) and empties the table.
  clear_rows() {
    this.rows = [];
    this.queued = [];
    cancelAnimationFrame(this.frame);
    this.frame = 0;
    this.follow = true;
    $('rows').tBodies[0].replaceChildren();
    this.draw_rows();
  }

  /// Takes rows newer than the last one held; returns how many were new. The table, the charts and
  /// the head follow once per animation frame: a fast job's stream delivers hundreds of rows in one
  /// network chunk, and a table row, a layout read and the head per row froze the page for seconds.
  add_rows(rows) {
    let last = this.rows.length ? this.rows[this.rows.length - 1].iteration : -Infinity;
    let fresh = 0;
    for (const row of rows) {
      if (!(row.iteration > last)) continue;  // a row seen already (reconnect overlap)
      last = row.iteration;
      this.rows.push(row);
      this.queued.push(row);
      ++fresh;
    }
    if (fresh && !this.frame) this.frame = requestAnimationFrame(() => this.render_rows());
    return fresh;
  }

  /// Appends the queued rows to the table in one go, then the charts and the head.
  render_rows() {
    this.frame = 0;
    const rows = this.queued;
    this.queued = [];
    if (!rows.length) return;
    const body = $('rows').tBodies[0];
    const batch = document.createDocumentFragment();
    for (const row of rows) {
      const tr = document.createElement('tr');
      for (const [key, f] of TABLE) {
        const td = document.createElement('td');
        td.textContent = f(row[key]);
        tr.append(td);
      }
      batch.append(tr);
    }
    body.append(batch);
    ++this.batches;
    if (this.follow) {
      const wrap = body.closest('.tablewrap');
      wrap.scrollTop = wrap.scrollHeight;  // the one layout read of the batch
    }
    this.draw_rows();
    if (this.job) this.render_head();
  }

  draw_rows() { for (const c of this.charts) c.set_rows(this.rows); }

  render_head() {
    const job = this.job;
    const state = $('job-state');
    state.textContent = job.state;
    state.className = `state ${job.state}`;
    const total = job.params?.iterations || job.progress?.iterations || 0;
    const done = Math.max(job.progress?.iteration || 0, this.rows.length ? this.rows[this.rows.length - 1].iteration : 0);
    const bar = $('progress');
    bar.max = Math.max(total, 1);
    bar.value = job.state === 'succeeded' ? bar.max : Math.min(done, bar.max);
    this.hooks.on_progress?.(job, done, total);
    let text = `iteration ${done} of ${total}`;
    if (job.state === 'succeeded' && done < total) text += ' (stopped early)';
    if (job.outcome) text += ` · ${typeof job.outcome === 'string' ? job.outcome : JSON.stringify(job.outcome)}`;
    const thin = job.thin_parts;
    if (thin && thin.outside > 0)
      text += ` · ${thin.outside} edges outside, ${thin.in_thin_parts} of them where the input is thinner than ${thin.limit.toPrecision(3)}` +
        (thin.at_irregular_vertices !== undefined ? `, ${thin.at_irregular_vertices} at vertices of valence other than 6` : '') +
        (thin.at_kept_creases ? `, ${thin.at_kept_creases} at kept creases` : '');
    // Regular vertices where the input is thick and in its thin parts (a tube a few edges round
    // needs a 5-7 pair wherever it widens or narrows), when the result has both.
    const by = thin?.vertices;
    if (by && by.thinner.vertices > 0 && by.thicker.vertices > 0) {
      const share = (part) => (100 * part.regular / part.vertices).toFixed(1);
      text += ` · ${share(by.thicker)} % regular where the input is at least ${by.limit.toPrecision(3)} thick, ` +
        `${share(by.thinner)} % in thinner parts`;
    }
    if (job.layered)
      text += ' · the surface lies over itself throughout, as a part duplicated in place does: ' +
        'crossing faces not counted';
    else if (job.crossing_pairs > 0) text += ` · ${job.crossing_pairs} pairs of faces crossing each other`;
    const tri = job.triangles;
    if (tri && tri.faces > 0)
      text += ` · angles ${tri.min_angle.toFixed(1)}° to ${tri.max_angle.toFixed(1)}°, ` +
        `${(100 * tri.below_30).toFixed(2)} % of triangles with one under 30°`;
    // How far the result lies from the input (both sides' largest), against the input's size.
    const far = job.distance_to_input;
    if (far && Number.isFinite(far.hausdorff))
      text += ` · within ${+far.hausdorff.toPrecision(3)} of the input (${+(100 * far.relative).toPrecision(2)} % of its diagonal)`;
    const secs = this.rows.reduce((s, r) => s + (r.seconds || 0), 0);
    if (secs) text += ` · ${secs.toFixed(1)} s`;
    $('progress-text').textContent = text;
    // Where the time went, once succeeded (seconds_by_step), as the line's tooltip, in the run's order.
    const steps = job.seconds_by_step;
    $('progress-text').title = steps
      ? `seconds by step: ${STEPS.filter((k) => k in steps).map((k) => `${k} ${Number(steps[k]).toFixed(3)}`).join(', ')}`
      : '';
    $('dual-summary').textContent = dual_text(job.dual);
    document.title = `${FINAL.has(job.state) ? job.state : `${done}/${total}`} · ${job.input?.filename || 'job'} · remeshd`;
    $('cancel').disabled = !(job.state === 'queued' || job.state === 'running');
    if (job.error) this.show_error(typeof job.error === 'string' ? job.error : job.error.detail || JSON.stringify(job.error));
  }

  render_downloads() {
    const job = this.job;
    const box = $('downloads');
    box.replaceChildren();
    const base = (job.input?.filename || 'mesh').replace(/\.[^.]*$/, '');
    const group = (label, items) => {
      const g = document.createElement('div');
      g.className = 'grp';
      g.setAttribute('role', 'group');
      g.setAttribute('aria-label', `Download ${label}`);
      const s = document.createElement('span');
      s.textContent = label;
      g.append(s);
      for (const [text, url, name] of items) {
        const b = document.createElement('button');
        b.type = 'button';
        b.textContent = text;
        b.title = url;
        b.dataset.url = url;
        b.setAttribute('aria-label', `Download ${label} as ${text}`);
        b.addEventListener('click', () => api.download(url, name).catch((e) => this.show_error(e.message)));
        g.append(b);
      }
      box.append(g);
    };
    if (job.state === 'succeeded') {
      // Not the files the formats cannot hold (float32 STL, GLB and glTF of a mesh past 3.4e38): the
      // server names them, and a download of one is refused. Text glTF stores float32 as GLB does.
      const unwritable = new Set(job.unwritable || []);
      const cannot = (mesh, f) => unwritable.has(`${mesh}.${f}`) || (f === 'gltf' && unwritable.has(`${mesh}.glb`));
      for (const mesh of ['remeshed', 'dual'])
        group(mesh, RESULT_FORMATS[mesh].filter((f) => !cannot(mesh, f))
          .map((f) => [f, api.result_url(job.id, mesh, f), `${base}_${mesh}.${f}`]));
    }
    group('statistics', [['csv', api.stats_csv_url(job.id), `${base}_stats.csv`]]);
  }

  async cancel() {
    if (!this.job) return;
    $('cancel').disabled = true;
    try {
      await api.delete_job(this.job.id);
      this.refresh(this.generation);
    } catch (e) { this.show_error(`Cancel failed: ${e.message}`); }
  }

  show_error(text) { $('job-error').textContent = text; }
}
