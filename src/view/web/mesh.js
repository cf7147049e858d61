// The lit mesh (docs/view.md, "Lit mesh"): a mesh (the embedded one, or an OBJ under a --root)
// rendered by the server (/api/mesh) with each BRDF shown, under the point light from ωo's
// direction (evaluated: no noise) or under the spheres' environment (passes averaged, as the
// spheres refine). Dragging on a mesh turns it (yaw, pitch); every BRDF's image comes in one
// request per update.
import { fieldsOf } from './batch.js';
import { drawSphere } from './views.js';
import { isAbort } from './api.js';

const PASSES = 32;  // environment: passes of one sample (of the BRDF and of the environment) each
const DRAG_SIZE = 96;  // while the mesh turns
// The images' side on screen (CSS pixels); they are rendered at it in device pixels (at most 512).
export const MESH_SIDES = [192, 256, 384, 512];
// The settings a page's URL holds (app.js: state), with their defaults ('': the first mesh).
export const MESH_DEFAULTS = { mesh: '', meshLight: 'point', meshYaw: 35, meshPitch: 25, meshSize: 256 };

export class MeshView {
  // panel: the section to fill; options: meshes (the /api/info list), colours, label(spec),
  // title(spec), swatch(b) (HTML), onError(message) (a request failed), settings (an object with the keys of
  // MESH_DEFAULTS, read at the start and written when the user changes one: the page's state),
  // onSettings() (called after such a change).
  constructor(panel, options) {
    this.o = options;
    this.settings = options.settings;
    this.checkSettings();
    this.view = { specs: [], colours: [], to: 45, po: 180, env: 'sky', exposure: 0 };
    this.generation = 0;
    const head = document.createElement('div');
    head.className = 'panel-head';
    head.innerHTML = '<h2>Lit mesh</h2>';
    this.meshSelect = this.select('mesh', options.meshes.map((m) => [m, m.replace(/^(file|embedded):/, '')]),
      'the embedded mesh, or a Wavefront .obj under a --root');
    this.lightSelect = this.select('light', [['point', 'point light from ωo'], ['env', 'environment']],
      'a distant light from ωo\'s direction as seen from the camera (as the point-lit spheres), or the spheres\' environment');
    this.sizeSelect = this.select('size', MESH_SIDES.map((n) => [String(n), `${n} px`]),
      'the side of each image on screen (rendered at it in device pixels, at most 512)');
    const exports = Object.assign(document.createElement('span'), { className: 'export' });
    exports.dataset.target = 'mesh';
    head.append(this.meshSelect.parentElement, this.lightSelect.parentElement, this.sizeSelect.parentElement, exports);
    this.meshSelect.value = this.settings.mesh;
    this.lightSelect.value = this.settings.meshLight;
    this.sizeSelect.value = String(this.settings.meshSize);
    this.figures = document.createElement('div');
    this.figures.id = 'meshes';
    // Side by side, wrapping within the panel (each caption under its image), as the spheres.
    Object.assign(this.figures.style, { display: 'flex', flexWrap: 'wrap', gap: '8px', maxWidth: '100%' });
    this.note = document.createElement('p');
    this.note.className = 'note';
    this.note.id = 'mesh-note';
    panel.replaceChildren(head, this.figures, this.note);
    this.meshSelect.addEventListener('change', () => this.set({ mesh: this.meshSelect.value }));
    this.lightSelect.addEventListener('change', () => this.set({ meshLight: this.lightSelect.value }));
    this.sizeSelect.addEventListener('change', () => this.set({ meshSize: Number(this.sizeSelect.value) }));
  }

  // The settings as the URL gave them, each one out of range replaced by its default and named
  // in settingsNote.
  checkSettings() {
    const s = this.settings, wrong = [];
    const fix = (key, ok, value) => {
      if (ok) return;
      wrong.push(`${key} '${s[key]}'`);
      s[key] = value;
    };
    if (s.mesh === '') s.mesh = this.o.meshes[0];
    fix('mesh', this.o.meshes.includes(s.mesh), this.o.meshes[0]);
    fix('meshLight', ['point', 'env'].includes(s.meshLight), MESH_DEFAULTS.meshLight);
    fix('meshYaw', Number.isFinite(s.meshYaw) && Math.abs(s.meshYaw) <= 180, MESH_DEFAULTS.meshYaw);
    fix('meshPitch', Number.isFinite(s.meshPitch) && Math.abs(s.meshPitch) <= 90, MESH_DEFAULTS.meshPitch);
    fix('meshSize', MESH_SIDES.includes(s.meshSize), MESH_DEFAULTS.meshSize);
    // What the page's status line says after loading (empty: all was well).
    this.settingsNote = wrong.length ? `lit mesh: ${wrong.join(', ')} not offered (meshes: ${this.o.meshes.join(', ')}; `
      + `light point or env; yaw −180…180°, pitch −90…90°; size ${MESH_SIDES.join(', ')}): the default instead` : '';
  }

  // A setting changed by the user: kept (the page writes it into the URL), the images again.
  set(values) {
    Object.assign(this.settings, values);
    this.o.onSettings();
    this.restart();
  }

  get side() { return this.settings.meshSize; }
  get size() { return Math.min(512, Math.round(this.side * (window.devicePixelRatio || 1))); }

  select(label, entries, title) {
    const l = document.createElement('label');
    l.textContent = `${label} `;
    l.title = title;
    const s = document.createElement('select');
    s.id = `mesh-${label}`;
    for (const [value, text] of entries) s.append(new Option(text, value));
    l.append(s);
    return s;
  }

  // The BRDFs shown (specs, and colours: each one's place in options.colours), ωo (degrees), the
  // environment and the exposure: restarts when one changes (the exposure only draws again).
  update(view) {
    const before = this.view;
    this.view = { ...before, ...view };
    const same = before.specs.join('\n') === this.view.specs.join('\n') &&
      before.colours.join() === this.view.colours.join() && before.env === this.view.env &&
      (this.settings.meshLight === 'env' || (before.to === this.view.to && before.po === this.view.po));
    if (same && this.canvases && this.canvases.length === this.view.specs.length) {
      if (before.exposure !== this.view.exposure) this.redraw();
      return this.pending || Promise.resolve();
    }
    return this.restart();
  }

  build() {
    this.figures.replaceChildren();
    this.canvases = this.view.specs.map((spec, b) => {
      const fig = document.createElement('figure');
      const canvas = Object.assign(document.createElement('canvas'), { id: `mesh-${b}`, title: 'drag to turn the mesh' });
      canvas.style.width = canvas.style.height = `${this.side}px`;
      canvas.dataset.spec = spec;
      Object.assign(fig.style, { margin: '0', width: `${this.side}px`, textAlign: 'center' });
      const cap = document.createElement('figcaption');
      cap.style.overflowWrap = 'anywhere';  // a long spec wraps under its image
      cap.innerHTML = `${this.o.swatch(this.view.colours[b] ?? b)}&nbsp;${escape(this.o.label(spec))}`;
      cap.title = this.o.title(spec);
      fig.append(canvas, cap);
      this.figures.append(fig);
      this.drag(canvas);
      return canvas;
    });
  }

  drag(canvas) {
    let start = null;
    canvas.addEventListener('pointerdown', (e) => {
      start = { x: e.clientX, y: e.clientY, yaw: this.settings.meshYaw, pitch: this.settings.meshPitch };
      canvas.setPointerCapture(e.pointerId);
    });
    canvas.addEventListener('pointermove', (e) => {
      if (!start) return;
      this.settings.meshYaw = Number((((start.yaw + (e.clientX - start.x) * 0.5 + 540) % 360) - 180).toFixed(2));
      this.settings.meshPitch = Number(Math.max(-90, Math.min(90, start.pitch + (e.clientY - start.y) * 0.5)).toFixed(2));
      this.turning();
    });
    const end = () => { if (start) { start = null; this.set({}); } };
    canvas.addEventListener('pointerup', end);
    canvas.addEventListener('pointercancel', end);
  }

  // While the mesh turns: the point light at a small size, one request in flight at a time.
  turning() {
    if (this.turnBusy) { this.turnAgain = true; return; }
    this.turnBusy = true;
    ++this.generation;
    const light = this.lightParams();
    fieldsOf(null, '/api/mesh', this.view.specs, [...this.meshParams(DRAG_SIZE), ...light])
      .then((fields) => fields.forEach((f, b) => this.draw(b, f.data, 1, DRAG_SIZE)))
      .catch((e) => { if (!isAbort(e)) this.o.onError(e.message); })
      .finally(() => {
        this.turnBusy = false;
        if (this.turnAgain) { this.turnAgain = false; this.turning(); }
      });
  }

  meshParams(size) {
    const s = this.settings;
    return [['mesh', s.mesh], ['size', size], ['yaw', s.meshYaw.toFixed(2)], ['pitch', s.meshPitch.toFixed(2)]];
  }
  lightParams() {
    return [['light', 'point'], ['theta_l', this.view.to], ['phi_l', this.view.po]];
  }

  restart() {
    const gen = ++this.generation;
    if (!this.canvases || this.canvases.length !== this.view.specs.length ||
        this.canvases.some((c, b) => c.dataset.spec !== this.view.specs[b] || c.style.width !== `${this.side}px`)) this.build();
    this.sums = this.view.specs.map(() => null);
    this.pending = (this.settings.meshLight === 'point' ? this.point(gen) : this.environment(gen))
      .catch((e) => { if (!isAbort(e)) this.o.onError(e.message); });
    return this.pending;
  }

  async point(gen) {
    const size = this.size;
    const fields = await fieldsOf('mesh', '/api/mesh', this.view.specs, [...this.meshParams(size), ...this.lightParams()]);
    if (gen !== this.generation) return;
    fields.forEach((f, b) => { this.sums[b] = { data: Float32Array.from(f.data), passes: 1, size }; });
    this.redraw();
    this.note.textContent = `${this.label()}: a distant light from ωo (θo ${this.view.to}°, φo ${this.view.po}°), evaluated (2 × 2 positions a pixel). Direct light only: a concave mesh has no shadows.`;
  }

  async environment(gen) {
    const size = this.size;
    const sums = this.view.specs.map(() => new Float32Array(size * size * 3));
    for (let pass = 0; pass < PASSES && gen === this.generation; ++pass) {
      const fields = await fieldsOf('mesh', '/api/mesh', this.view.specs,
        [...this.meshParams(size), ['light', 'env'], ['env', this.view.env], ['spp', 1], ['pass', pass]]);
      if (gen !== this.generation) return;
      fields.forEach((f, b) => {
        for (let k = 0; k < sums[b].length; ++k) sums[b][k] += f.data[k];
        this.sums[b] = { data: sums[b], passes: pass + 1, size };
      });
      this.redraw();
      this.note.textContent = `${this.label()} under ${this.view.env}: ${pass + 1} of ${PASSES} passes (each one sample of the BRDF and one of the environment per position, 2 × 2 positions a pixel). Direct light only: a concave mesh has no shadows.`;
      await new Promise((r) => setTimeout(r, 30));  // let the other views through
    }
  }

  label() {
    const s = this.settings;
    return `${s.mesh.replace(/^(file|embedded):/, '')} turned ${Math.round(s.meshYaw)}° (yaw), ${Math.round(s.meshPitch)}° (pitch)`;
  }

  // What a figure of the view says it shows (app.js: the export's title).
  title() {
    const light = this.settings.meshLight === 'point' ? `a point light from ωo (θo = ${Number(this.view.to).toFixed(1)}°, φo = ${Number(this.view.po).toFixed(1)}°)`
      : `the environment ${this.view.env}`;
    return `lit mesh ${this.label()}, under ${light}`;
  }

  draw(b, data, passes, size) {
    const canvas = this.canvases && this.canvases[b];
    if (!canvas) return;
    drawSphere(canvas, data, passes, size, size, this.view.exposure);
    canvas.dataset.passes = passes;
    canvas.sum = data;
  }

  redraw() {
    (this.sums || []).forEach((s, b) => { if (s) this.draw(b, s.data, s.passes, s.size); });
  }
}

function escape(text) {
  return String(text).replace(/[&<>"]/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' })[c]);
}
