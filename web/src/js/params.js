/// The parameter form: reading it into the API's params object, filling it from a job, the
/// target-mean helper, and the server's 422 field errors shown next to their fields.

const $ = (id) => document.getElementById(id);

const NUMBERS = ['emin', 'emax', 'iterations', 'rings', 'relax_every', 'flip_factor'];
const BOOLEANS = ['run_all_iterations', 'protect_tips', 'keep_creases', 'more_regular', 'relax_dual', 'weld'];

/// The params object for POST /jobs. Empty fields are left out (the server applies its defaults,
/// and reports a missing emin/emax itself); text the browser cannot parse as a number is sent
/// as-is so the server names the field.
export function read_params() {
  const out = {};
  for (const name of NUMBERS) {
    const input = $(name);
    if (input.value === '' && !input.validity.badInput) continue;
    const v = input.valueAsNumber;
    out[name] = Number.isFinite(v) ? v : input.value;
  }
  for (const name of BOOLEANS) if ($(name).checked) out[name] = true;
  return out;
}

/// Fills the form from a job's params (e.g. when watching a job started elsewhere).
export function write_params(params) {
  if (!params) return;
  for (const name of NUMBERS) if (params[name] !== undefined) $(name).value = params[name];
  for (const name of BOOLEANS) if (params[name] !== undefined) $(name).checked = !!params[name];
}

/// The interval currently typed in the form (NaN when missing).
export function interval() {
  return { emin: $('emin').valueAsNumber, emax: $('emax').valueAsNumber };
}

/// Local checks that save a round trip; the server's answer stays the authority.
export function local_errors(p) {
  const errs = [];
  if (p.emin === undefined) errs.push({ field: 'emin', message: 'is required' });
  else if (!(p.emin > 0)) errs.push({ field: 'emin', message: 'must be a number > 0' });
  if (p.emax === undefined) errs.push({ field: 'emax', message: 'is required' });
  else if (!(p.emax > 0)) errs.push({ field: 'emax', message: 'must be a number > 0' });
  else if (p.emin > 0 && !(p.emax > p.emin)) errs.push({ field: 'emax', message: 'must be greater than e_min' });
  return errs;
}

/// Shows [{field, message}] next to their fields; errors for unknown fields go to the form's line.
export function show_field_errors(errors) {
  clear_field_errors();
  const form = $('params');
  const general = [];
  for (const { field, message } of errors) {
    const slot = form.querySelector(`.err[data-for="${CSS.escape(field || '')}"]`);
    const input = field && form.elements[field];
    if (slot && slot.dataset.for !== 'params') {
      slot.textContent = slot.textContent ? `${slot.textContent}; ${message}` : `${field} ${message}`;
      if (input) {
        input.setAttribute('aria-invalid', 'true');
        input.setAttribute('aria-describedby', slot.id || (slot.id = `err-${field}`));
      }
    } else general.push(field ? `${field}: ${message}` : message);
  }
  form.querySelector('.err[data-for="params"]').textContent = general.join('; ');
  const first = form.querySelector('[aria-invalid=true]');
  if (first) first.focus();
}

export function clear_field_errors() {
  const form = $('params');
  for (const e of form.querySelectorAll('.err')) e.textContent = '';
  for (const i of form.querySelectorAll('[aria-invalid]')) i.removeAttribute('aria-invalid');
}

/// The helper: target mean ± tolerance % -> emin/emax. `on_change` runs after the form changed.
export function init_helper(on_change) {
  const apply = () => {
    const target = $('target').valueAsNumber;
    const tol = ($('tolerance').valueAsNumber || 20) / 100;
    if (!(target > 0) || !(tol > 0 && tol < 1)) {
      $('target').setAttribute('aria-invalid', 'true');
      return;
    }
    $('target').removeAttribute('aria-invalid');
    $('emin').value = round(target * (1 - tol));
    $('emax').value = round(target * (1 + tol));
    on_change();
  };
  $('apply-target').addEventListener('click', apply);
  for (const id of ['target', 'tolerance']) $(id).addEventListener('keydown', (e) => {
    if (e.key === 'Enter') { e.preventDefault(); apply(); }
  });
  $('use-mean').addEventListener('click', () => {
    const mean = +$('input-mean').dataset.value;
    if (mean > 0) { $('target').value = round(mean); apply(); }
  });
  for (const id of ['emin', 'emax']) $(id).addEventListener('input', on_change);
  return apply;
}

/// Shows the input's mean edge length beside the helper; on a fresh input (or an empty form)
/// it becomes the target and fills the interval.
export function set_input_mean(mean, source, { fill = false } = {}) {
  const out = $('input-mean');
  out.dataset.value = mean > 0 ? mean : '';
  out.textContent = mean > 0 ? `${round(mean)} (${source})` : '–';
  $('use-mean').hidden = !(mean > 0);
  if (mean > 0 && (fill || $('target').value === '')) {
    $('target').value = round(mean);
    $('apply-target').click();
  }
}

/// Four significant digits: enough for an interval, short enough to read.
export function round(v) { return +v.toPrecision(4); }
