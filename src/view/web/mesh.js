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

export class MeshView {
  // panel: the section to fill; options: meshes (the /api/info list), colours, label(spec),
  // title(spec), swatch(b) (HTML), onError(message).
  constructor(panel, options) {
    this.o = options;
    this.size = Math.min(512, Math.round(256 * (window.devicePixelRatio || 1)));
    this.state = { mesh: options.meshes[0], light: 'point', yaw: 35, pitch: 25 };
    this.view = { specs: [], to: 45, po: 180, env: 'sky', exposure: 0 };
    this.generation = 0;
    const head = document.createElement('div');
    head.className = 'panel-head';
    head.innerHTML = '<h2>Lit mesh</h2>';
    this.meshSelect = this.select('mesh', options.meshes.map((m) => [m, m.replace(/^(file|embedded):/, '')]),
      'the embedded mesh, or a Wavefront .obj under a --root');
    this.lightSelect = this.select('light', [['point', 'point light from ωo'], ['env', 'environment']],
      'a distant light from ωo\'s direction as seen from the camera (as the point-lit spheres), or the spheres\' environment');
    head.append(this.meshSelect.parentElement, this.lightSelect.parentElement);
    this.figures = document.createElement('div');
    this.figures.id = 'meshes';
    // Side by side, wrapping within the panel (each caption under its image), as the spheres.
    Object.assign(this.figures.style, { display: 'flex', flexWrap: 'wrap', gap: '8px', maxWidth: '100%' });
    this.note = document.createElement('p');
    this.note.className = 'note';
    this.note.id = 'mesh-note';
    panel.replaceChildren(head, this.figures, this.note);
    this.meshSelect.addEventListener('change', () => { this.state.mesh = this.meshSelect.value; this.restart(); });
    this.lightSelect.addEventListener('change', () => { this.state.light = this.lightSelect.value; this.restart(); });
  }

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

  // The BRDFs shown, ωo (degrees), the environment and the exposure: restarts when one changes
  // (the exposure only draws again).
  update(view) {
    const before = this.view;
    this.view = { ...before, ...view };
    const same = before.specs.join('\n') === this.view.specs.join('\n') && before.env === this.view.env &&
      (this.state.light === 'env' || (before.to === this.view.to && before.po === this.view.po));
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
      canvas.style.width = canvas.style.height = '256px';
      canvas.dataset.spec = spec;
      Object.assign(fig.style, { margin: '0', width: '256px', textAlign: 'center' });
      const cap = document.createElement('figcaption');
      cap.style.overflowWrap = 'anywhere';  // a long spec wraps under its image
      cap.innerHTML = `${this.o.swatch(b)}&nbsp;${escape(this.o.label(spec))}`;
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
      start = { x: e.clientX, y: e.clientY, yaw: this.state.yaw, pitch: this.state.pitch };
      canvas.setPointerCapture(e.pointerId);
    });
    canvas.addEventListener('pointermove', (e) => {
      if (!start) return;
      this.state.yaw = ((start.yaw + (e.clientX - start.x) * 0.5 + 540) % 360) - 180;
      this.state.pitch = Math.max(-90, Math.min(90, start.pitch + (e.clientY - start.y) * 0.5));
      this.turning();
    });
    const end = () => { if (start) { start = null; this.restart(); } };
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
    return [['mesh', this.state.mesh], ['size', size], ['yaw', this.state.yaw.toFixed(2)], ['pitch', this.state.pitch.toFixed(2)]];
  }
  lightParams() {
    return [['light', 'point'], ['theta_l', this.view.to], ['phi_l', this.view.po]];
  }

  restart() {
    const gen = ++this.generation;
    if (!this.canvases || this.canvases.length !== this.view.specs.length ||
        this.canvases.some((c, b) => c.dataset.spec !== this.view.specs[b])) this.build();
    this.sums = this.view.specs.map(() => null);
    this.pending = (this.state.light === 'point' ? this.point(gen) : this.environment(gen))
      .catch((e) => { if (!isAbort(e)) this.o.onError(e.message); });
    return this.pending;
  }

  async point(gen) {
    const fields = await fieldsOf('mesh', '/api/mesh', this.view.specs, [...this.meshParams(this.size), ...this.lightParams()]);
    if (gen !== this.generation) return;
    fields.forEach((f, b) => { this.sums[b] = { data: Float32Array.from(f.data), passes: 1, size: this.size }; });
    this.redraw();
    this.note.textContent = `${this.label()}: a distant light from ωo (θo ${this.view.to}°, φo ${this.view.po}°), evaluated (2 × 2 positions a pixel). Direct light only: a concave mesh has no shadows.`;
  }

  async environment(gen) {
    const sums = this.view.specs.map(() => new Float32Array(this.size * this.size * 3));
    for (let pass = 0; pass < PASSES && gen === this.generation; ++pass) {
      const fields = await fieldsOf('mesh', '/api/mesh', this.view.specs,
        [...this.meshParams(this.size), ['light', 'env'], ['env', this.view.env], ['spp', 1], ['pass', pass]]);
      if (gen !== this.generation) return;
      fields.forEach((f, b) => {
        for (let k = 0; k < sums[b].length; ++k) sums[b][k] += f.data[k];
        this.sums[b] = { data: sums[b], passes: pass + 1, size: this.size };
      });
      this.redraw();
      this.note.textContent = `${this.label()} under ${this.view.env}: ${pass + 1} of ${PASSES} passes (each one sample of the BRDF and one of the environment per position, 2 × 2 positions a pixel). Direct light only: a concave mesh has no shadows.`;
      await new Promise((r) => setTimeout(r, 30));  // let the other views through
    }
  }

  label() {
    return `${this.state.mesh.replace(/^(file|embedded):/, '')} turned ${Math.round(this.state.yaw)}° (yaw), ${Math.round(this.state.pitch)}° (pitch)`;
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
