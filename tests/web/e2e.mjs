// End-to-end test of the page: the real remeshd on a free loopback port with a temporary data
// directory, Debian's Chromium driven by playwright-core (never downloads a browser).
//
//   REMESHD=<build>/bin/remeshd WEB_ROOT=<build>/web ARTIFACTS=<build>/test-artifacts/web node tests/web/e2e.mjs
//
// Environment: REMESHD (the daemon; or REMESHD_URL = a server already running, for development),
// WEB_ROOT (passed as --web-root when the daemon has that option), ARTIFACTS (screenshots and
// downloads), CHROMIUM (default /usr/bin/chromium). Exits non-zero with one line per failed check.
import { spawn } from 'node:child_process';
import { createRequire } from 'node:module';
import fs from 'node:fs';
import net from 'node:net';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { drawn_fraction, changed_fraction } from './png.mjs';
import { icosphere_obj, parse_obj } from './meshes.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const web_dir = path.resolve(here, '../../web');
const { chromium } = createRequire(path.join(web_dir, 'package.json'))('playwright-core');
const artifacts = path.resolve(process.env.ARTIFACTS || path.join(os.tmpdir(), 'remeshd-web-artifacts'));
const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'remeshd-web-'));
fs.mkdirSync(artifacts, { recursive: true });
const started = Date.now();
const failures = [];
const log = (...a) => console.log(`[${((Date.now() - started) / 1000).toFixed(1)}s]`, ...a);
function check(ok, what) {
  log(ok ? 'ok  ' : 'FAIL', what);
  if (!ok) failures.push(what);
  return ok;
}

let server = null;
let browser = null;
let page = null;
async function main() {
  const base = process.env.REMESHD_URL || await start_server();
  log('server', base);
  const mesh_path = path.join(tmp, 'sphere.obj');
  fs.writeFileSync(mesh_path, icosphere_obj(2));
  const garbage_path = path.join(tmp, 'garbage.obj');
  fs.writeFileSync(garbage_path, 'this is not a mesh\nv 1 2\nf 1 2 9\n');

  browser = await chromium.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
      '--disable-background-networking', '--disable-component-update', '--disable-sync', '--no-first-run',
      '--disable-quic', '--disable-dev-shm-usage'],
  });
  const context = await browser.newContext({ viewport: { width: 1400, height: 1000 }, acceptDownloads: true });
  page = await context.newPage();
  const console_errors = [];
  // Chromium logs every 4xx answer as 'Failed to load resource'; the test provokes some on purpose.
  page.on('console', (m) => { if (m.type() === 'error' && !/Failed to load resource/.test(m.text())) console_errors.push(m.text()); });
  page.on('pageerror', (e) => console_errors.push(String(e)));
  const shot = (name) => page.screenshot({ path: path.join(artifacts, `${name}.png`), fullPage: true });

  await page.goto(base, { waitUntil: 'load' });
  await page.waitForFunction(() => window.__remeshd, null, { timeout: 60000 });  // modules and three.js loaded
  await page.waitForSelector('#health.ok', { timeout: 10000 });
  check(true, 'page loads and /healthz answers');

  // --- a small mesh: local preview and the interval helper ---
  await page.setInputFiles('#file', mesh_path);
  await page.waitForFunction(() => +document.getElementById('input-mean').dataset.value > 0, null, { timeout: 10000 });
  const mean = await page.$eval('#input-mean', (o) => +o.dataset.value);
  const filled = await page.evaluate(() => ({ emin: +document.getElementById('emin').value, emax: +document.getElementById('emax').value }));
  check(Math.abs(filled.emin - 0.8 * mean) < 0.01 * mean && Math.abs(filled.emax - 1.2 * mean) < 0.01 * mean,
    `helper fills e_min/e_max = mean ±20 % (mean ${mean}, got ${filled.emin}..${filled.emax})`);

  // --- a 422 field error from the server, shown next to its field ---
  await page.fill('#iterations', '100000000');
  await page.click('#submit');
  const iter_error = await page.waitForSelector('.err[data-for="iterations"]:not(:empty)', { timeout: 10000 })
    .then((e) => e.textContent()).catch(() => '');
  check(/iterations/.test(iter_error), `server's 422 for iterations shown beside the field ("${iter_error}")`);

  // --- a long job started over the API (as with curl) holds the only worker, so the page's job
  // waits in the queue with its event stream open and every row of it must arrive live ---
  const blocker = await api_post_job(base, icosphere_obj(4), { emin: 0.01, emax: 0.02, iterations: 1000, run_all_iterations: true });
  check(await wait_state(base, blocker, ['running']), `API job ${blocker} running`);

  // --- the page's job: refine to 0.6 x mean, 4 iterations, all of them ---
  await page.fill('#target', String(+(0.6 * mean).toPrecision(4)));
  await page.click('#apply-target');
  await page.fill('#iterations', '4');
  await page.check('#run_all_iterations');
  await page.click('#submit');
  await page.waitForFunction(() => /job=/.test(location.hash), null, { timeout: 10000 });
  const job_id = await page.evaluate(() => decodeURIComponent(/job=([^&]+)/.exec(location.hash)[1]));
  check(await page.waitForSelector('#summary dd', { timeout: 10000 }).then(() => true, () => false), 'input summary shown');
  const streaming = await page.waitForFunction(() => window.__remeshd.view.source?.readyState === 1, null, { timeout: 10000 })
    .then(() => true, () => false);
  check(streaming && (await page.textContent('#job-state')) === 'queued', 'queued job: state shown, event stream open');
  await page.click('#jobs-refresh');
  const blocker_row = await page.waitForSelector(`#jobs li[data-id="${blocker}"] .state.running`, { timeout: 10000 })
    .then(() => true, () => false);
  check(blocker_row, 'the API-started job is listed as running in the recent jobs');
  await shot('0-queued');
  const cancel = await fetch(`${base}/api/v1/jobs/${blocker}`, { method: 'DELETE' });
  check(cancel.status === 202, `API job cancelled (DELETE answered ${cancel.status})`);
  await page.waitForSelector('#job-state.succeeded, #job-state.failed, #job-state.cancelled', { timeout: 30000 });
  const final_state = await page.textContent('#job-state');
  check(final_state === 'succeeded', `job ${job_id} succeeded (state ${final_state})`);
  const api_rows = await (await fetch(`${base}/api/v1/jobs/${job_id}/stats?format=json`)).json();
  const rows = Array.isArray(api_rows) ? api_rows : api_rows.rows || [];
  const table_rows = await page.$$eval('#rows tbody tr', (trs) => trs.length);
  check(rows.length === 4 && table_rows === rows.length, `table holds every row (${table_rows} in page, ${rows.length} from /stats)`);
  const streamed = await page.evaluate(() => window.__remeshd.view.streamed);
  check(streamed === rows.length, `every row arrived live over the event stream (${streamed} of ${rows.length})`);
  check(await wait_state(base, blocker, ['cancelled']), 'the API job ended cancelled');
  await page.waitForFunction(() => /^seconds by step: stellar /.test(document.getElementById('progress-text').title), null, { timeout: 5000 }).catch(() => {});
  const steps_title = await page.getAttribute('#progress-text', 'title');
  check(/^seconds by step: stellar [\d.]+, flips [\d.]+, .*total [\d.]+$/.test(steps_title || ''), `time by step shown once succeeded (${steps_title})`);
  const dual_line = await page.textContent('#dual-summary');
  const job_doc = await (await fetch(`${base}/api/v1/jobs/${job_id}`)).json();
  check(job_doc.dual && dual_line.startsWith(`dual: ${job_doc.dual.atoms.toLocaleString('en-US')} atoms, ${job_doc.dual.bonds.toLocaleString('en-US')} bonds · rings `) &&
    / % inside \[[\d.]+, [\d.]+\] = \[emin, emax\] \/ √3 \([\d,]+ short, [\d,]+ long\)$/.test(dual_line),
    `the dual's atoms, rings and bonds shown once succeeded (${dual_line})`);
  const by = job_doc.thin_parts?.vertices;
  const progress_text = await page.textContent('#progress-text');
  const both = Boolean(by && by.thinner.vertices > 0 && by.thicker.vertices > 0);
  check(both === / % regular where the input is at least [\d.]+ thick, [\d.]+ % in thinner parts/.test(progress_text),
    `regular vertices by thickness shown exactly when the job document has both kinds (${JSON.stringify(by)})`);
  const summary_text = await page.textContent('#summary');
  check(/server summary/.test(summary_text) && /genus/.test(summary_text), 'server summary with genus replaces the local one');

  await page.waitForFunction(() => /^remeshed/.test(document.getElementById('view-status').textContent), null, { timeout: 15000 });
  await page.waitForTimeout(300);
  await shot('1-succeeded');
  const chart_png = await page.locator('#chart-length').screenshot();
  check(drawn_fraction(chart_png) > 0.01, `chart canvas draws (${(100 * drawn_fraction(chart_png)).toFixed(1)} % of pixels)`);
  const remeshed_png = await page.locator('#view3d').screenshot({ path: path.join(artifacts, '2-remeshed-3d.png') });
  const remeshed_drawn = drawn_fraction(remeshed_png);
  check(remeshed_drawn > 0.02, `3D canvas draws the remeshed mesh (${(100 * remeshed_drawn).toFixed(1)} % of pixels)`);
  const hist_png = await page.locator('#histogram').screenshot();
  check(drawn_fraction(hist_png) > 0.005, 'edge-length histogram draws');

  // --- the dual, drawn with its polygon edges ---
  await page.click('label[for="show-dual"]');
  await page.waitForFunction(() => /^dual/.test(document.getElementById('view-status').textContent), null, { timeout: 15000 });
  await page.waitForTimeout(300);
  const dual_png = await page.locator('#view3d').screenshot({ path: path.join(artifacts, '3-dual-3d.png') });
  check(drawn_fraction(dual_png) > 0.02 && changed_fraction(remeshed_png, dual_png) > 0.005,
    `3D canvas draws the dual, different from the remeshed (${(100 * changed_fraction(remeshed_png, dual_png)).toFixed(1)} % changed)`);

  // --- a download that parses ---
  const [download] = await Promise.all([page.waitForEvent('download', { timeout: 10000 }),
    page.click('#downloads button[aria-label="Download remeshed as obj"]')]);
  const obj_path = path.join(artifacts, 'remeshed.obj');
  await download.saveAs(obj_path);
  const obj = parse_obj(fs.readFileSync(obj_path, 'utf8'));
  const last = rows[rows.length - 1] || {};
  check(obj.error === '' && obj.vertices > 162 && obj.faces > 320,
    `remeshed.obj parses (${obj.vertices} v, ${obj.faces} f, refined from 162 v${obj.error ? `; ${obj.error}` : ''})`);
  check(obj.vertices - obj.edges + obj.faces === 2, `remeshed.obj is still a sphere (Euler ${obj.vertices - obj.edges + obj.faces})`);
  check(last.vertices === undefined || Math.abs(obj.vertices - last.vertices) <= 0.2 * last.vertices,
    `vertex count near the last row's (${obj.vertices} vs ${last.vertices})`);

  // --- a reload reconnects to the job and shows every row again ---
  await page.reload({ waitUntil: 'load' });
  await page.waitForFunction(() => window.__remeshd, null, { timeout: 60000 });
  await page.waitForFunction((n) => document.querySelectorAll('#rows tbody tr').length === n, rows.length, { timeout: 10000 })
    .catch(() => {});
  check(await page.$$eval('#rows tbody tr', (t) => t.length) === rows.length, 'after a reload the table holds every row again');
  const listed = await page.$$eval('#jobs li', (lis) => lis.map((li) => li.dataset.id));
  check(listed.includes(job_id), 'the job is in the recent-jobs list');

  // --- a lens (a sphere of radius 6 flattened to 3 across: thick in its middle, thin at its rim),
  // started over the API and opened by its address: the regular vertices by the input's thickness ---
  const lens = icosphere_obj(4).replace(/^v (\S+) (\S+) (\S+)$/gm, (_, x, y, z) => `v ${6 * x} ${6 * y} ${1.5 * z}`);
  const lens_id = await api_post_job(base, lens, { emin: 1.0, emax: 1.4 });
  check(await wait_state(base, lens_id, ['succeeded']), `lens job ${lens_id} succeeded`);
  await page.evaluate((id) => { location.hash = `job=${id}`; }, lens_id);
  const lens_shown = await page.waitForFunction(() => / % in thinner parts/.test(document.getElementById('progress-text').textContent),
    null, { timeout: 10000 }).then(() => true, () => false);
  const lens_by = (await (await fetch(`${base}/api/v1/jobs/${lens_id}`)).json()).thin_parts?.vertices;
  const lens_text = await page.textContent('#progress-text');
  const lens_share = (part) => (100 * part.regular / part.vertices).toFixed(1);
  check(lens_shown && lens_by && lens_text.includes(`${lens_share(lens_by.thicker)} % regular where the input is at least ` +
    `${lens_by.limit.toPrecision(3)} thick, ${lens_share(lens_by.thinner)} % in thinner parts`),
    `the lens's regular vertices by thickness shown as its job document has them (${JSON.stringify(lens_by)})`);

  // --- garbage: the server's reader message appears ---
  await page.setInputFiles('#file', garbage_path);
  await page.fill('#emin', '0.1');
  await page.fill('#emax', '0.2');
  await page.click('#submit');
  const bad = await page.waitForSelector('#repairs li.err', { timeout: 10000 }).then((e) => e.textContent()).catch(() => '');
  check(/could not use this mesh/.test(bad) && bad.length > 30, `garbage file refused with the reader's message ("${bad}")`);
  await shot('4-garbage');

  check(console_errors.length === 0, `no errors in the browser console${console_errors.length ? `: ${console_errors.join(' | ')}` : ''}`);
}

/// POSTs a job as multipart (what curl -F does); returns its id.
async function api_post_job(base, obj_text, params) {
  const form = new FormData();
  form.append('mesh', new Blob([obj_text]), 'api_sphere.obj');
  form.append('params', JSON.stringify(params));
  const res = await fetch(`${base}/api/v1/jobs`, { method: 'POST', body: form });
  if (res.status !== 202) throw new Error(`POST /jobs answered ${res.status}: ${await res.text()}`);
  return (await res.json()).id;
}

/// Polls the job until its state is one of `states` (true) or 20 s pass (false).
async function wait_state(base, id, states) {
  for (let i = 0; i < 200; ++i) {
    const job = await (await fetch(`${base}/api/v1/jobs/${id}`)).json();
    if (states.includes(job.state)) return true;
    await new Promise((r) => setTimeout(r, 100));
  }
  return false;
}

async function free_port() {
  return new Promise((resolve) => {
    const s = net.createServer().listen(0, '127.0.0.1', () => { const { port } = s.address(); s.close(() => resolve(port)); });
  });
}

async function start_server() {
  const bin = process.env.REMESHD;
  if (!bin) throw new Error('set REMESHD (the daemon) or REMESHD_URL');
  const port = await free_port();
  const args = ['--host', '127.0.0.1', '--port', String(port), '--data-dir', path.join(tmp, 'data'), '--workers', '1'];
  const help = await new Promise((resolve) => {
    const h = spawn(bin, ['--help']);
    let out = '';
    h.stdout.on('data', (d) => { out += d; });
    h.stderr.on('data', (d) => { out += d; });
    h.on('close', () => resolve(out));
    h.on('error', () => resolve(''));
  });
  if (process.env.WEB_ROOT && /--web-root/.test(help)) args.push('--web-root', process.env.WEB_ROOT);
  const log_file = fs.openSync(path.join(artifacts, 'remeshd.log'), 'w');
  server = spawn(bin, args, { stdio: ['ignore', log_file, log_file] });
  const url = `http://127.0.0.1:${port}`;
  for (let i = 0; i < 100; ++i) {
    if (server.exitCode !== null) throw new Error(`remeshd exited with ${server.exitCode} (see remeshd.log)`);
    try { if ((await fetch(`${url}/healthz`)).ok) return url; } catch { /* not up yet */ }
    await new Promise((r) => setTimeout(r, 100));
  }
  throw new Error('remeshd did not answer /healthz within 10 s');
}

try {
  await main();
} catch (e) {
  failures.push(e.stack || String(e));
  console.log('FAIL', e.stack || e);
  if (page) await page.screenshot({ path: path.join(artifacts, 'failure.png'), fullPage: true }).catch(() => {});
} finally {
  if (browser) await browser.close().catch(() => {});
  if (server) server.kill('SIGTERM');
  fs.rmSync(tmp, { recursive: true, force: true });
}
log(failures.length ? `${failures.length} check(s) failed` : 'all checks passed', `- artifacts in ${artifacts}`);
process.exit(failures.length ? 1 : 0);
