/// The page's wiring: token, input file (drop or picker), local preview, submission, the watched
/// job (#job=<id> in the URL), the 3D view's mesh switch and options, and the recent-jobs list.

import * as api from './api.js';
import * as params from './params.js';
import { format_of } from './preview.js';
import { length_stats } from './edges.js';
import { in_worker } from './mesh_loader.js';
import { JobView } from './job_view.js';
import { JobsList } from './jobs_list.js';
import { fmt } from './charts.js';

const $ = (id) => document.getElementById(id);
const state = { file: null, input_of: null, viewer: null, loading: new Map() };

// ---- banner, token, health -------------------------------------------------------------------

function banner(text) {
  const b = $('banner');
  b.textContent = text || '';
  b.hidden = !text;
}

function init_token() {
  $('token').value = api.token();
  $('token-form').addEventListener('submit', (e) => {
    e.preventDefault();
    api.set_token($('token').value.trim());
    banner('');
    jobs.refresh();
    const id = job_id_from_hash();
    if (id) watch(id);
  });
  api.set_unauthorized_handler(() => {
    banner(api.token()
      ? 'The server refused the API token (401). Check it in the "API token" field and press Save.'
      : 'This server requires an API token (401). Enter it in the "API token" field at the top and press Save.');
    $('token').focus();
  });
}

async function poll_health() {
  const el = $('health');
  try {
    const ok = await api.health();
    el.textContent = ok ? 'server up' : 'server unhealthy';
    el.className = `health ${ok ? 'ok' : 'bad'}`;
  } catch {
    el.textContent = 'server unreachable';
    el.className = 'health bad';
  }
  setTimeout(poll_health, 10000);
}

// ---- input --------------------------------------------------------------------------------------

function init_input() {
  const drop = $('drop');
  $('file').addEventListener('change', () => { if ($('file').files[0]) choose_file($('file').files[0]); });
  for (const type of ['dragenter', 'dragover']) drop.addEventListener(type, (e) => {
    e.preventDefault();
    drop.classList.add('over');
  });
  for (const type of ['dragleave', 'drop']) drop.addEventListener(type, () => drop.classList.remove('over'));
  drop.addEventListener('drop', (e) => {
    e.preventDefault();
    const file = e.dataTransfer.files[0];
    if (file) choose_file(file);
  });
  // Dropping anywhere else must not navigate away from the page.
  window.addEventListener('dragover', (e) => e.preventDefault());
  window.addEventListener('drop', (e) => {
    e.preventDefault();
    if (e.dataTransfer.files[0]) choose_file(e.dataTransfer.files[0]);
  });
}

/// A new input: preview it locally at once; the server's summary follows after the upload.
async function choose_file(file) {
  state.file = file;
  leave_job();
  $('file-name').textContent = `${file.name} · ${bytes(file.size)}`;
  $('submit-status').textContent = '';
  clear_file_error();  // the last file's complaint is not about this one
  set_available(['input']);
  $('show-input').checked = true;
  // The last input's target does not carry over ("Fill" gave an interval twice this file's mean);
  // the preview, if any, fills it and the interval from this file's mean.
  params.set_input_mean(NaN, '', { clear: true });
  if (!['obj', 'off', 'ply', 'stl', 'gltf', 'glb'].includes(format_of(file.name))) {
    // The server also reads the content (a mesh named .txt works), so this is no verdict yet.
    status(`".${format_of(file.name)}" is not an extension the preview knows, so there is no preview; ` +
      'the server will try to detect the format when you press Remesh.');
    return;
  }
  if (file.size > 200 * 1024 * 1024) { status('Large file: the preview appears after the upload.'); return; }
  status(`reading ${file.name}…`);
  try {
    const mesh = await in_worker({ file });
    await state.viewer_ready;
    if (state.file !== file) return;
    const stats = state.viewer ? state.viewer.set_mesh('input', mesh, { label: 'input (local preview)' })
      : length_stats(mesh.lengths);
    state.viewer?.show('input');
    show_summary({ vertices: mesh.positions.length / 3, faces: mesh.faces,
      edge_length: stats ? { mean: stats.mean } : undefined }, 'local preview; the server summary follows the upload');
    if (stats) params.set_input_mean(stats.mean, 'local preview', { fill: true });
    state.input_of = 'local';
  } catch (e) {
    status(`No local preview (${e.message}); the server reads it on upload.`);
  }
}

function show_summary(s, source) {
  const dl = $('summary');
  dl.replaceChildren();
  const add = (k, v) => {
    if (v === undefined || v === null || v === '') return;
    dl.append(Object.assign(document.createElement('dt'), { textContent: k }),
      Object.assign(document.createElement('dd'), { textContent: v }));
  };
  const n = (v) => (Number.isFinite(v) ? v.toLocaleString('en-US') : undefined);
  add('vertices', n(s.vertices));
  add('faces', n(s.faces));
  add('edges', n(s.edges));
  add('components', n(s.components));
  add('boundary loops', n(s.boundary_loops));
  if (Array.isArray(s.genus)) add('genus', s.genus.length ? s.genus.join(', ') : '– (no closed component)');
  add('euler', n(s.euler));
  if (s.edge_length) {
    add('mean edge', fmt(s.edge_length.mean));
    if (s.edge_length.min !== undefined) add('min / max edge', `${fmt(s.edge_length.min)} / ${fmt(s.edge_length.max)}`);
  }
  if (s.bbox) add('bbox diagonal', fmt(s.bbox.diagonal));
  add('area', Number.isFinite(s.area) ? fmt(s.area) : undefined);
  if (s.layered) add('crossing faces', 'not counted (too many faces overlap)');
  else add('crossing faces', Number.isFinite(s.crossing_pairs) ? `${n(s.crossing_pairs)} pairs` : undefined);
  dl.append(Object.assign(document.createElement('dd'), { className: 'src', textContent: source }));
}

function show_repairs(repairs) {
  const ul = $('repairs');
  ul.replaceChildren();
  for (const r of repairs || [])
    ul.append(Object.assign(document.createElement('li'), {
      textContent: `repaired: ${r.kind}${r.count ? ` ×${r.count}` : ''}${r.detail ? ` (${r.detail})` : ''}` }));
}

// ---- submission ---------------------------------------------------------------------------------

async function submit(e) {
  e.preventDefault();
  params.clear_field_errors();
  clear_file_error();
  const p = params.read_params();
  if (!state.file && view.job) {
    // Watching a job started elsewhere: run again on its (server-read) input, in its own format
    // where the server writes it (OBJ, OFF and PLY hold the coordinates exactly; glTF has float32,
    // as a glTF input had), so the new job keeps the input's name.
    const job = view.job;
    try {
      // The format the server read it as (a mesh named .txt is OBJ), else the name's extension.
      const name = job.input?.filename || 'input';
      const own = [job.input?.format, format_of(name)].find((f) => ['obj', 'off', 'ply', 'stl', 'glb', 'gltf'].includes(f));
      const format = own || 'glb';
      const res = await api.request(api.result_url(job.id, 'input', format));
      const blob = await res.blob();
      // Another job opened meanwhile: this press was for the one no longer shown. A file chosen
      // meanwhile is the one sent.
      if (view.job !== job) return;
      const stem = name.replace(/\.[^.]*$/, '');
      if (!state.file) state.file = new File([blob], format_of(name) === format ? name : `${stem}.${format}`);
    } catch (err) {
      $('submit-status').textContent = `Cannot fetch the job's input: ${err.message}`;
      return;
    }
  }
  if (!state.file) {
    $('submit-status').textContent = 'Choose a mesh file first.';
    $('file').focus();
    return;
  }
  const local = params.local_errors(p);
  if (local.length) { params.show_field_errors(local); return; }
  const button = $('submit');
  button.disabled = true;
  $('submit-status').textContent = 'uploading…';
  try {
    const job = await api.create_job(state.file, p, (f) => {
      $('submit-status').textContent = f < 1 ? `uploading ${Math.round(100 * f)} %` : 'reading on the server…';
    });
    $('submit-status').textContent = '';
    state.file_job = job.id;
    location.hash = `job=${encodeURIComponent(job.id)}`;  // hashchange starts watching
    jobs.refresh();  // the new job belongs in the list now, not at the next poll
    show_job_panel();
  } catch (err) {
    $('submit-status').textContent = '';
    const name = state.file?.name || 'the file';
    const size = /the result would have (about|over) (\d+) faces, more than the limit of (\d+)/.exec(err.message);
    if (err.status === 422 && err.fieldErrors.length) {
      // Complaints about the file go beside it (and by the button); the rest beside their fields.
      const about_file = err.fieldErrors.filter((f) => FILE_FIELDS.includes(f.field));
      const others = err.fieldErrors.filter((f) => !FILE_FIELDS.includes(f.field));
      if (others.length) params.show_field_errors(others);
      if (about_file.length)
        file_error(about_file.map((f) => f.field === 'mesh' ? `The file ${name} ${f.message}.` : `The file ${name}: ${f.field} ${f.message}.`)
          .join(' ') + ' Choose another file.', { focus: !others.length });
    } else if (err.status === 422) file_error(`The server could not read ${name}: ${err.message}. Fix the file or choose another one.`);
    else if (err.status === 413 && size) {
      // "over" N: the estimate at its cap (1e18), a bound and no count to show.
      const faces = size[1] === 'over' ? 'more faces than' : `about ${readable(+size[2])} faces, more than`;
      params.show_field_errors([{ field: 'emin', text: `e_min and e_max are so small that the result would have ${faces} ` +
        `this server's limit of ${readable(+size[3])}. Use a larger e_min and e_max.` }],
      { also: ['emax'] });
    } else if (err.status === 413)
      file_error(`${name} is too large for this server: ${readable_numbers(err.message)}. Choose a smaller mesh.`);
    else if (err.status === 503) $('submit-status').textContent = `Server busy: ${err.message}.`;
    else if (err.status !== 401) $('submit-status').textContent = `Upload failed: ${err.message}`;
  } finally {
    button.disabled = false;
  }
}

/// On one column (phones, narrow windows) the job panel lies below the form and the job list: it is
/// brought into view when a job starts (at 390 px a tap on Remesh changed nothing on screen, and
/// the job ran unseen 1 200 px further down).
function show_job_panel() {
  if (!matchMedia('(max-width: 860px)').matches) return;  // two columns: the panel is beside the form
  const panel = document.querySelector('section.job');
  const r = panel.getBoundingClientRect();
  if (r.top < 0 || r.top > 0.5 * innerHeight) panel.scrollIntoView({ block: 'start', behavior: 'smooth' });
}

/// The request fields that are about the uploaded file rather than a parameter.
const FILE_FIELDS = ['mesh', 'format'];

/// A complaint about the input file: beside the file chooser, where it belongs, and in the line by
/// the Remesh button, where the user is looking after pressing it (focus moves there).
function file_error(text, { focus = true } = {}) {
  $('file-error').textContent = text;
  $('form-error').textContent = text;
  if (focus) $('form-error').focus();
}

function clear_file_error() {
  $('file-error').textContent = '';
  $('form-error').textContent = '';
}

/// 58602528135 -> "58.6 billion", 5000000 -> "5 million", 12345 -> "12,345".
function readable(n) {
  if (n >= 1e12) return `${+(n / 1e12).toPrecision(3)} trillion`;
  if (n >= 1e9) return `${+(n / 1e9).toPrecision(3)} billion`;
  if (n >= 1e6) return `${+(n / 1e6).toPrecision(3)} million`;
  return n.toLocaleString('en-US');
}
function readable_numbers(text) { return String(text).replace(/\b\d{5,}\b/g, (d) => readable(+d)); }

// ---- the watched job ----------------------------------------------------------------------------

const view = new JobView({
  on_job(job) {
    jobs.set_current(job.id);
    const first = state.watched !== job.id;
    if (job.input?.summary) {
      show_summary(job.input.summary, `server summary of ${job.input.filename || 'the input'}` +
        (job.input.format ? ` (${job.input.format})` : ''));
      show_repairs(job.input.repairs);
      // A job opened from the list is another input: its mean becomes the target (the interval
      // stays the job's own, written below).
      params.set_input_mean(job.input.summary.edge_length?.mean, 'server',
        { target: first && job.id !== state.file_job });
    }
    if (job.input?.filename)
      $('file-name').textContent = `${job.input.filename}${job.input.bytes ? ` · ${bytes(job.input.bytes)}` : ''}`;
    if (first) {
      state.watched = job.id;
      params.write_params(job.params);
      interval_changed();
    }
    if (state.input_of !== job.id) {
      state.input_of = job.id;
      load_mesh('input', job.id);
    }
    // Queued, running, ended: the recent-jobs list shows the change now, not at its next poll.
    const seen = `${job.id} ${job.state}`;
    if (state.job_state !== seen) {
      state.job_state = seen;
      jobs.refresh();
    }
  },
  on_progress(job, done, total) { jobs.set_progress(job.id, done, total); },
  on_end(job) {
    if (job.state !== 'succeeded') return;
    set_available(['input', 'remeshed', 'dual']);
    $('show-remeshed').checked = true;
    load_mesh('remeshed', job.id);
  },
});
const jobs = new JobsList({ on_deleted: forget_job });

/// The watched job was deleted (from the recent-jobs list): its panel, meshes and address go, so
/// that no download or view points at files that are gone ("no job with id ...").
function forget_job(id) {
  if (view.job?.id !== id && state.watched !== id) return;
  leave_job();
  $('job-state').textContent = 'deleted';
  state.job_state = null;
  if (state.file_job === id) state.file_job = null;
  set_available([]);
  if (!state.file) {
    $('file-name').textContent = '';
    params.set_input_mean(NaN, '', { clear: true });
  }
  status(state.file ? `The job was deleted with its files; Remesh uploads ${state.file.name} again.`
    : 'The job was deleted with its files. Drop a mesh to start.');
  jobs.set_current('');
}

/// Stops watching the job shown (a new file chosen, or the job deleted): its stream, panel, address,
/// input summary and meshes go.
function leave_job() {
  view.stop();
  if (location.hash) history.replaceState(null, '', location.pathname + location.search);
  reset_job_panel();
  $('summary').replaceChildren();
  $('repairs').replaceChildren();
  for (const name of ['input', 'remeshed', 'dual']) state.viewer?.forget(name);
  state.input_of = null;
  state.watched = null;
}

function reset_job_panel() {
  document.title = 'remeshd';
  $('job-id').textContent = '–';
  $('job-state').textContent = 'idle';
  $('job-state').className = 'state';
  $('progress-text').textContent = '';
  $('progress').value = 0;
  $('cancel').disabled = true;
  $('job-error').textContent = '';
  $('downloads').replaceChildren();
  $('dual-summary').textContent = '';
  view.clear_rows();
  view.job = null;
}

function job_id_from_hash() {
  const m = /job=([^&]+)/.exec(location.hash);
  return m ? decodeURIComponent(m[1]) : '';
}

function watch(id) {
  state.watched = null;
  if (id !== state.file_job) state.file = null;  // "Remesh" now re-runs this job's input
  for (const name of ['remeshed', 'dual']) state.viewer?.forget(name);
  set_available(['input']);
  $('show-input').checked = true;
  view.watch(id);
}

// ---- the 3D view --------------------------------------------------------------------------------

function status(text) { $('view-status').textContent = text; }

function set_available(names) {
  for (const name of ['input', 'remeshed', 'dual']) $(`show-${name}`).disabled = !names.includes(name);
}

/// Fetches mesh=`name` as GLB for the job and shows it if it is the selected one. Loads overlap (the
/// input and the remeshed of a finished job): whichever finishes last must not replace the
/// selected one, so the radio alone decides what is shown.
async function load_mesh(name, id) {
  const viewer = state.viewer;
  if (!viewer) return;
  const key = `${id}/${name}`;
  if (state.loading.has(key)) return state.loading.get(key);
  const task = (async () => {
    if (selected() === name) status(`loading ${name}…`);  // else the status stays the shown mesh's
    try {
      const res = await api.request(api.result_url(id, name === 'input' ? 'input' : name, 'glb'));
      const mesh = await in_worker({ glb: await res.arrayBuffer() });
      if (view.job?.id !== id) return;
      // The dual's bonds are judged against [e_min, e_max] / √3 (the job's dual.bond_interval).
      viewer.set_mesh(name, mesh, { scale: name === 'dual' ? 1 / Math.sqrt(3) : 1,
        label: name === 'dual' ? 'dual (polygon edges)' : name });
      if (selected() === name) viewer.show(name);
    } catch (e) {
      status(`Could not load the ${name} mesh: ${e.message}`);
    } finally {
      state.loading.delete(key);
    }
  })();
  state.loading.set(key, task);
  return task;
}

function selected() { return document.querySelector('input[name=show]:checked')?.value; }

async function init_viewer() {
  try {
    const { Viewer } = await import('./viewer.js');
    state.viewer = new Viewer($('view3d'), $('histogram'), $('view-status'), $('hist-caption'), $('legend'));
  } catch (e) {
    status(`3D view unavailable: ${e.message}`);
    return;
  }
  for (const radio of document.querySelectorAll('input[name=show]')) radio.addEventListener('change', () => {
    const name = selected();
    if (state.viewer.has(name)) state.viewer.show(name);
    else if (view.job) load_mesh(name, view.job.id);
  });
  const options = () => state.viewer.set_options({ surface: $('opt-surface').checked,
    edges: $('opt-edges').checked, classes: $('opt-classes').checked });
  for (const id of ['opt-surface', 'opt-edges', 'opt-classes']) $(id).addEventListener('change', options);
  $('fit').addEventListener('click', () => state.viewer.fit());
  window.addEventListener('keydown', (e) => {
    if (e.target.closest('input, textarea, select')) return;
    if (e.key === 'f') state.viewer.fit();
  });
  interval_changed();
}

function interval_changed() {
  const { emin, emax } = params.interval();
  state.viewer?.set_interval(emin, emax);
  view.draw_rows();
}

function bytes(n) {
  if (n >= 1 << 20) return `${(n / (1 << 20)).toFixed(1)} MiB`;
  if (n >= 1 << 10) return `${(n / (1 << 10)).toFixed(1)} KiB`;
  return `${n} B`;
}

// ---- start ---------------------------------------------------------------------------------------

init_token();
init_input();
params.init_helper(interval_changed);
$('params').addEventListener('submit', submit);
window.addEventListener('hashchange', () => { const id = job_id_from_hash(); if (id) watch(id); });
poll_health();
jobs.refresh();
state.viewer_ready = init_viewer();
await state.viewer_ready;
const initial = job_id_from_hash();
if (initial) watch(initial);
window.__remeshd = { state, view, jobs, api };  // for the browser test and for debugging in the console
