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
  view.stop();
  if (location.hash) history.replaceState(null, '', location.pathname + location.search);
  reset_job_panel();
  $('file-name').textContent = `${file.name} · ${bytes(file.size)}`;
  $('summary').replaceChildren();
  $('repairs').replaceChildren();
  $('submit-status').textContent = '';
  for (const name of ['input', 'remeshed', 'dual']) state.viewer?.forget(name);
  set_available(['input']);
  $('show-input').checked = true;
  params.set_input_mean(NaN);
  state.input_of = null;
  state.watched = null;
  if (!['obj', 'off', 'ply', 'stl', 'gltf', 'glb'].includes(format_of(file.name))) {
    status(`".${format_of(file.name)}" is not a mesh format remeshd reads; the server will say more.`);
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
  const p = params.read_params();
  if (!state.file && view.job) {
    // Watching a job started elsewhere: run again on its (server-read) input, as GLB.
    try {
      const res = await api.request(api.result_url(view.job.id, 'input', 'glb'));
      const stem = (view.job.input?.filename || 'input').replace(/\.[^.]*$/, '');
      state.file = new File([await res.blob()], `${stem}.glb`, { type: 'model/gltf-binary' });
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
  } catch (err) {
    $('submit-status').textContent = '';
    if (err.status === 422 && err.fieldErrors.length) params.show_field_errors(err.fieldErrors);
    else if (err.status === 422) input_error(`The server could not use this mesh: ${err.message}`);
    else if (err.status === 413) input_error(`Too big for this server: ${err.message}`);
    else if (err.status === 503) $('submit-status').textContent = `Server busy (queue full): ${err.message}. Try again shortly.`;
    else if (err.status !== 401) $('submit-status').textContent = `Upload failed: ${err.message}`;
  } finally {
    button.disabled = false;
  }
}

function input_error(text) {
  const ul = $('repairs');
  ul.replaceChildren(Object.assign(document.createElement('li'), { className: 'err', textContent: text }));
  ul.querySelector('li').setAttribute('role', 'alert');
}

// ---- the watched job ----------------------------------------------------------------------------

const view = new JobView({
  on_job(job) {
    jobs.set_current(job.id);
    if (job.input?.summary) {
      show_summary(job.input.summary, `server summary of ${job.input.filename || 'the input'}` +
        (job.input.format ? ` (${job.input.format})` : ''));
      show_repairs(job.input.repairs);
      params.set_input_mean(job.input.summary.edge_length?.mean, 'server');
    }
    if (job.input?.filename)
      $('file-name').textContent = `${job.input.filename}${job.input.bytes ? ` · ${bytes(job.input.bytes)}` : ''}`;
    if (state.watched !== job.id) {
      state.watched = job.id;
      params.write_params(job.params);
      interval_changed();
    }
    if (state.input_of !== job.id) {
      state.input_of = job.id;
      load_mesh('input', job.id, true);
    }
  },
  on_end(job) {
    jobs.refresh();
    if (job.state !== 'succeeded') return;
    set_available(['input', 'remeshed', 'dual']);
    $('show-remeshed').checked = true;
    load_mesh('remeshed', job.id, true);
  },
});
const jobs = new JobsList();

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
  $('rows').tBodies[0].replaceChildren();
  view.rows = [];
  view.job = null;
  view.draw_rows();
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

/// Fetches mesh=`name` as GLB for the job and shows it if `show` (or if it is the selected one).
async function load_mesh(name, id, show) {
  const viewer = state.viewer;
  if (!viewer) return;
  const key = `${id}/${name}`;
  if (state.loading.has(key)) return state.loading.get(key);
  const task = (async () => {
    status(`loading ${name}…`);
    try {
      const res = await api.request(api.result_url(id, name === 'input' ? 'input' : name, 'glb'));
      const mesh = await in_worker({ glb: await res.arrayBuffer() });
      if (view.job?.id !== id) return;
      viewer.set_mesh(name, mesh, { classed: name !== 'dual',
        label: name === 'dual' ? 'dual (polygon edges)' : name });
      if (show || selected() === name) viewer.show(name);
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
    state.viewer = new Viewer($('view3d'), $('histogram'), $('view-status'), $('hist-caption'));
  } catch (e) {
    status(`3D view unavailable: ${e.message}`);
    return;
  }
  for (const radio of document.querySelectorAll('input[name=show]')) radio.addEventListener('change', () => {
    const name = selected();
    if (state.viewer.has(name)) state.viewer.show(name);
    else if (view.job) load_mesh(name, view.job.id, true);
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
window.__remeshd = { state, view, jobs };  // for the browser test and for debugging in the console
