/// The parameter form: reading it into the API's params object, filling it from a job, the
/// target-mean helper, and the server's 422 field errors shown next to their fields.

const $ = (id) => document.getElementById(id);

const NUMBERS = ['emin', 'emax', 'iterations', 'rings', 'relax_every', 'flip_factor'];
const BOOLEANS = ['run_all_iterations', 'protect_tips', 'keep_creases', 'more_regular', 'relax_dual', 'weld'];
/// The fields inside "More options" (index.html).
const FOLDED = ['rings', 'relax_every', 'flip_factor', ...BOOLEANS];

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
  show_bonds();
  // A job that used any of the folded options shows them.
  if (FOLDED.some((name) => $(name).type === 'checkbox' ? $(name).checked : $(name).value !== $(name).defaultValue))
    $('more-options').open = true;
}

/// The interval currently typed in the form (NaN when missing).
export function interval() {
  return { emin: $('emin').valueAsNumber, emax: $('emax').valueAsNumber };
}

/// The page's name of each API field, for messages (the API's emin reads "e_min" on the page).
const LABELS = { emin: 'e_min', emax: 'e_max', iterations: 'Iterations', rings: 'Rings k',
  relax_every: 'Relax every', flip_factor: 'Flip factor f', run_all_iterations: 'Run all iterations',
  protect_tips: 'Protect tips', keep_creases: 'Keep creases', more_regular: 'More regular',
  relax_dual: "Relax the dual's bonds", weld: 'Weld duplicate vertices', mesh: 'The file' };

export function label(field) { return LABELS[field] || field; }

/// A server message with the API's field names replaced by the page's labels.
export function in_page_terms(text) {
  return String(text).replace(/\b(emin|emax|relax_every|flip_factor|run_all_iterations|protect_tips|keep_creases|more_regular|relax_dual)\b/g,
    (name) => LABELS[name]);
}

/// Local checks that save a round trip; the server's answer stays the authority.
export function local_errors(p) {
  const errs = [];
  if (p.emin === undefined) errs.push({ field: 'emin', message: 'is required: enter the shortest edge length wanted' });
  else if (!(p.emin > 0)) errs.push({ field: 'emin', message: 'must be a number greater than 0' });
  if (p.emax === undefined) errs.push({ field: 'emax', message: 'is required: enter the longest edge length wanted' });
  else if (!(p.emax > 0)) errs.push({ field: 'emax', message: 'must be a number greater than 0' });
  else if (p.emin > 0 && !(p.emax > p.emin)) errs.push({ field: 'emax', message: 'must be greater than e_min' });
  // A fraction where a count is wanted, in words (the server's message adds the integer range).
  for (const name of ['iterations', 'rings', 'relax_every'])
    if (typeof p[name] === 'number' && !Number.isInteger(p[name]))
      errs.push({ field: name, message: `must be a whole number, not ${p[name]}` });
  return errs;
}

/// Shows [{field, message}] next to their fields; errors for unknown fields go to the form's line
/// above the Remesh button. `also`: more fields to mark invalid with the first field's message
/// (the output-size estimate is about e_min and e_max together). Focus moves to the first field.
export function show_field_errors(errors, { also = [] } = {}) {
  clear_field_errors();
  const form = $('params');
  const general = [];
  // `message` completes the field's label ("must be > 0"); `text` is a whole sentence of its own.
  for (const { field, message, text: whole } of errors) {
    const slot = form.querySelector(`.err[data-for="${CSS.escape(field || '')}"]`);
    const text = whole || in_page_terms(message);
    if (slot && slot.dataset.for !== 'params') {
      const own = whole || `${label(field)} ${text}`;
      slot.textContent = slot.textContent ? `${slot.textContent}; ${text}` : own;
      for (const f of [field, ...(field === errors[0].field ? also : [])]) {
        const el = form.elements[f];
        if (!el) continue;
        el.setAttribute('aria-invalid', 'true');
        el.setAttribute('aria-describedby', slot.id || (slot.id = `err-${field}`));
      }
    } else general.push(field ? `${label(field)}: ${text}` : text);
  }
  form.querySelector('.err[data-for="params"]').textContent = general.join('; ');
  const first = form.querySelector('[aria-invalid=true]');
  // A field in the folded options is shown before it takes focus.
  if (first) first.closest('details')?.setAttribute('open', '');
  if (first) first.focus();
}

/// Clears the messages of the form's fields (all of them, or those of `fields`). The line above
/// the Remesh button is cleared only when clearing all.
export function clear_field_errors(fields) {
  const form = $('params');
  for (const e of form.querySelectorAll('.err')) if (!fields || fields.includes(e.dataset.for)) e.textContent = '';
  for (const i of form.querySelectorAll('[aria-invalid]')) {
    if (fields && !fields.includes(i.name || i.id)) continue;
    i.removeAttribute('aria-invalid');
    i.removeAttribute('aria-describedby');
  }
}

/// Editing a field clears its message (a fixed value must not keep its old complaint); e_min and
/// e_max go together, since their messages (order, output size) are about both.
function clear_on_edit() {
  const form = $('params');
  form.addEventListener('input', (e) => {
    const name = e.target.name;
    if (!name) return;
    clear_field_errors(name === 'emin' || name === 'emax' ? ['emin', 'emax'] : [name]);
  });
}

/// A decimal comma typed or pasted into a number field becomes a point. Chromium's number inputs
/// drop the comma of "0,04" (the value read as 4) in every locale, silently.
function decimal_comma() {
  const insert = (text) => document.execCommand('insertText', false, text);
  for (const input of document.querySelectorAll('input[type=number]')) {
    input.addEventListener('keydown', (e) => {
      if (e.key === ',' && !e.ctrlKey && !e.metaKey && !e.altKey && insert('.')) e.preventDefault();
    });
    input.addEventListener('paste', (e) => {
      const text = e.clipboardData?.getData('text') ?? '';
      if (/^\s*[-+]?\d*,\d+(e[-+]?\d+)?\s*$/i.test(text) && insert(text.trim().replace(',', '.'))) e.preventDefault();
    });
  }
}

/// Edge length per unit of target: 1 for a target edge, √3 for a target bond of the dual
/// (equilateral triangles of side a have dual edges a / √3; the API's bond_min/bond_max do the same).
const per_target = () => ($('target-of').value === 'bond' ? Math.sqrt(3) : 1);

/// The dual's bond interval [e_min, e_max] / √3 beside the helper, from the form as typed.
export function show_bonds() {
  const { emin, emax } = interval();
  $('bond-interval').textContent = emin > 0 && emax > emin
    ? `[${round(emin / Math.sqrt(3))}, ${round(emax / Math.sqrt(3))}]` : '–';
}

/// The helper: target mean ± tolerance % -> emin/emax. `on_change` runs after the form changed.
/// A wrong target or tolerance is named beside the helper instead of being replaced by a default.
/// The target is an edge length or, with "bond" chosen beside it, a bond length of the dual.
export function init_helper(on_change) {
  clear_on_edit();
  decimal_comma();
  const error = $('helper-error');
  const complain = (field, text) => {
    for (const id of ['target', 'tolerance']) {
      if (id === field) { $(id).setAttribute('aria-invalid', 'true'); $(id).setAttribute('aria-describedby', 'helper-error'); }
      else { $(id).removeAttribute('aria-invalid'); $(id).removeAttribute('aria-describedby'); }
    }
    error.textContent = text;
  };
  const apply = () => {
    const target = $('target').valueAsNumber;
    const percent = $('tolerance').valueAsNumber;
    if (!(target > 0)) {
      complain('target', $('target').value === '' && !$('target').validity.badInput
        ? `Target mean is empty: enter the ${per_target() > 1 ? "dual's bond" : 'edge'} length wanted (or press "use it" for the input's mean).`
        : 'Target mean must be a number greater than 0.');
      return;
    }
    if (!(percent > 0 && percent < 100)) {
      complain('tolerance', '± % must be a number between 0 and 100, for example 20 (e_min = target − 20 %, e_max = target + 20 %).');
      return;
    }
    complain('', '');
    const tol = percent / 100;
    $('emin').value = round(target * per_target() * (1 - tol));
    $('emax').value = round(target * per_target() * (1 + tol));
    clear_field_errors(['emin', 'emax']);
    show_bonds();
    on_change();
  };
  $('apply-target').addEventListener('click', apply);
  for (const id of ['target', 'tolerance']) {
    $(id).addEventListener('keydown', (e) => {
      if (e.key === 'Enter') { e.preventDefault(); apply(); }
    });
    $(id).addEventListener('input', () => { if ($(id).hasAttribute('aria-invalid')) complain('', ''); });
  }
  $('use-mean').addEventListener('click', () => {
    const mean = +$('input-mean').dataset.value;
    if (mean > 0) { $('target').value = round(mean / per_target()); apply(); }
  });
  // A target typed already is taken as the new kind of length.
  $('target-of').addEventListener('change', () => { if ($('target').valueAsNumber > 0) apply(); });
  for (const id of ['emin', 'emax']) $(id).addEventListener('input', () => { show_bonds(); on_change(); });
  return apply;
}

/// Shows the input's mean edge length beside the helper; on a fresh input (or an empty form)
/// it becomes the target and fills the interval.
/// With `target`, the mean becomes the target without touching the interval (a job opened from the
/// list keeps its own); with `clear` (a new input, mean unknown yet), the target is emptied, so
/// that "Fill" cannot apply the last input's mean to this one (the interval stays as typed: a file
/// without a preview is still sent, for the server to read or refuse).
export function set_input_mean(mean, source, { fill = false, target = false, clear = false } = {}) {
  const out = $('input-mean');
  out.dataset.value = mean > 0 ? mean : '';
  out.textContent = mean > 0 ? `${round(mean)} (${source})` : '–';
  $('use-mean').hidden = !(mean > 0);
  if (clear) {
    $('target').value = '';
    $('helper-error').textContent = '';
  }
  if (mean > 0 && target) $('target').value = round(mean / per_target());
  else if (mean > 0 && (fill || $('target').value === '')) {
    $('target').value = round(mean / per_target());
    $('apply-target').click();
  }
}

/// Four significant digits: enough for an interval, short enough to read.
export function round(v) { return +v.toPrecision(4); }
