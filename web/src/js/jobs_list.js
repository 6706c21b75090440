/// The recent-jobs list (GET /jobs, newest first): state, file, progress and a link that watches
/// the job here (#job=<id>), so a job started with curl can be followed in the page.

import * as api from './api.js';

const $ = (id) => document.getElementById(id);

export class JobsList {
  /// `on_deleted(id)`: a job was deleted from the list (the page forgets it if it is watched).
  constructor({ on_deleted } = {}) {
    this.on_deleted = on_deleted;
    this.timer = null;
    this.current = '';
    this.requests = 0;
    /// Milliseconds between polls while some job is active, and otherwise (the page also refreshes
    /// on submit and on every state change of the watched job).
    this.poll = { active: 3000, idle: 15000 };
    $('jobs-refresh').addEventListener('click', () => this.refresh());
    document.addEventListener('visibilitychange', () => { if (!document.hidden) this.refresh(); });
  }

  /// The watched job's iterations as its rows arrive (the list polls every 3 s: it showed 0/200
  /// while the job panel was at iteration 46).
  set_progress(id, done, total) {
    const meta = [...$('jobs').children].find((li) => li.dataset.id === id)?.querySelector('.meta');
    if (!meta?.dataset.parts || !total) return;
    const parts = JSON.parse(meta.dataset.parts);
    parts[2] = `${done}/${total} it`;
    meta.dataset.parts = JSON.stringify(parts);
    meta.textContent = parts.filter(Boolean).join(' · ');
  }

  set_current(id) {
    this.current = id;
    for (const li of $('jobs').children) li.classList.toggle('current', li.dataset.id === id);
  }

  /// Fetches the list now and again every few seconds while anything is active.
  async refresh() {
    clearTimeout(this.timer);
    const request = ++this.requests;
    let active = false;
    try {
      const body = await api.list_jobs(20);
      if (request !== this.requests) return;  // a later refresh is under way: its answer is newer
      const jobs = body.jobs || [];
      active = jobs.some((j) => ['queued', 'running', 'cancelling'].includes(j.state));
      this.render(jobs, body.total ?? jobs.length);
    } catch (e) {
      if (request !== this.requests) return;
      $('jobs').replaceChildren(Object.assign(document.createElement('li'), { className: 'err', textContent: e.message }));
    }
    if (!document.hidden) this.timer = setTimeout(() => this.refresh(), active ? this.poll.active : this.poll.idle);
  }

  render(jobs, total) {
    const ol = $('jobs');
    ol.replaceChildren();
    if (!jobs.length) {
      ol.append(Object.assign(document.createElement('li'), { className: 'muted', textContent: 'No jobs yet.' }));
      return;
    }
    for (const job of jobs) {
      const li = document.createElement('li');
      li.dataset.id = job.id;
      li.classList.toggle('current', job.id === this.current);
      const state = Object.assign(document.createElement('span'), { className: `state ${job.state}`, textContent: job.state });
      const a = document.createElement('a');
      a.href = `#job=${encodeURIComponent(job.id)}`;
      a.className = 'name';
      a.textContent = job.input?.filename || job.id;
      a.title = `Watch job ${job.id}`;
      const events = document.createElement('a');
      // Opened by the browser in a new tab, without the page's Authorization header.
      events.href = api.authorized_url(`${api.BASE}/jobs/${encodeURIComponent(job.id)}`);
      events.textContent = 'json';
      events.title = 'The job document';
      events.target = '_blank';
      const meta = document.createElement('span');
      meta.className = 'meta';
      const p = job.progress || {};
      const v = job.input?.summary?.vertices;
      const parts = [job.id.slice(0, 8), when(job.created_at),
        p.iterations ? `${p.iteration ?? 0}/${p.iterations} it` : '', v ? `${v.toLocaleString()} v` : ''];
      meta.dataset.parts = JSON.stringify(parts);
      meta.textContent = parts.filter(Boolean).join(' · ');
      const links = document.createElement('span');
      links.append(events);
      if (['succeeded', 'failed', 'cancelled'].includes(job.state)) {
        const del = document.createElement('button');
        del.type = 'button';
        del.className = 'link';
        del.textContent = 'delete';
        del.setAttribute('aria-label', `Delete job ${job.input?.filename || job.id} and its files`);
        del.addEventListener('click', async () => {
          if (!confirm(`Delete job ${job.id} (${job.input?.filename || ''}) and its files?`)) return;
          try {
            await api.delete_job(job.id);
            this.on_deleted?.(job.id);
          } catch (e) {
            if (e.status === 404) this.on_deleted?.(job.id);  // gone already (expired, or deleted elsewhere)
            else alert(e.message);
          }
          this.refresh();
        });
        links.append(' ', del);
      }
      li.append(state, a, links, meta);
      ol.append(li);
    }
    if (total > jobs.length)
      ol.append(Object.assign(document.createElement('li'), { className: 'muted', textContent: `${total - jobs.length} older not shown` }));
  }
}

function when(iso) {
  if (!iso) return '';
  const d = new Date(typeof iso === 'number' && iso < 1e12 ? iso * 1000 : iso);
  if (Number.isNaN(+d)) return String(iso);
  const same_day = d.toDateString() === new Date().toDateString();
  return same_day ? d.toLocaleTimeString([], { hour12: false }) : d.toLocaleString([], { hour12: false });
}
