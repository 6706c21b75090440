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
import { decode_png, drawn_fraction, changed_fraction } from './png.mjs';
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

  // --- the helper names the wrong field instead of using a default (± % = 0 used to mean 20 %) ---
  await page.fill('#tolerance', '0');
  await page.click('#apply-target');
  const helper_error = await page.textContent('#helper-error');
  const kept = +(await page.inputValue('#emin'));
  check(/^± % must be/.test(helper_error) && await page.getAttribute('#tolerance', 'aria-invalid') === 'true' &&
    await page.getAttribute('#target', 'aria-invalid') === null && kept === filled.emin,
    `helper refuses ± % = 0 beside that field and leaves e_min alone ("${helper_error}")`);
  await page.fill('#tolerance', '20');
  check(await page.textContent('#helper-error') === '', 'editing ± % clears its message');

  // --- a target bond of the dual: edges √3 times as long, the bond interval shown ---
  const edge_target = +(await page.inputValue('#target'));
  await page.selectOption('#target-of', 'bond');
  const as_bond = { emin: +(await page.inputValue('#emin')), emax: +(await page.inputValue('#emax')) };
  const bonds_shown = await page.textContent('#bond-interval');
  const bond_lo = +(0.8 * edge_target).toPrecision(4), bond_hi = +(1.2 * edge_target).toPrecision(4);
  check(Math.abs(as_bond.emin - 0.8 * Math.sqrt(3) * edge_target) < 1e-3 * as_bond.emin &&
    Math.abs(as_bond.emax - 1.2 * Math.sqrt(3) * edge_target) < 1e-3 * as_bond.emax &&
    bonds_shown === `[${bond_lo}, ${bond_hi}]`,
    `a target bond b fills e_min/e_max = b √3 ±20 % and shows the bonds (b ${edge_target}: ${as_bond.emin}..${as_bond.emax}, "${bonds_shown}")`);
  await page.selectOption('#target-of', 'edge');
  check(+(await page.inputValue('#emin')) === filled.emin && +(await page.inputValue('#emax')) === filled.emax,
    'back to a target edge, the interval is the edge one again');

  // --- a decimal comma typed into a number field is a point (Chromium read "0,5" as 5) ---
  const target_before = await page.inputValue('#target');
  await page.fill('#target', '');
  await page.type('#target', '0,5');
  const typed = await page.$eval('#target', (i) => [i.value, i.valueAsNumber]);
  check(typed[0] === '0.5' && typed[1] === 0.5, `"0,5" typed into a number field reads 0.5 (got ${JSON.stringify(typed)})`);
  await page.fill('#target', target_before);

  // --- a local check in the page's terms (labels, not API names) ---
  await page.fill('#emax', String(filled.emin / 2));
  await page.click('#submit');
  const order_error = await page.textContent('.err[data-for="emax"]');
  check(order_error === 'e_max must be greater than e_min', `local e_max < e_min message uses the labels ("${order_error}")`);
  await page.fill('#emax', String(filled.emax));
  check(await page.textContent('.err[data-for="emax"]') === '', 'editing e_max clears its message');

  // --- a 422 field error from the server, shown next to its field ---
  await page.fill('#iterations', '100000000');
  await page.click('#submit');
  const iter_error = await page.waitForSelector('.err[data-for="iterations"]:not(:empty)', { timeout: 10000 })
    .then((e) => e.textContent()).catch(() => '');
  check(/^Iterations /.test(iter_error), `server's 422 for iterations shown beside the field, by its label ("${iter_error}")`);
  await page.fill('#iterations', '100');

  // --- the less-used options are folded, so Remesh is in the first screen; an error in one of
  // them unfolds them and takes focus ---
  check(!(await page.$eval('#more-options', (d) => d.open)), 'the less-used options are folded at first');
  const submit_top = await page.$eval('#submit', (b) => b.getBoundingClientRect().bottom + window.scrollY);
  check(submit_top < 800, `Remesh within the first 800 px of the page (${Math.round(submit_top)})`);
  await page.click('#more-options > summary');
  await page.fill('#flip_factor', '2');
  await page.click('#more-options > summary');
  await page.click('#submit');
  await page.waitForSelector('.err[data-for="flip_factor"]:not(:empty)', { timeout: 10000 }).catch(() => null);
  check(await page.$eval('#more-options', (d) => d.open) && await page.evaluate(() => document.activeElement?.id) === 'flip_factor',
    'an error in a folded option unfolds the options and focuses its field');
  await page.fill('#flip_factor', '0.5');

  // --- a long job started over the API (as with curl) holds the only worker, so the page's job
  // waits in the queue with its event stream open and every row of it must arrive live ---
  const blocker = await api_post_job(base, icosphere_obj(4), { emin: 0.01, emax: 0.02, iterations: 1000, run_all_iterations: true });
  check(await wait_state(base, blocker, ['running']), `API job ${blocker} running`);

  // The recent-jobs list polls no more from here on: what it shows below came from the page's own
  // refreshes (on submit, on the job's state changes).
  await page.evaluate(() => { window.__remeshd.jobs.poll = { active: 2e9, idle: 2e9 }; return window.__remeshd.jobs.refresh(); });

  // --- the page's job: refine to 0.6 x mean, 4 iterations, all of them ---
  await page.fill('#target', String(+(0.6 * mean).toPrecision(4)));
  await page.click('#apply-target');
  await page.fill('#iterations', '4');
  await page.check('#run_all_iterations');
  await page.click('#submit');
  await page.waitForFunction(() => /job=/.test(location.hash), null, { timeout: 10000 });
  const job_id = await page.evaluate(() => decodeURIComponent(/job=([^&]+)/.exec(location.hash)[1]));
  check(await page.waitForSelector(`#jobs li[data-id="${job_id}"]`, { timeout: 10000 }).then(() => true, () => false),
    'the submitted job is in the recent-jobs list without waiting for a poll');
  check(await page.$eval('#job-id', (c) => c.textContent === c.innerText && getComputedStyle(c).textTransform === 'none'),
    'the job id is shown as it is (ids are case-sensitive)');
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
  check(await page.waitForSelector(`#jobs li[data-id="${job_id}"] .state.succeeded`, { timeout: 10000 }).then(() => true, () => false),
    'the recent-jobs list shows the job succeeded once it ended');
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
  // The keyboard goes from Remesh to the job's downloads, not through every recent job's links first.
  await page.focus('#submit');
  await page.keyboard.press('Tab');
  const after_submit = await page.evaluate(() => document.activeElement?.closest('section')?.className || document.activeElement?.localName);
  check(after_submit === 'job', `Tab from Remesh reaches the job panel (${after_submit})`);
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
  const far = job_doc.distance_to_input;
  check(far && progress_text.includes(`within ${+far.hausdorff.toPrecision(3)} of the input (${+(100 * far.relative).toPrecision(2)} % of its diagonal)`),
    `the distance to the input shown as the job document has it (${JSON.stringify(far)})`);
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
  const last = rows[rows.length - 1] || {};
  await check_histogram(page, 'remeshed', last);
  const out_series = await page.evaluate(() => Object.fromEntries(window.__remeshd.view.charts
    .find((c) => c.canvas.id === 'chart-out').series.map((s) => [s.label, s.color])));
  check(out_series.small === '--short' && out_series.big === '--long',
    `"Edges outside" draws small in the short colour and big in the long colour (${JSON.stringify(out_series)})`);

  // --- the dual, drawn with its polygon edges ---
  await page.click('label[for="show-dual"]');
  await page.waitForFunction(() => /^dual/.test(document.getElementById('view-status').textContent), null, { timeout: 15000 });
  await page.waitForTimeout(300);
  const dual_png = await page.locator('#view3d').screenshot({ path: path.join(artifacts, '3-dual-3d.png') });
  check(drawn_fraction(dual_png) > 0.02 && changed_fraction(remeshed_png, dual_png) > 0.005,
    `3D canvas draws the dual, different from the remeshed (${(100 * changed_fraction(remeshed_png, dual_png)).toFixed(1)} % changed)`);
  const dual_view = await page.evaluate(() => ({ counts: window.__remeshd.state.viewer.current.counts,
    status: document.getElementById('view-status').textContent,
    legend: document.getElementById('legend').classList.contains('bond') }));
  const near = (a, b) => Math.abs(a - b) <= Math.max(2, 0.01 * job_doc.dual.bonds);  // float32 positions in the GLB
  check(dual_view.legend && /short · [\d,]+ long \(against e_min\/√3, e_max\/√3\)$/.test(dual_view.status) &&
    near(dual_view.counts.short, job_doc.dual.short_bonds) && near(dual_view.counts.long, job_doc.dual.long_bonds),
    `the dual's bonds are coloured against [e_min, e_max]/√3 like the job's counts (${JSON.stringify(dual_view.counts)} vs ` +
    `${job_doc.dual.short_bonds} short, ${job_doc.dual.long_bonds} long; "${dual_view.status}")`);
  await check_histogram(page, 'dual', null);

  // --- a download that parses ---
  const [download] = await Promise.all([page.waitForEvent('download', { timeout: 10000 }),
    page.click('#downloads button[aria-label="Download remeshed as obj"]')]);
  const obj_path = path.join(artifacts, 'remeshed.obj');
  await download.saveAs(obj_path);
  const obj = parse_obj(fs.readFileSync(obj_path, 'utf8'));
  check(obj.error === '' && obj.vertices > 162 && obj.faces > 320,
    `remeshed.obj parses (${obj.vertices} v, ${obj.faces} f, refined from 162 v${obj.error ? `; ${obj.error}` : ''})`);
  check(obj.vertices - obj.edges + obj.faces === 2, `remeshed.obj is still a sphere (Euler ${obj.vertices - obj.edges + obj.faces})`);
  check(last.vertices === undefined || Math.abs(obj.vertices - last.vertices) <= 0.2 * last.vertices,
    `vertex count near the last row's (${obj.vertices} vs ${last.vertices})`);
  // Text glTF: the dual's, its buffer inside, one position per atom.
  const [gltf_download] = await Promise.all([page.waitForEvent('download', { timeout: 10000 }),
    page.click('#downloads button[aria-label="Download dual as gltf"]')]);
  const gltf_path = path.join(artifacts, 'dual.gltf');
  await gltf_download.saveAs(gltf_path);
  let gltf = null;
  try { gltf = JSON.parse(fs.readFileSync(gltf_path, 'utf8')); } catch { /* checked below */ }
  check(gltf?.asset?.version === '2.0' && gltf.buffers?.[0]?.uri?.startsWith('data:application/octet-stream;base64,') &&
    gltf.accessors?.[0]?.count === job_doc.dual.atoms,
    `dual.gltf is glTF 2.0 with its buffer inside and a position per atom (${gltf?.accessors?.[0]?.count} vs ${job_doc.dual.atoms})`);
  // A job whose GLB the server could not write (float32): no GLB nor glTF button, the rest stay.
  const buttons = await page.evaluate(() => {
    const view = window.__remeshd.view;
    const job = view.job;
    view.job = { ...job, unwritable: ['dual.glb', 'remeshed.stl'] };
    view.render_downloads();
    const labels = [...document.querySelectorAll('#downloads button')].map((b) => b.getAttribute('aria-label'));
    view.job = job;
    view.render_downloads();
    return labels;
  });
  check(!buttons.includes('Download dual as glb') && !buttons.includes('Download dual as gltf') &&
    !buttons.includes('Download remeshed as stl') && buttons.includes('Download remeshed as gltf') &&
    buttons.includes('Download dual as obj'),
    `downloads leave out what the server could not write, glTF with GLB (${buttons.filter((b) => /dual|stl/.test(b)).join(', ')})`);

  // --- many rows at once (a fast job's stream chunk: one event each, in one task) are all kept and
  // reach the table together in one later frame; the table follows the newest row while the user
  // is at its bottom, and stays where the user scrolled it otherwise ---
  const batch = await page.evaluate(async () => {
    const view = window.__remeshd.view;
    const body = document.querySelector('#rows tbody');
    const wrap = body.closest('.tablewrap');
    const frames = () => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)));
    const add = (n) => {
      const last = view.rows[view.rows.length - 1];
      for (let i = 1; i <= n; ++i) view.add_rows([{ ...last, iteration: last.iteration + i }]);
    };
    const gap = () => wrap.scrollHeight - wrap.scrollTop - wrap.clientHeight;
    const before = body.rows.length;
    const batches = view.batches;
    add(500);
    const in_task = body.rows.length;
    await frames();
    const out = { before, in_task, after: body.rows.length, held: view.rows.length, batches: view.batches - batches, gap: gap() };
    wrap.scrollTop = 0;  // the user scrolls up to read
    await frames();
    add(20);
    await frames();
    out.scrolled_up = wrap.scrollTop;
    wrap.scrollTop = wrap.scrollHeight;  // and back down
    await frames();
    add(20);
    await frames();
    out.gap_again = gap();
    return out;
  });
  check(batch.in_task === batch.before && batch.after === batch.before + 500 && batch.held === batch.after && batch.batches === 1,
    `500 rows delivered at once: none drawn in that task, all drawn in one batch (${JSON.stringify(batch)})`);
  check(batch.gap < 24 && batch.scrolled_up === 0 && batch.gap_again < 24,
    'the table follows the newest row at its bottom, and not after the user scrolled up');

  // --- the json link of the recent jobs carries the token (opened in a new tab, without the
  // page's Authorization header); this server needs none, so the token is only set for a moment ---
  const links = await page.evaluate(async () => {
    const { api, jobs } = window.__remeshd;
    api.set_token('t0k&n');
    const url = api.authorized_url('api/v1/jobs/ab?x=1');
    await jobs.refresh();
    const href = document.querySelector('#jobs li[data-id] a[target=_blank]').getAttribute('href');
    api.set_token('');
    await jobs.refresh();
    return { url, href, plain: document.querySelector('#jobs li[data-id] a[target=_blank]').getAttribute('href') };
  });
  check(links.url === 'api/v1/jobs/ab?x=1&access_token=t0k%26n' && /\?access_token=t0k%26n$/.test(links.href) &&
    !/access_token/.test(links.plain), `the jobs list's json link carries the token when one is set (${JSON.stringify(links)})`);

  // --- a reload reconnects to the job and shows every row again; the input's GLB is held back
  // until the remeshed one is in, so the input finishes loading last: the view must still show
  // the mesh of the selected radio (Remeshed), not the last one loaded ---
  const hold_input = async (route) => {
    await page.waitForFunction(() => window.__remeshd?.state.viewer?.has('remeshed'), null, { timeout: 20000 }).catch(() => {});
    await route.continue();
  };
  await page.route(/\/result\?mesh=input&format=glb/, hold_input);
  await page.reload({ waitUntil: 'load' });
  await page.waitForFunction(() => window.__remeshd, null, { timeout: 60000 });
  await page.waitForFunction(() => { const s = window.__remeshd.state; return s.viewer.has('input') && s.viewer.has('remeshed') && !s.loading.size; },
    null, { timeout: 30000 }).catch(() => {});
  const race = await page.evaluate(() => ({ radio: document.querySelector('input[name=show]:checked').value,
    status: document.getElementById('view-status').textContent, both: window.__remeshd.state.viewer.has('input') }));
  check(race.both && race.radio === 'remeshed' && race.status.startsWith('remeshed ·'),
    `the input loaded after the remeshed: the view still shows the selected radio's mesh (${race.radio}: "${race.status}")`);
  await page.unroute(/\/result\?mesh=input&format=glb/, hold_input);
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
  await page.waitForFunction(() => /^remeshed/.test(document.getElementById('view-status').textContent), null, { timeout: 15000 }).catch(() => {});
  const lens_rows = await (await fetch(`${base}/api/v1/jobs/${lens_id}/stats?format=json`)).json();
  await check_histogram(page, 'remeshed', (Array.isArray(lens_rows) ? lens_rows : lens_rows.rows || []).at(-1));

  // --- a job opened by its address keeps its own interval, and its input's mean becomes the target
  // (the target of the page's last file stayed, and "Fill" gave an interval for that file) ---
  const lens_mean = (await (await fetch(`${base}/api/v1/jobs/${lens_id}`)).json()).input.summary.edge_length.mean;
  const lens_form = { target: +await page.inputValue('#target'), emin: +await page.inputValue('#emin'), emax: +await page.inputValue('#emax') };
  check(Math.abs(lens_form.target - lens_mean) <= 1e-3 * lens_mean && lens_form.emin === 1 && lens_form.emax === 1.4,
    `the opened job's input mean is the target, its interval the job's (${JSON.stringify(lens_form)}, mean ${lens_mean})`);

  // --- deleting the watched job from the recent-jobs list clears its panel (its downloads pointed
  // at files that were gone) ---
  const delete_button = `#jobs li[data-id="${lens_id}"] button.link`;
  await page.waitForSelector(delete_button, { timeout: 10000 });
  page.once('dialog', (d) => d.accept());
  await page.click(delete_button);
  const forgotten = await page.waitForFunction(() => document.getElementById('job-state').textContent === 'deleted' &&
    !document.querySelector('#downloads button') && !/job=/.test(location.hash) &&
    document.getElementById('show-remeshed').disabled, null, { timeout: 10000 }).then(() => true, () => false);
  check(forgotten, 'deleting the watched job clears its panel, downloads, 3D choices and address');

  // --- a .txt name: no verdict before the server has tried ---
  const txt_path = path.join(tmp, 'sphere.txt');
  fs.writeFileSync(txt_path, icosphere_obj(2));
  await page.setInputFiles('#file', txt_path);
  const txt_status = await page.textContent('#view-status');
  check(/server will try to detect the format/.test(txt_status), `an unknown extension defers to the server ("${txt_status}")`);

  // --- an output-size estimate over the limit: beside e_min/e_max, in numbers one can read, focus
  // there; editing the interval clears it ---
  await page.setInputFiles('#file', mesh_path);
  // The local preview fills e_min/e_max from the mean: wait for it, or it would overwrite them.
  await page.waitForFunction(() => +document.getElementById('input-mean').dataset.value > 0, null, { timeout: 10000 });
  await page.fill('#emin', '0.0001');
  await page.fill('#emax', '0.0002');
  await page.click('#submit');
  const size_error = await page.waitForSelector('.err[data-for="emin"]:not(:empty)', { timeout: 10000 })
    .then((e) => e.textContent()).catch(() => '');
  const size_focus = await page.evaluate(() => document.activeElement?.id);
  check(/^e_min and e_max are so small that the result would have about [\d.]+ (million|billion|trillion) faces, more than this server's limit of [\d.,]+( million)?\. Use a larger e_min and e_max\.$/.test(size_error) &&
    size_focus === 'emin' && await page.getAttribute('#emax', 'aria-invalid') === 'true' && await page.textContent('#file-error') === '',
    `the output-size limit is shown beside e_min/e_max with focus there ("${size_error}", focus ${size_focus})`);
  await page.fill('#emin', '0.1');
  check(await page.textContent('.err[data-for="emin"]') === '' && await page.getAttribute('#emax', 'aria-invalid') === null,
    'editing e_min clears the size message of both fields');
  await page.fill('#emax', '0.2');

  // --- garbage: the server's reader message, beside the file and by the button (focused) ---
  await page.setInputFiles('#file', garbage_path);
  await page.click('#submit');
  const bad = await page.waitForSelector('#file-error:not(:empty)', { timeout: 10000 }).then((e) => e.textContent()).catch(() => '');
  const by_button = await page.textContent('#form-error');
  const bad_focus = await page.evaluate(() => document.activeElement?.id);
  check(/^The server could not read garbage\.obj: .{10,}\. Fix the file or choose another one\.$/.test(bad) && by_button === bad && bad_focus === 'form-error',
    `garbage file refused with the reader's message beside the file and by the button, focus there ("${bad}")`);
  await shot('4-garbage');

  // --- an empty file: said beside the file chooser; choosing a good file clears it ---
  const empty_path = path.join(tmp, 'empty.obj');
  fs.writeFileSync(empty_path, '');
  await page.setInputFiles('#file', empty_path);
  await page.click('#submit');
  const empty = await page.waitForSelector('#file-error:not(:empty)', { timeout: 10000 }).then((e) => e.textContent()).catch(() => '');
  check(/^The file empty\.obj is empty\. Choose another file\.$/.test(empty) && await page.textContent('#form-error') === empty,
    `an empty file is named beside the file chooser and by the button ("${empty}")`);
  await page.setInputFiles('#file', mesh_path);
  check(await page.textContent('#file-error') === '' && await page.textContent('#form-error') === '',
    'choosing another file clears the last file\'s message');

  // --- a phone (390x844): the finished job and then a chosen file, in a context of its own ---
  await check_phone(base, job_id, mesh_path, console_errors);

  check(console_errors.length === 0, `no errors in the browser console${console_errors.length ? `: ${console_errors.join(' | ')}` : ''}`);
}

/// At a phone's 390x844 viewport (touch, the page's `width=device-width`): the page never scrolls
/// sideways (wide tables scroll in their own box), the 3D view and the charts fit the width, with a
/// file chosen the file chooser, e_min/e_max and the Remesh button are in the first screen (the
/// options folded) and Remesh is at least 40 px high, a finger's size.
async function check_phone(base, job_id, mesh_path, console_errors) {
  const W = 390, H = 844;
  const context = await browser.newContext({ viewport: { width: W, height: H }, isMobile: true, hasTouch: true });
  const phone = await context.newPage();
  phone.on('console', (m) => { if (m.type() === 'error' && !/Failed to load resource/.test(m.text())) console_errors.push(`phone: ${m.text()}`); });
  phone.on('pageerror', (e) => console_errors.push(`phone: ${e}`));
  const measure = () => phone.evaluate(() => {
    const box = (sel) => {
      const r = document.querySelector(sel).getBoundingClientRect();
      return { left: Math.round(r.left), right: Math.round(r.right), top: Math.round(r.top + scrollY),
        bottom: Math.round(r.bottom + scrollY), width: Math.round(r.width), height: Math.round(r.height) };
    };
    // What sticks out on the right (none should), for the message.
    const out = [...document.querySelectorAll('body *')].filter((e) => !e.closest('.tablewrap') &&
      e.getBoundingClientRect().right > innerWidth + 0.5).map((e) => `${e.localName}${e.id ? `#${e.id}` : ''}`).slice(0, 5);
    return { inner: innerWidth, scroll: document.documentElement.scrollWidth, out,
      file: box('.filebtn'), emin: box('#emin'), emax: box('#emax'), submit: box('#submit'),
      more_open: document.getElementById('more-options').open,
      canvases: ['#view3d', '#histogram', '#chart-length', '#chart-seconds'].map(box) };
  });
  const sideways = (m) => `scrollWidth ${m.scroll}, innerWidth ${m.inner}${m.out.length ? `; sticking out: ${m.out.join(' ')}` : ''}`;
  try {
    // A first visit: choose a file, and the form is ready to send. The name takes two lines at
    // this width, as a scan's or a CAD export's often does.
    const named = path.join(tmp, 'statue_scan_2026-11-27_decimated_final_v2.obj');
    fs.copyFileSync(mesh_path, named);
    await phone.goto(base, { waitUntil: 'load' });
    await phone.waitForFunction(() => window.__remeshd, null, { timeout: 60000 });
    await phone.setInputFiles('#file', named);
    await phone.waitForFunction(() => +document.getElementById('input-mean').dataset.value > 0, null, { timeout: 10000 });
    const form = await measure();
    await phone.screenshot({ path: path.join(artifacts, '5-phone-file.png') });
    check(form.scroll <= form.inner, `phone ${W}x${H}, a file chosen: the page does not scroll sideways (${sideways(form)})`);
    check(!form.more_open && Math.max(form.file.bottom, form.emin.bottom, form.emax.bottom, form.submit.bottom) <= H,
      `phone, a file chosen: the file chooser, e_min/e_max and Remesh in the first ${H} px with the options folded ` +
      `(bottoms ${form.file.bottom}, ${form.emin.bottom}, ${form.emax.bottom}, Remesh ${form.submit.bottom})`);
    check(form.submit.height >= 40, `phone: Remesh is a touch target at least 40 px high (${form.submit.height} px)`);
    // Remesh brings the job panel into view: it lies below the form and the job list, and a tap
    // changed nothing on screen while the job ran unseen 1 200 px further down.
    await phone.click('#submit');
    const panel_shown = await phone.waitForFunction(() => {
      const r = document.querySelector('section.job').getBoundingClientRect();
      return /job=/.test(location.hash) && r.top >= -1 && r.top < innerHeight / 2;
    }, null, { timeout: 10000 }).then(() => true, () => false);
    check(panel_shown, 'phone: Remesh brings the job panel into view');

    // The finished job: downloads, 3D view, histogram, charts and its table.
    await phone.evaluate((id) => { location.hash = `job=${id}`; }, job_id);
    await phone.waitForFunction(() => document.querySelector('#rows tbody tr') && document.querySelector('#downloads button') &&
      /^remeshed/.test(document.getElementById('view-status').textContent), null, { timeout: 20000 }).catch(() => {});
    const job = await measure();
    await phone.screenshot({ path: path.join(artifacts, '6-phone-job.png'), fullPage: true });
    check(job.scroll <= job.inner, `phone, a finished job: the page does not scroll sideways (${sideways(job)})`);
    check(job.canvases.every((c) => c.left >= 0 && c.right <= job.inner && c.width >= 0.8 * job.inner),
      `phone: the 3D view, histogram and charts fit the width (${job.canvases.map((c) => `${c.left}..${c.right}`).join(', ')})`);
  } finally {
    await context.close();
  }
}

/// Checks the histogram of the mesh shown (`name`): its short/long bars hold exactly the edges the
/// view colours short/long, no pixel has the short (long) colour when no edge is short (long), and
/// none when the last statistics row `row` has every edge inside.
async function check_histogram(page, name, row) {
  const h = await page.evaluate(() => {
    const v = window.__remeshd.state.viewer;
    const sum = (a) => a.reduce((s, x) => s + x, 0);
    const css = (n) => getComputedStyle(document.documentElement).getPropertyValue(n).trim();
    return { name: v.current.name, short: sum(v.histogram.short), long: sum(v.histogram.long), counts: v.current.counts,
      colours: [css('--short'), css('--long')] };
  });
  const png = decode_png(await page.locator('#histogram').screenshot());
  const [short_px, long_px] = h.colours.map((hex) => {
    const c = [1, 3, 5].map((i) => parseInt(hex.slice(i, i + 2), 16));
    let n = 0;
    for (let p = 0; p < png.data.length; p += png.channels)
      if (c.every((v, k) => Math.abs(png.data[p + k] - v) <= 12)) ++n;
    return n;
  });
  check(h.name === name && h.short === h.counts.short && h.long === h.counts.long &&
    (h.short > 0 || short_px === 0) && (h.long > 0 || long_px === 0),
    `the ${name} histogram's short/long bars hold exactly the short/long edges (${h.short}/${h.long} vs ` +
    `${h.counts.short}/${h.counts.long}; ${short_px}/${long_px} pixels in the short/long colours)`);
  if (row && row.small === 0 && row.big === 0)
    check(h.short === 0 && h.long === 0, `no short or long bars when the job's last row has every edge inside (${h.short}/${h.long})`);
  else if (row) log(`(the last row has ${row.small} small, ${row.big} big: the every-edge-inside histogram check is skipped)`);
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
