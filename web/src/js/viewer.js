/// The 3D view: one indexed BufferGeometry for the surface (flat shaded) and one LineSegments for
/// all edges, sharing the position buffer. Edges are grouped short | inside | long in the index
/// buffer with one material per group, so re-colouring after an e_min/e_max change rewrites one
/// index array and nothing else. Renders on demand only (no animation loop).

import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { triangle_edges, edge_lengths, classify, length_stats, class_histogram } from './edges.js';
import { css, draw_histogram, fit_canvas, fmt } from './charts.js';

const BINS = 64;

export class Viewer {
  /// canvas: the WebGL canvas; hist: the histogram canvas; status/caption: text elements; legend:
  /// the colour legend (its class `bond` says the interval is divided by √3, for the dual).
  constructor(canvas, hist, status, caption, legend = null) {
    this.canvas = canvas;
    this.legend = legend;
    this.hist = hist;
    this.status = status;
    this.caption = caption;
    this.slots = new Map();  // name -> prepared mesh
    this.current = null;
    this.options = { surface: true, edges: true, classes: true };
    this.interval = { emin: NaN, emax: NaN };

    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: true });
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(40, 1, 0.01, 100);
    this.scene.add(this.camera);
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x444444, 1.6));
    const key = new THREE.DirectionalLight(0xffffff, 1.6);
    key.position.set(0.5, 0.8, 1);
    this.camera.add(key);  // a headlight: the lit side is always the one you look at

    this.surface_material = new THREE.MeshPhongMaterial({ flatShading: true, side: THREE.DoubleSide,
      shininess: 8, polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1 });
    this.edge_materials = [0, 1, 2].map(() => new THREE.LineBasicMaterial());
    this.apply_theme();
    matchMedia('(prefers-color-scheme: light)').addEventListener('change', () => { this.apply_theme(); this.render(); });

    this.controls = new OrbitControls(this.camera, canvas);
    this.controls.addEventListener('change', () => this.render());
    this.controls.listenToKeyEvents(canvas);  // arrow keys pan when the canvas has focus
    canvas.addEventListener('keydown', (e) => {
      if (e.key === '+' || e.key === '=') this.zoom(0.8);
      else if (e.key === '-') this.zoom(1.25);
      else return;
      e.preventDefault();
    });
    new ResizeObserver(() => this.resize()).observe(canvas);
    new ResizeObserver(() => this.draw_histogram()).observe(hist);
  }

  apply_theme() {
    this.scene.background = new THREE.Color(css('--view-bg'));
    const light = matchMedia('(prefers-color-scheme: light)').matches;
    this.surface_material.color.set(light ? 0xc9ced4 : 0x9ea7b1);
    this.inside_on_surface = new THREE.Color(light ? 0x4a525c : 0x30353c);
    this.inside_alone = new THREE.Color(css('--inside'));
    this.update_edge_colors();
  }

  update_edge_colors() {
    const [s, i, l] = this.edge_materials;
    const inside = this.options.surface ? this.inside_on_surface : this.inside_alone;
    const classes = this.options.classes && !!this.current;
    s.color.set(classes ? css('--short') : inside);
    i.color.copy(inside);
    l.color.set(classes ? css('--long') : inside);
  }

  resize() {
    const w = this.canvas.clientWidth;
    const h = this.canvas.clientHeight;
    if (!w || !h) return;
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.render();
  }

  render() { this.renderer.render(this.scene, this.camera); }

  has(name) { return this.slots.has(name); }
  forget(name) {
    const slot = this.slots.get(name);
    if (!slot) return;
    if (this.current === slot) {
      this.scene.remove(slot.group);
      this.current = null;
      this.render();
      fit_canvas(this.hist);  // clears it
      this.caption.textContent = 'Edge lengths';
      this.status.textContent = '';
    }
    slot.geometry.dispose();
    slot.edge_geometry.dispose();
    this.slots.delete(name);
  }

  /// Prepares a mesh {positions, triangles, lines?, pairs?, lengths?} under a name ('input',
  /// 'remeshed', 'dual'); `pairs`/`lengths` are the edges when already computed (mesh_worker.js).
  /// `scale`: its edges are judged against [e_min, e_max] × scale (the dual's bonds: 1/√3, as the
  /// server counts them). Polygon edges come from `lines` when given, else from the triangles.
  set_mesh(name, mesh, { scale = 1, label = name } = {}) {
    this.forget(name);
    const vertex_count = mesh.positions.length / 3;
    const position = new THREE.BufferAttribute(mesh.positions, 3);
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', position);
    geometry.setIndex(new THREE.BufferAttribute(mesh.triangles, 1));
    geometry.computeBoundingSphere();
    const pairs = mesh.pairs || (mesh.lines && mesh.lines.length ? mesh.lines : triangle_edges(mesh.triangles, vertex_count));
    const lengths = mesh.lengths || edge_lengths(mesh.positions, pairs);
    const edge_geometry = new THREE.BufferGeometry();
    edge_geometry.setAttribute('position', position);
    edge_geometry.setIndex(new THREE.BufferAttribute(new Uint32Array(pairs.length), 1));
    edge_geometry.boundingSphere = geometry.boundingSphere;
    const surface = new THREE.Mesh(geometry, this.surface_material);
    const edges = new THREE.LineSegments(edge_geometry, this.edge_materials);
    const group = new THREE.Group();
    group.add(surface, edges);
    const slot = { name, label, geometry, edge_geometry, surface, edges, group, pairs, lengths, scale,
      stats: length_stats(lengths), vertices: used_vertices(pairs, vertex_count), faces: mesh.triangles.length / 3 };
    this.slots.set(name, slot);
    this.reclassify(slot);
    return slot.stats;
  }

  /// Shows a prepared mesh; fits the view the first time anything is shown.
  show(name) {
    const slot = this.slots.get(name);
    if (!slot) return false;
    const first = !this.current;
    if (this.current) this.scene.remove(this.current.group);
    this.current = slot;
    this.scene.add(slot.group);
    this.legend?.classList.toggle('bond', slot.scale !== 1);
    this.apply_options();
    if (first || !this.fitted_radius) this.fit();
    this.update_status();
    this.draw_histogram();
    return true;
  }

  set_options(options) { Object.assign(this.options, options); this.apply_options(); }

  apply_options() {
    if (!this.current) return this.render();
    this.current.surface.visible = this.options.surface;
    this.current.edges.visible = this.options.edges;
    this.update_edge_colors();
    this.draw_histogram();
    this.render();
  }

  set_interval(emin, emax) {
    if (emin === this.interval.emin && emax === this.interval.emax) return;
    this.interval = { emin, emax };
    for (const slot of this.slots.values()) this.reclassify(slot);
    this.update_status();
    this.draw_histogram();
    this.render();
  }

  /// The interval a slot's edges are judged against.
  interval_of(slot) { return { emin: this.interval.emin * slot.scale, emax: this.interval.emax * slot.scale }; }

  reclassify(slot) {
    const { emin, emax } = this.interval_of(slot);
    const index = slot.edge_geometry.index;
    slot.counts = classify(slot.pairs, slot.lengths, emin, emax, index.array);
    index.needsUpdate = true;
    const g = slot.edge_geometry;
    g.clearGroups();
    g.addGroup(0, 2 * slot.counts.short, 0);
    g.addGroup(2 * slot.counts.short, 2 * slot.counts.inside, 1);
    g.addGroup(2 * (slot.counts.short + slot.counts.inside), 2 * slot.counts.long, 2);
  }

  /// Frames the current mesh's bounding sphere.
  fit() {
    if (!this.current) return;
    const sphere = this.current.geometry.boundingSphere;
    const r = sphere.radius || 1;
    const dist = r / Math.sin(THREE.MathUtils.degToRad(this.camera.fov / 2)) * 1.05;
    const dir = this.camera.position.clone().sub(this.controls.target);
    if (dir.lengthSq() === 0 || !this.fitted_radius) dir.set(0.4, 0.3, 1);
    dir.normalize();
    this.controls.target.copy(sphere.center);
    this.camera.position.copy(sphere.center).addScaledVector(dir, dist);
    this.camera.near = dist / 1000;
    this.camera.far = dist * 10;
    this.camera.updateProjectionMatrix();
    this.fitted_radius = r;
    this.controls.update();
    this.render();
  }

  /// Moves the camera towards (factor < 1) or away from the orbit target.
  zoom(factor) {
    const offset = this.camera.position.clone().sub(this.controls.target).multiplyScalar(factor);
    this.camera.position.copy(this.controls.target).add(offset);
    this.controls.update();
    this.render();
  }

  update_status() {
    const s = this.current;
    if (!s) return;
    const c = s.counts;
    const parts = [`${s.label}`, `${s.vertices.toLocaleString()} v`];
    if (s.scale === 1) parts.push(`${s.faces.toLocaleString()} f`);  // the dual's triangles are a fan, not its faces
    parts.push(`${s.lengths.length.toLocaleString()} e`);
    if (c.short + c.long + c.inside && this.interval.emax > this.interval.emin)
      parts.push(`${c.short.toLocaleString()} short · ${c.long.toLocaleString()} long` + (s.scale === 1 ? '' : ' (against e_min/√3, e_max/√3)'));
    this.status.textContent = parts.join(' · ');
  }

  draw_histogram() {
    const s = this.current;
    if (!s) return;
    const { emin, emax } = this.interval_of(s);
    const interval = emax > emin && emin > 0;
    const st = s.stats;
    // Up to mean + 4 deviations (a few huge edges must not squash the rest), but always past e_max;
    // from just below the shortest edge (or e_min), so the bars use the width.
    let hi = Math.min(st.max, st.mean + 4 * st.deviation);
    let lo = Math.max(0, Math.min(st.min, interval ? emin : st.min) - 0.05 * (hi - st.min));
    if (interval) hi = Math.max(hi, emax + 0.1 * (emax - lo));
    if (!(hi > lo)) { lo = 0; hi = st.max || 1; }
    const bins = interval ? aligned_bins(lo, hi, emin, emax) : { lo, hi, count: BINS };
    const hist = class_histogram(s.lengths, bins.lo, bins.hi, bins.count, interval ? emin : NaN, interval ? emax : NaN);
    this.histogram = hist;  // read by the browser test
    const scaled = s.scale === 1 ? '' : '/√3';
    draw_histogram(this.hist, hist, bins.lo, bins.hi, emin, emax, this.options.classes, scaled);
    this.caption.textContent = `Edge lengths of the ${s.label} (${st.count.toLocaleString()} edges):` +
      ` mean ${fmt(st.mean)}, deviation ${fmt(st.deviation)}, min ${fmt(st.min)}, max ${fmt(st.max)}` +
      (bins.hi < st.max ? ` (axis clipped at ${fmt(bins.hi)})` : '') +
      (scaled && interval ? `; coloured against e_min/√3 ${fmt(emin)} and e_max/√3 ${fmt(emax)}` : '');
  }
}

/// About BINS bins over [lo, hi] with e_min and e_max on bin edges, so a bar lies on one side of
/// each (the counts per class stay exact either way: class_histogram splits by the edges' class).
function aligned_bins(lo, hi, emin, emax) {
  const inside = Math.max(1, Math.round(BINS * (emax - emin) / (hi - lo)));
  const w = (emax - emin) / inside;
  const below = Math.max(0, Math.min(Math.ceil((emin - lo) / w - 1e-9), Math.floor(emin / w + 1e-9)));
  const above = Math.max(1, Math.ceil((hi - emax) / w - 1e-9));
  // An interval tiny against the spread of lengths (an input far from it) would need thousands of
  // bins: then the bins ignore it and only the split of the bars shows the classes.
  if (below + inside + above > 2 * BINS) return { lo, hi, count: BINS };
  return { lo: emin - below * w, hi: emax + above * w, count: below + inside + above };
}

/// Vertices that some edge uses (a GLB may carry positions for the fan triangulation only).
function used_vertices(pairs, vertex_count) {
  const seen = new Uint8Array(vertex_count);
  let n = 0;
  for (let i = 0; i < pairs.length; ++i) if (!seen[pairs[i]]) { seen[pairs[i]] = 1; ++n; }
  return n;
}
