/// The public HTTP API of remeshd (/api/v1), as the page uses it. Every call sends the token (if
/// any) as `Authorization: Bearer`; errors come back as ApiError carrying the problem document.

const TOKEN_KEY = 'remeshd.token';
export const BASE = 'api/v1';

/// An HTTP error with the server's application/problem+json body (title, status, detail, errors).
export class ApiError extends Error {
  constructor(status, problem) {
    const text = problem.detail || problem.title || `HTTP ${status}`;
    super(text);
    this.status = status;
    this.problem = problem;
    /// [{field, message}] for 422 validation errors, else [].
    this.fieldErrors = Array.isArray(problem.errors) ? problem.errors : [];
  }
}

export function token() { return sessionStorage.getItem(TOKEN_KEY) || ''; }
export function set_token(value) {
  if (value) sessionStorage.setItem(TOKEN_KEY, value); else sessionStorage.removeItem(TOKEN_KEY);
}

function headers(extra = {}) {
  const t = token();
  return t ? { ...extra, Authorization: `Bearer ${t}` } : extra;
}

let on_unauthorized = () => {};
/// Called with the ApiError whenever any request answers 401.
export function set_unauthorized_handler(fn) { on_unauthorized = fn; }

async function problem_of(res) {
  const type = res.headers.get('content-type') || '';
  try {
    if (type.includes('json')) return await res.json();
    const text = (await res.text()).trim();
    return { title: res.statusText, status: res.status, detail: text.slice(0, 300) };
  } catch {
    return { title: res.statusText, status: res.status };
  }
}

/// fetch() relative to the page, with the token; throws ApiError on a non-2xx answer.
export async function request(path, options = {}) {
  let res;
  try {
    res = await fetch(path, { ...options, headers: headers(options.headers) });
  } catch (e) {
    throw new ApiError(0, { title: 'Network error', detail: `cannot reach the server (${e.message})` });
  }
  if (!res.ok) {
    const err = new ApiError(res.status, await problem_of(res));
    if (res.status === 401) on_unauthorized(err);
    throw err;
  }
  return res;
}

export async function json(path, options) {
  const res = await request(path, options);
  return res.status === 204 ? null : res.json();
}

/// POST /jobs as multipart: the mesh file and the params JSON. Resolves to the job document.
/// `on_progress(fraction)` reports upload progress (XMLHttpRequest: fetch cannot).
export function create_job(file, params, on_progress = () => {}) {
  const form = new FormData();
  form.append('mesh', file, file.name);
  form.append('params', JSON.stringify(params));
  return new Promise((resolve, reject) => {
    const xhr = new XMLHttpRequest();
    xhr.open('POST', `${BASE}/jobs`);
    const t = token();
    if (t) xhr.setRequestHeader('Authorization', `Bearer ${t}`);
    xhr.upload.onprogress = (e) => { if (e.lengthComputable) on_progress(e.loaded / e.total); };
    xhr.onerror = () => reject(new ApiError(0, { title: 'Network error', detail: 'the upload failed' }));
    xhr.onload = () => {
      let body = {};
      try { body = JSON.parse(xhr.responseText); } catch { body = { detail: xhr.responseText.slice(0, 300) }; }
      if (xhr.status >= 200 && xhr.status < 300) return resolve(body);
      const err = new ApiError(xhr.status, { title: xhr.statusText, ...body });
      if (xhr.status === 401) on_unauthorized(err);
      reject(err);
    };
    xhr.send(form);
  });
}

export const get_job = (id) => json(`${BASE}/jobs/${encodeURIComponent(id)}`);
export const list_jobs = (limit = 20) => json(`${BASE}/jobs?limit=${limit}`);
export const delete_job = (id) => json(`${BASE}/jobs/${encodeURIComponent(id)}`, { method: 'DELETE' });

/// All statistics rows of a job so far, as an array (accepts a bare array or {rows|stats: [...]}).
export async function get_stats(id) {
  const body = await json(`${BASE}/jobs/${encodeURIComponent(id)}/stats?format=json`);
  if (Array.isArray(body)) return body;
  return body.rows || body.stats || body.iterations || [];
}

export function result_url(id, mesh, format) {
  return `${BASE}/jobs/${encodeURIComponent(id)}/result?mesh=${mesh}&format=${format}`;
}
export function stats_csv_url(id) { return `${BASE}/jobs/${encodeURIComponent(id)}/stats?format=csv`; }

/// `path` with the token (if any) as `access_token`, for what cannot send a header: an EventSource,
/// a link the browser opens by itself. The server accepts it on every route.
export function authorized_url(path) {
  const t = token();
  if (!t) return path;
  return `${path}${path.includes('?') ? '&' : '?'}${new URLSearchParams({ access_token: t })}`;
}

/// An EventSource on the job's events; `after` = last iteration already held (0 = none).
export function events(id, after) {
  const path = `${BASE}/jobs/${encodeURIComponent(id)}/events`;
  return new EventSource(authorized_url(after > 0 ? `${path}?lastEventId=${after}` : path));
}

/// Fetches a URL with the token and saves it under `fallback_name` (or the server's filename).
export async function download(path, fallback_name) {
  const res = await request(path);
  const disposition = res.headers.get('content-disposition') || '';
  const m = /filename\*?=(?:UTF-8'')?"?([^";]+)"?/i.exec(disposition);
  const name = m ? decodeURIComponent(m[1]) : fallback_name;
  const url = URL.createObjectURL(await res.blob());
  const a = document.createElement('a');
  a.href = url;
  a.download = name;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 60_000);
  return name;
}

export async function health() {
  const res = await fetch('healthz', { headers: headers() });
  return res.ok;
}
