// The page of `halfback view`: state (kept in the URL's fragment), the linked views and their
// requests. Views: slices of the four isotropic forms, the hemisphere of ωi, the polar plot, the
// lit sphere; a configuration (ωi, ωo) hovered or clicked in one is marked in all of them and
// listed in every parameterization (the server's numbers, the same as `halfback convert/eval`).
import { getJson, getField, getFields, isAbort } from './api.js';
import * as V from './views.js';
import { LobeView, lobeMesh } from './lobe.js';
import * as B from './batch.js';
import { MeshView, MESH_DEFAULTS } from './mesh.js';

const $ = (id) => document.getElementById(id);
const DEG = Math.PI / 180;
// One colour per BRDF shown, in the order of loaded(): the first, the compare one, the others
// (the defaults; a BRDF's chip chooses another: state.colours).
const COLOURS = ['#ff9a3c', '#3cc8ff', '#9be37a', '#e879f9', '#f7d154', '#ff6b6b', '#a0a4ff', '#5eead4'];
const palette = () => COLOURS.map((c, b) => (/^#[0-9a-f]{6}$/i.test(state.colours[b] || '') ? state.colours[b] : c));
// The swatches (class swatch-N) take their colour from the CSS variables --cN.
function applyPalette() {
  palette().forEach((c, b) => document.documentElement.style.setProperty(`--c${b}`, c));
}
const MAX_MORE = COLOURS.length - 1;  // BRDFs added beside the first (with the compare one: 8 in all)
const DRAG = 128;  // slice resolution (at most) while dragging; at rest: the side on screen
// The layout grows with the window: the panels of the views are `viewSize()` CSS pixels wide or
// more (0.3 of the window, 330 … 760 px; as many in a row as fit, then they wrap), and each view
// takes its panel's width.
const viewSize = () => Math.round(Math.max(330, Math.min(760, 0.3 * window.innerWidth)));
// The slices' side on screen (CSS pixels), growing with the window: for one BRDF as large as the
// panel allows with at least 0.55 of a view (240 px or more) each; for several (a row each)
// half a view (200 px or more), so that the rows stay short. They wrap. Their resolution at
// rest is that side in device pixels (at most 512).
let sliceSide = 256;
const fullSide = () => Math.min(512, Math.round(sliceSide * (window.devicePixelRatio || 1)));
function fitSliceSide(rows = 1) {
  const available = ($('slices').clientWidth || 1200) - (rows > 1 ? 24 : 0), axes = 48 + 12;  // axes and the gap
  const forms = info ? info.forms.length : 4;
  if (rows > 1) return Math.min(480, Math.max(200, Math.round(0.5 * viewSize())), Math.floor(available + 12 - axes - 4));
  const least = Math.max(240, Math.round(0.55 * viewSize()));
  const columns = Math.max(1, Math.min(forms, Math.floor((available + 12) / (least + axes))));
  return Math.max(128, Math.min(480, Math.floor((available + 12) / columns) - axes - 4));
}
// While a slider moves, the slices' side adapts (64 … 128): smaller when an update (request and
// drawing) took longer than 45 ms, larger again below 25 ms.
let dragSide = DRAG;
function adaptDragSide(ms) {
  if (ms > 45) dragSide = Math.max(64, dragSide - 32);
  else if (ms < 25) dragSide = Math.min(DRAG, dragSide + 32);
}

const state = {
  a: '', b: '', mode: 'a', az: 0, scale: 'log', levels: 'auto', to: 45, po: 180,
  hemi: 'rho', env: 'sky', exposure: 0, polar: 'linear', pose: 0, lobe: 'rho', lobeScale: 'linear',
  more: [],  // further BRDFs, drawn in every view
  hide: [],  // the BRDFs hidden (their specs): kept, not drawn
  colours: [],  // a colour chosen per place in loaded() ('' or absent: COLOURS)
  polarY: 'rho', theta: 'rho', thetaScale: 'log', lobeOpacity: 0.55, lobeZoom: 1,
  ...MESH_DEFAULTS,  // the lit mesh's: mesh, meshLight, meshYaw, meshPitch, meshSize (mesh.js)
};
const MODES = { b: 'the second', diff: 'the difference', ratio: 'the ratio' };
let info = null;
let cursor = null;      // the last /api/point answer
let pinned = false;
let interactive = false;  // while dragging: lower resolution
let refineTimer = 0;
// The views drawn at a drag's lower resolution, or left as they were (the lobe, the point-lit
// spheres and the mesh follow ωo at rest only), since the last rest: what the rest refines. A
// drag of ωo leaves the slices alone (they do not depend on it), a move of the azimuth slider
// everything but the slices.
const coarse = new Set();
let sphereStale = false;  // the sphere waits for the end of a slider's drag
const pending = new Set();
const stats = { updates: 0, lastUpdateMs: 0, sliceDraws: 0 };

// --- state <-> URL ------------------------------------------------------------------------
// Whether the fragment names BRDFs (else the command line's are shown).
function readHash() {
  const h = new URLSearchParams(location.hash.slice(1));
  const named = ['a', 'b', 'more'].some((k) => h.has(k));
  for (const k of Object.keys(state)) {
    if (!h.has(k)) continue;
    if (k === 'colours') state[k] = h.getAll(k).slice(0, COLOURS.length);
    else if (Array.isArray(state[k])) state[k] = h.getAll(k).filter(Boolean).slice(0, k === 'hide' ? COLOURS.length : MAX_MORE);
    else state[k] = typeof state[k] === 'number' ? Number(h.get(k)) : h.get(k);
  }
  return named;
}
// At most ten writes a second (the last one always made): a moving slider sends ~60 input events
// a second, and Chromium throttles history.replaceState (each one a message to the browser).
let hashTimer = 0, lastHashWrite = -Infinity;
function writeHash() {
  clearTimeout(hashTimer);
  const wait = lastHashWrite + 100 - performance.now();
  if (wait > 0) {
    hashTimer = setTimeout(writeHash, wait);
    return;
  }
  lastHashWrite = performance.now();
  const h = new URLSearchParams();
  for (const [k, v] of Object.entries(state)) {
    if (Array.isArray(v)) v.forEach((x) => h.append(k, x));
    else h.set(k, String(v));
  }
  history.replaceState(null, '', `${location.pathname}${location.search}#${h}`);
}

function setStatus(text, error = false) {
  $('status').textContent = text;
  $('status').className = error ? 'error' : '';
}

// Tracks a view update; failures other than cancellations are shown in the status line.
function track(promise) {
  const started = performance.now();
  const p = promise.then(() => {
    stats.updates += 1;
    stats.lastUpdateMs = performance.now() - started;
  }).catch((e) => {
    if (!isAbort(e)) setStatus(e.message, true);
  }).finally(() => pending.delete(p));
  pending.add(p);
  return p;
}
// At most one update of a kind in flight and one waiting: while a slider moves, a newer value
// replaces the waiting update (only the latest matters), and the one in flight is not cancelled,
// so that a continuous drag shows a picture every round trip. `run` reads the state when it
// starts; every caller's promise settles when a run that started after its call has finished.
function coalesced(run) {
  let running = null, waiting = null;
  const schedule = () => {
    if (!running) {
      running = run().finally(() => {
        running = null;
        if (!waiting) return;
        const w = waiting;
        waiting = null;
        w.resolve(schedule());
      });
      return running;
    }
    if (!waiting) {
      waiting = {};
      waiting.promise = new Promise((resolve) => { waiting.resolve = resolve; });
    }
    return waiting.promise;
  };
  return schedule;
}
async function idle() {
  while (pending.size) await Promise.allSettled([...pending]);
}
const spheres = new Set();  // the progressive renders, apart: they run for seconds
// Resolves when the progressive renders have ended or every sphere has drawn `passes` passes
// (a layout test needs one), or after `seconds`; gives the fewest passes drawn.
async function spheresDone(passes = PASSES, seconds = Infinity) {
  const canvases = () => [...document.querySelectorAll('#spheres canvas[id^="sphere-"]')];
  const fewest = () => Math.min(PASSES, ...canvases().map((c) => Number(c.dataset.passes || 0)));
  const end = performance.now() + 1000 * seconds;
  while (spheres.size && fewest() < passes && performance.now() < end)
    await Promise.race([...spheres, new Promise((r) => setTimeout(r, 100))]);
  return fewest();
}
// Ends the progressive renders at the pass they are at (a measurement of the other views wants
// the cores to itself); resolves when their last request has returned.
async function stopSpheres() {
  ++sphereGeneration;
  await Promise.allSettled([...spheres]);
}
window.halfback = { addBrdf, state, stats, idle, spheresDone, stopSpheres, cursor: () => cursor, lobe: () => lobeData,
  albedo: () => albedoCurves, polar: () => polarCurves, theta: () => thetaAxis };

// What the slices and the hemisphere show: the pair (second, difference, ratio), or every BRDF
// shown (the hemisphere: the first of them).
const pairMode = () => Boolean(state.b) && state.mode !== 'a';
const specs = () => (pairMode() ? [state.a, state.b] : [visible()[0]?.spec || state.a]);
const formInfo = (space) => info.forms.find((f) => f.space === space);
// Every BRDF loaded (at most one per colour); its place in this list is its colour.
const loaded = () => [state.a, state.b, ...state.more].filter(Boolean).slice(0, COLOURS.length);
// The BRDFs drawn: those loaded and not hidden, each { spec, b } with b its colour's place.
const visible = () => loaded().map((spec, b) => ({ spec, b })).filter((v) => !state.hide.includes(v.spec));
// style.css has the classes swatch-0 … swatch-7 in COLOURS (the page's policy forbids inline styles).
const swatch = (b) => `<span class="swatch-${b}">■</span>`;

// --- slices ---------------------------------------------------------------------------------
// One row of slices per BRDF shown, in its colour (the same colour scale for all), or one row of
// the pair's second, difference or ratio. sliceRows[r][space] is a canvas.
let sliceRows = [];
let builtKey = '';  // the rows built: sliceKey() when they were built
const sliceKey = () => (pairMode() ? 'pair' : visible().map((v) => `${v.b}:${v.spec}`).join('|'));
// The BRDFs one /api/slices request may ask at n pixels a side: as many as the server's bounds
// allow (BRDFs a request, bytes an answer) within SLICES_REQUEST_BYTES; more are asked in requests
// side by side. While a slider moves (n ≤ 128) that is every BRDF shown; at rest (n = 256) four.
// The server drops a response not read within its deadline (kResponseWriteSeconds): the smaller
// the answers, the less a loaded browser risks it.
const SLICES_REQUEST_BYTES = 8 << 20;
const sliceBatch = (n) => {
  const limits = (info && info.limits) || {};
  const perBrdf = info.forms.length * n * n * 4;  // luminance: one float a pixel
  const bytes = Math.min(limits.slices_bytes || perBrdf, SLICES_REQUEST_BYTES);
  return Math.max(1, Math.min(limits.brdfs || 1, Math.floor(bytes / perBrdf)));
};
function buildSlices() {
  const box = $('slices');
  box.replaceChildren();
  const rows = pairMode() ? [null] : visible();
  sliceSide = fitSliceSide(rows.length);
  builtKey = sliceKey();
  sliceRows = rows.map((row, r) => {
    const group = Object.assign(document.createElement('div'), { className: 'slice-group' });
    if (row) {
      const name = Object.assign(document.createElement('div'), { className: 'row-name', title: fullSpec(row.spec) });
      name.innerHTML = `${swatch(row.b)} ${escapeHtml(specLabel(row.spec))}`;
      group.append(name);
    }
    const line = Object.assign(document.createElement('div'), { className: 'slice-row' });
    const canvases = {};
    for (const f of info.forms) {
      const div = document.createElement('div');
      div.className = 'slice';
      const canvas = document.createElement('canvas');
      canvas.id = r ? `slice-${f.space}-${r}` : `slice-${f.space}`;
      canvas.dataset.space = f.space;
      canvas.dataset.row = r;
      canvas.style.width = canvas.style.height = `${sliceSide}px`;
      const plot = Object.assign(document.createElement('div'), { className: 'plot' });
      plot.append(V.sliceAxes(f.axes, [plain(f.axes[0].label), plain(f.axes[1].label)], sliceSide), canvas);
      div.append(Object.assign(document.createElement('h2'), { textContent: f.space, title: f.summary }), plot,
        Object.assign(document.createElement('span'), {
          className: 'axis',
          textContent: `at the relative azimuth ${plain(f.azimuth_label)}`,
        }));
      line.append(div);
      canvases[f.space] = canvas;
      canvas.addEventListener('mousemove', (e) => pointerOnSlice(e, f, false));
      canvas.addEventListener('click', (e) => pointerOnSlice(e, f, true));
    }
    group.append(line);
    box.append(group);
    return canvases;
  });
}
// A window resized: every view of the size that fits, drawn again.
let resizeTimer = 0;
window.addEventListener('resize', () => {
  clearTimeout(resizeTimer);
  resizeTimer = setTimeout(() => { if (info) layout(); }, 200);
});
const plain = (label) => label.replace(/_/g, '').replace(/[{}]/g, '');

let sliceFields = {};  // { key: sliceKey() of the request, perForm: { space: [field per row BRDF] } }
// The forms' slices of every BRDF of the rows (or of the pair): one /api/slices request, or
// several side by side when the answer would exceed the server's bound.
const updateSlices = coalesced(async () => {
  if (builtKey !== sliceKey()) buildSlices();
  const key = builtKey, list = pairMode() ? [state.a, state.b] : visible().map((v) => v.spec);
  const moving = interactive, n = moving ? dragSide : fullSide();
  if (moving) coarse.add('slices');
  const t0 = performance.now();
  const batches = [];
  const batch = sliceBatch(n);
  for (let k = 0; k < list.length; k += batch) batches.push(list.slice(k, k + batch));
  const answers = await Promise.all(batches.map((group) => getFields(null, '/api/slices',
    [...group.map((s) => ['brdf', s]), ['azimuth', state.az], ['pose', state.pose], ['n', n], ['values', 'luminance']])));
  if (!answers.length) return;
  const forms = answers[0].headers.get('X-Halfback-Forms').split(',');
  const fields = answers.flatMap((a) => a.fields);
  sliceFields = { key, perForm: {} };
  forms.forEach((space, f) => { sliceFields.perForm[space] = list.map((_, b) => fields[b * forms.length + f]); });
  const t1 = performance.now();
  drawSlices();
  stats.sliceFetchMs = t1 - t0;  // the request (server and transfer)
  stats.sliceDrawMs = performance.now() - t1;  // colours, isolines, markers
  stats.sliceDraws += 1;
  stats.sliceSide = n;
  if (moving) adaptDragSide(performance.now() - t0);
});
function drawSlices() {
  if (!sliceFields.perForm || sliceFields.key !== builtKey) return;  // the rows changed: a new update comes
  const pair = sliceFields.key === 'pair', mode = pair ? state.mode : 'a';
  const scalars = sliceRows.map((_, r) => {
    const out = {};
    for (const f of info.forms) {
      const fields = sliceFields.perForm[f.space];
      if (!fields) return null;
      out[f.space] = pair ? V.sliceScalar(fields[0], fields[1], mode) : V.luminanceOf(fields[r]);
    }
    return out;
  });
  if (scalars.some((x) => !x)) return;
  const scale = V.makeScale(scalars.flatMap((x) => Object.values(x)), mode, state.scale);
  const levels = V.isoLevels(state.levels, scale);
  sliceRows.forEach((canvases, r) => {
    for (const f of info.forms) {
      const field = sliceFields.perForm[f.space][pair ? 0 : r];
      V.drawScalar(canvases[f.space], scalars[r][f.space], field.width, field.height, scale, levels);
    }
  });
  drawColourbar(scale);
  markSlices();
}
function drawColourbar(scale) {
  $('colorbar').replaceChildren(V.colourbarSvg(scale, `${scaleUnit(scale)}; hatched: outside the valid domain`, 320));
}
// What a colour scale's ticks are, in words (the ticks are values of it, not of a transform).
function scaleUnit(scale, name = '') {
  const names = () => [specLabel(state.a), specLabel(state.b)];
  if (scale.mode === 'ratio') return `ratio of luminances, ${names()[0]} / ${names()[1]} (log scale)`;
  if (scale.mode === 'diff') {
    return `difference of luminances, ${names()[0]} − ${names()[1]} (sr⁻¹${scale.kind === 'log' ? ', log scale beyond ±' + V.shortNumber(scale.eps) : ''})`;
  }
  return `luminance of ρ${name ? ` of ${name}` : ''} (sr⁻¹${scale.kind === 'log' ? ', log scale' : ''})`;
}

function pointerOnSlice(e, f, click) {
  if (pinned && !click) return;
  const r = e.target.getBoundingClientRect();
  const x = (e.clientX - r.left) / r.width, y = 1 - (e.clientY - r.top) / r.height;
  const coords = [x * f.axes[0].max, y * f.axes[1].max, state.az * DEG];
  if (click) pinned = !pinned;
  setCursor([['form', f.space], ['iso', 1], ['coords', coords.join(',')]]);
}

// --- hemisphere -------------------------------------------------------------------------------
const wo = () => [Math.sin(state.to * DEG) * Math.cos(state.po * DEG),
  Math.sin(state.to * DEG) * Math.sin(state.po * DEG), Math.cos(state.to * DEG)];
let hemiField = null;
let hemiBarKey = '';  // what the hemisphere's colour bar shows: its range and unit
// The hemisphere's side on screen (CSS pixels): its panel's width (at most 640); at rest its
// resolution is that side in device pixels (at most 512).
let hemiSide = 256;
const HEMI_MARGIN = 20;  // room for the φ labels around the disk
const hemiN = () => Math.min(512, Math.round(hemiSide * (window.devicePixelRatio || 1)));
// The θ circles (every 30°) and φ lines (every 45°) over the disk, labelled: SVG, so that they
// export as they are; the equal-area radius of θ is √2 sin(θ/2).
function drawHemiMarks() {
  const svg = $('hemi-marks'), m = HEMI_MARGIN, R = hemiSide / 2, c = m + R, size = hemiSide + 2 * m;
  svg.replaceChildren();
  for (const [k, v] of Object.entries({ width: size, height: size, viewBox: `0 0 ${size} ${size}` })) svg.setAttribute(k, v);
  const add = (name, attrs, content) => {
    const e = document.createElementNS('http://www.w3.org/2000/svg', name);
    for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
    if (content !== undefined) e.textContent = content;
    svg.append(e);
    return e;
  };
  const line = { stroke: '#ffffff', 'stroke-opacity': 0.35, 'stroke-width': 1, fill: 'none' };
  for (const t of [30, 60]) add('circle', { cx: c, cy: c, r: R * Math.SQRT2 * Math.sin(t * DEG / 2), ...line, class: 'theta-mark', 'data-theta': t });
  for (let p = 0; p < 360; p += 45) {
    add('line', { x1: c, y1: c, x2: c + R * Math.cos(p * DEG), y2: c - R * Math.sin(p * DEG), ...line, class: 'phi-mark', 'data-phi': p });
    add('text', { x: c + (R + 11) * Math.cos(p * DEG), y: c - (R + 11) * Math.sin(p * DEG) + 4, fill: '#9a9cab', 'font-size': 10,
      'font-family': 'system-ui, sans-serif', 'text-anchor': 'middle', class: 'phi-label' }, `${p}°`);
  }
  for (const t of [30, 60, 90]) {  // along φ = 112.5°, between two lines
    const r = R * Math.SQRT2 * Math.sin(t * DEG / 2) - 3, a = 112.5 * DEG;
    add('text', { x: c + r * Math.cos(a), y: c - r * Math.sin(a), fill: '#ffffff', 'fill-opacity': 0.75, 'font-size': 10,
      'font-family': 'system-ui, sans-serif', 'text-anchor': 'middle', class: 'theta-label' }, `θ ${t}°`);
  }
}
const updateHemisphere = coalesced(async () => {
  const n = interactive ? DRAG : hemiN();
  if (interactive) coarse.add('hemisphere');
  const common = [['theta_o', state.to], ['phi_o', state.po], ['n', n]];
  const t0 = performance.now();
  if (state.hemi === 'rho') {
    const fields = await B.fieldsOf(null, '/api/hemisphere', specs(),
      [['colour', 'rho'], ['values', 'luminance'], ...common]);
    hemiField = { rho: fields };
  } else {
    hemiField = { coords: await getField(null, '/api/hemisphere', [['colour', state.hemi], ...common]) };
  }
  const t1 = performance.now();
  drawHemisphere();
  stats.hemiFetchMs = t1 - t0;  // the request (server and transfer), in the page's clock
  stats.hemiDrawMs = performance.now() - t1;
});
function drawHemisphere() {
  const canvas = $('hemisphere');
  if (!hemiField) return;
  if (hemiField.rho) {
    const [a, b] = hemiField.rho;
    const mode = b ? state.mode : 'a';
    const s = Float32Array.from(V.sliceScalar(a, b, mode));
    for (let k = 0; k < s.length; ++k) if (!Number.isFinite(a.data[a.channels * k])) s[k] = NaN;
    const scale = V.makeScale([s], mode, 'log');
    V.drawScalar(canvas, s, a.width, a.height, scale, []);
    blackOutside(canvas);
    // The colour bar again only when its range or unit changed (not at every step of a drag
    // that leaves them).
    const unit = scaleUnit(scale, specLabel(specs()[0])), key = `${scale.lo} ${scale.hi} ${scale.eps} ${unit}`;
    if (hemiBarKey !== key) {
      hemiBarKey = key;
      $('hemi-colorbar').replaceChildren(V.colourbarSvg(scale, unit));
    }
  } else {
    const axes = formInfo(state.hemi).axes;
    V.drawCoordinates(canvas, hemiField.coords, axes);
    hemiBarKey = '';
    $('hemi-colorbar').textContent = `red: ${plain(axes[0].label)} / its maximum, green: ${plain(axes[1].label)} / its maximum; black: outside the domain`;
  }
  const o = wo();
  const p = V.diskPoint(o), m = V.diskPoint([-o[0], -o[1], o[2]]);
  V.drawMarker(canvas, (p[0] + 1) / 2, (p[1] + 1) / 2, true, 'cross');
  V.drawMarker(canvas, (m[0] + 1) / 2, (m[1] + 1) / 2, false);
  showNumber($('theta-o'), state.to.toFixed(1));
  showNumber($('phi-o'), state.po.toFixed(1));
  markHemisphere();
}
// A number field shows the state unless the user is typing in it.
function showNumber(input, text) {
  if (document.activeElement !== input) input.value = text;
}
// A typed angle in [lo, hi] degrees, or null after saying in the status line what is wrong.
function typedAngle(input, name, lo, hi) {
  const typed = input.value.trim();
  const v = typed === '' ? NaN : Number(typed);
  if (Number.isFinite(v) && v >= lo && v <= hi) return v;
  setStatus(`${name} must be a number of degrees in [${lo}, ${hi}], ${typed === '' ? 'not empty' : `not '${typed}'`}`, true);
  return null;
}
function setupTypedAngles() {
  const typedWo = (key, id, name, lo, hi) => $(id).addEventListener('change', (e) => {
    const v = typedAngle(e.target, name, lo, hi);
    if (v === null) { e.target.value = state[key].toFixed(1); return undefined; }  // as it was
    setStatus('ready');
    state[key] = v;
    return changed({ slices: false, sphere: false });
  });
  typedWo('to', 'theta-o', 'θo', 0, 89.9);
  typedWo('po', 'phi-o', 'φo', 0, 360);
  $('azimuth-value').addEventListener('change', (e) => {
    const v = typedAngle(e.target, 'the relative azimuth', 0, 360);
    if (v === null) { e.target.value = state.az; return; }
    setStatus('ready');
    setAzimuth(v);
    refineSoon();
  });
}
function blackOutside(canvas) {  // the corners outside the disk
  const ctx = canvas.getContext('2d'), w = canvas.width;
  ctx.save();
  ctx.fillStyle = '#000';
  ctx.beginPath();
  ctx.rect(0, 0, w, w);
  ctx.arc(w / 2, w / 2, w / 2, 0, 2 * Math.PI, true);
  ctx.fill('evenodd');
  ctx.restore();
}
function diskFromEvent(e) {
  const r = $('hemisphere').getBoundingClientRect();
  return [2 * (e.clientX - r.left) / r.width - 1, 1 - 2 * (e.clientY - r.top) / r.height];
}
// A press on the hemisphere becomes a drag (ωo follows the pointer, anywhere in the window) once
// the pointer has moved 4 px; a press released before that is a click: it pins the hovered ωi
// and leaves ωo where it was.
let dragging = false, press = null, dragged = false;
const DRAG_START = 4;
function setupHemisphere() {
  const c = $('hemisphere');
  c.addEventListener('mousedown', (e) => {
    if (e.button !== 0) return;
    press = [e.clientX, e.clientY];
    dragged = false;
    e.preventDefault();  // no text selection while dragging
    document.activeElement?.blur();  // a typed θo or φo is done (its field shows the drag)
  });
  window.addEventListener('mousemove', (e) => {
    if (!press) return;
    if (!dragging && Math.hypot(e.clientX - press[0], e.clientY - press[1]) < DRAG_START) return;
    dragging = dragged = true;
    moveWo(e);
  });
  window.addEventListener('mouseup', () => {
    press = null;
    if (!dragging) return;
    dragging = false;
    refineSoon();
  });
  c.addEventListener('mousemove', (e) => { if (!press && !pinned) hoverWi(e); });
  c.addEventListener('click', (e) => {
    if (dragged) { dragged = false; return; }  // the end of a drag
    pinned = !pinned;
    hoverWi(e);
  });
}
// ωo at the pointer; a pointer outside the disk puts it on the rim (θo = 89.9°) in its direction.
function moveWo(e) {
  let [u, v] = diskFromEvent(e);
  const r = Math.hypot(u, v);
  if (!(r <= 1)) { u /= r; v /= r; }
  const d = V.diskDirection(u, v);
  if (!d) return;
  state.to = Math.min(89.9, Math.acos(Math.min(1, d[2])) / DEG);
  state.po = ((Math.atan2(d[1], d[0]) / DEG) + 360) % 360;
  interactive = true;
  changed({ slices: false, sphere: false });
}
function hoverWi(e) {
  const [u, v] = diskFromEvent(e);
  const d = V.diskDirection(u, v);
  if (!d) return;
  setCursor([['wi', d.join(',')], ['wo', wo().join(',')]]);
}

// --- 3D lobe --------------------------------------------------------------------------------
let lobe = null;
let lobeData = [];  // per BRDF loaded: the lobeMesh drawn (for the test's read-back)
const LOBE_N = 96;
let lobeShown = [];  // the { spec, b } of each surface
const updateLobe = coalesced(async () => {
  if (!lobe || !lobe.available) return;
  const list = visible();
  const fields = await B.fieldsOf(null, '/api/hemisphere', list.map((v) => v.spec),
    [['colour', 'rho'], ['values', 'luminance'], ['theta_o', state.to], ['phi_o', state.po], ['n', LOBE_N]]);
  const options = { cosine: state.lobe === 'cos', log: state.lobeScale === 'log' };
  // One radius scale for all: the largest value of any BRDF shown is 1.
  const meshes = fields.map((f) => lobeMesh(f, options));
  const max = Math.max(0, ...meshes.map((m) => m.max));
  lobeData = fields.map((f) => lobeMesh(f, { ...options, max }));
  lobeShown = list;
  drawLobe();
});
// The surfaces in their colours, see-through at the chosen opacity (each shows through the
// others), and the legend: the BRDFs and what the rings on the ground mean.
function drawLobe() {
  if (!lobe || !lobe.available) return;
  lobe.opacity = state.lobeOpacity;
  lobe.zoom = state.lobeZoom;
  lobe.set(lobeData.map((mesh, k) => ({ mesh, colour: hexColour(palette()[lobeShown[k].b]) })), wo());
  const max = lobeData.length ? lobeData[0].max : 0, what = state.lobe === 'cos' ? 'ρ cos θi' : 'ρ';
  const ring = (r) => V.shortNumber(Number((state.lobeScale === 'log' ? max * 10 ** (3 * (r - 1)) : r * max).toPrecision(2)));
  const names = lobeShown.map((v) => `<span title="${escapeHtml(fullSpec(v.spec))}">${swatch(v.b)}&nbsp;${escapeHtml(specLabel(v.spec))}</span>`);
  $('lobe-note').textContent = 'Each ωi pushed out by the radius below (one scale for every BRDF); grey: the normal; red: ωo; white: its mirror direction. Drag to turn.';
  $('lobe-legend').innerHTML = `${names.join(' ')}<br>Radius: ${what} over its largest value shown, ${escapeHtml(ring(1))} sr⁻¹`
    + `${state.lobeScale === 'log' ? ' (3 decades)' : ''}; rings on the ground at radius ½ (${escapeHtml(ring(0.5))}) and 1 (${escapeHtml(ring(1))}).`;
  window.halfback.lobeScale = { max, half: ring(0.5), one: ring(1) };
}
const hexColour = (hex) => [1, 3, 5].map((k) => parseInt(hex.slice(k, k + 2), 16) / 255);
function setupLobe() {
  lobe = new LobeView($('lobe'));
  if (!lobe.available) $('lobe-note').textContent = 'This browser has no WebGL 2: no 3D lobe.';
  $('lobe-radius').addEventListener('change', (e) => { state.lobe = e.target.value; writeHash(); track(updateLobe()); });
  $('lobe-scale').addEventListener('change', (e) => { state.lobeScale = e.target.value; writeHash(); track(updateLobe()); });
  $('lobe-opacity').addEventListener('input', (e) => { state.lobeOpacity = Number(e.target.value); writeHash(); drawLobe(); });
  $('lobe-zoom').addEventListener('input', (e) => { state.lobeZoom = Number(e.target.value); writeHash(); drawLobe(); });
  $('lobe-radius').value = state.lobe;
  $('lobe-scale').value = state.lobeScale;
  $('lobe-opacity').value = state.lobeOpacity;
  $('lobe-zoom').value = state.lobeZoom;
}

// --- albedo plot ------------------------------------------------------------------------------
let albedoCurves = [];  // per BRDF loaded: the /api/albedo answer
let albedoShown = [];  // the { spec, b } of each curve
const updateAlbedo = coalesced(async () => {
  const list = visible();
  albedoCurves = await B.albedoCurves('albedo', list.map((v) => v.spec), [['n', 64]]);
  albedoShown = list;
  drawAlbedo();
});
function drawAlbedo() {
  const list = albedoShown, w = plotWidth('albedo-panel');
  V.drawAlbedo($('albedo'), albedoCurves, list.map((v) => palette()[v.b]), list.map((v) => specLabel(v.spec)),
    list.map((v) => fullSpec(v.spec)), w, Math.round(0.6 * w));
}

// --- polar plot ------------------------------------------------------------------------------
let polarCurves = [], polarShown = [], polarThetaO = 45;
// The polar plot and the plot against θi draw the same curves (/api/polar, one request a BRDF).
const updatePolar = coalesced(async () => {
  const list = visible(), thetaO = state.to;
  if (interactive) coarse.add('polar');
  const t0 = performance.now();
  polarCurves = await B.polarCurves(null, list.map((v) => v.spec),
    [['theta_o', thetaO], ['phi_o', state.po], ['n', interactive ? 91 : 181]]);
  polarShown = list;
  polarThetaO = thetaO;
  const t1 = performance.now();
  drawPolar();
  stats.polarFetchMs = t1 - t0;
  stats.polarDrawMs = performance.now() - t1;
});
function drawPolar() {
  const list = polarShown, colours = list.map((v) => palette()[v.b]);
  const names = list.map((v) => specLabel(v.spec)), titles = list.map((v) => fullSpec(v.spec));
  V.drawPolar($('polar'), polarCurves, state.polar, colours, polarCursorAngle(), names, titles,
    { quantity: state.polarY, thetaO: polarThetaO, width: plotWidth('polar-panel') });
  const w = plotWidth('theta-panel');
  thetaAxis = V.drawTheta($('theta'), polarCurves, colours, names, titles,
    { quantity: state.theta, scale: state.thetaScale, thetaO: polarThetaO, width: w, height: Math.round(0.6 * w), cursor: polarCursorAngle() });
}
let thetaAxis = null;  // what drawTheta drew: its y range and ticks (the test reads them)
// A plot's width: its panel's, within the panel's padding (at most 900 CSS pixels).
function plotWidth(panel) {
  const p = $(panel), style = getComputedStyle(p);
  const inner = p.clientWidth - parseFloat(style.paddingLeft) - parseFloat(style.paddingRight);
  return Math.max(240, Math.min(900, Math.floor(inner || 460)));
}
function setupPolar() {
  const svg = $('polar');
  const pick = (e, click) => {
    if (pinned && !click) return;
    const r = svg.getBoundingClientRect();
    const vb = svg.viewBox.baseVal;  // its height grows with the legend below the plot
    const x = vb.x + vb.width * (e.clientX - r.left) / r.width, y = vb.y + vb.height * (e.clientY - r.top) / r.height;
    if (y > 0) return;
    const t = Math.atan2(x, -y);
    if (Math.abs(t) > Math.PI / 2) return;
    if (click) pinned = !pinned;
    const o = wo(), s = Math.hypot(o[0], o[1]);
    const c = s > 0 ? [-o[0] / s, -o[1] / s] : [1, 0];
    setCursor([['wi', [Math.sin(t) * c[0], Math.sin(t) * c[1], Math.cos(t)].join(',')], ['wo', o.join(',')]]);
  };
  svg.addEventListener('mousemove', (e) => pick(e, false));
  svg.addEventListener('click', (e) => pick(e, true));
}

// --- sphere ----------------------------------------------------------------------------------
let sphereGeneration = 0;
// The spheres are rendered at their size on screen (0.6 of a view, 256 … 420 CSS pixels: it grows
// with the window) in device pixels: sharp.
let sphereSide = 256, SPHERE = 256;
const PASSES = 32, SPP = 4;
const fitSphereSide = () => Math.max(256, Math.min(420, Math.round(0.6 * viewSize())));
function restartSphere() {
  const gen = ++sphereGeneration;
  const box = $('spheres');
  box.replaceChildren();
  sphereSide = fitSphereSide();
  SPHERE = Math.min(512, Math.round(sphereSide * (window.devicePixelRatio || 1)));
  visible().forEach(({ spec: s, b }) => {
    const fig = document.createElement('figure');
    const canvas = document.createElement('canvas');
    canvas.id = `sphere-${b}`;
    fig.style.width = `${sphereSide}px`;
    canvas.style.width = canvas.style.height = `${sphereSide}px`;
    const cap = document.createElement('figcaption');
    cap.innerHTML = `${swatch(b)}&nbsp;${escapeHtml(specLabel(s))}, the environment`;
    cap.title = fullSpec(s);
    fig.append(canvas, cap);
    box.append(fig, pointLightFigure(s, b));
    const p = sphereLoop(gen, s, b, canvas).catch((e) => { if (!isAbort(e)) setStatus(e.message, true); })
      .finally(() => spheres.delete(p));
    spheres.add(p);
  });
  track(updatePointLights());
}
async function sphereLoop(gen, spec, b, canvas) {
  const sum = new Float32Array(SPHERE * SPHERE * 3);
  for (let pass = 0; pass < PASSES && gen === sphereGeneration; ++pass) {
    const f = await getField(`sphere-${b}`, '/api/render',
      [['brdf', spec], ['env', state.env], ['size', SPHERE], ['spp', SPP], ['pass', pass]]);
    if (gen !== sphereGeneration) return;
    for (let k = 0; k < sum.length; ++k) sum[k] += f.data[k];
    canvas.dataset.passes = pass + 1;
    canvas.sum = sum;
    // The render's row 0 is the top: draw as it is (no flip).
    V.drawSphere(canvas, sum, pass + 1, SPHERE, SPHERE, state.exposure);
    $('sphere-note').textContent = `${(pass + 1) * SPP} samples per pixel (${pass + 1} of ${PASSES} passes)`;
    if (pass === 0) await idleFrame();  // let the other views through first
  }
}
// Beside each environment-lit sphere, the same sphere under one distant light from ωo's
// direction as seen from the camera (θo from the view axis, φo from the right): evaluated, not
// sampled (/api/pointlight), drawn again when ωo moves (at rest).
function pointLightFigure(spec, b) {
  const fig = document.createElement('figure');
  const canvas = Object.assign(document.createElement('canvas'), { id: `pointlight-${b}` });
  canvas.dataset.spec = spec;
  fig.style.width = `${sphereSide}px`;
  canvas.style.width = canvas.style.height = `${sphereSide}px`;
  const cap = document.createElement('figcaption');
  cap.innerHTML = `${swatch(b)}&nbsp;${escapeHtml(specLabel(spec))}, a light from ωo`;
  cap.title = fullSpec(spec);
  fig.append(canvas, cap);
  return fig;
}
const updatePointLights = coalesced(async () => {
  const canvases = [...document.querySelectorAll('#spheres canvas[id^="pointlight-"]')];
  updateMesh();
  const fields = await B.fieldsOf(null, '/api/pointlight', canvases.map((c) => c.dataset.spec),
    [['theta_l', state.to], ['phi_l', state.po], ['size', SPHERE], ['spp', 4]]);
  canvases.forEach((c, k) => {
    c.sum = Float32Array.from(fields[k].data);
    c.dataset.passes = 1;
    V.drawSphere(c, c.sum, 1, SPHERE, SPHERE, state.exposure);
  });
});
const idleFrame = () => new Promise((r) => setTimeout(r, 30));
// The lit mesh (mesh.js): follows the BRDFs, ωo at rest, the environment and the exposure; its
// own settings are in the state (the URL).
let meshView = null;
function setupMesh() {
  meshView = new MeshView($('mesh-panel'), { meshes: info.meshes, colours: COLOURS, label: specLabel,
    title: fullSpec, swatch, onError: (m) => setStatus(m, true), settings: state, onSettings: writeHash });
}
function updateMesh() {
  if (!meshView) return;
  const shown = visible();  // hidden BRDFs leave the mesh too; each keeps its colour
  meshView.update({ specs: shown.map((v) => v.spec), colours: shown.map((v) => v.b), to: state.to, po: state.po,
    env: state.env, exposure: state.exposure });
}
function redrawSpheres() {
  updateMesh();
  for (const c of document.querySelectorAll('#spheres canvas'))
    if (c.sum) V.drawSphere(c, c.sum, Number(c.dataset.passes), SPHERE, SPHERE, state.exposure);
}

// --- the linked cursor -----------------------------------------------------------------------
async function setCursor(params) {
  const brdfs = loaded().map((s) => ['brdf', s]);
  return track((async () => {
    cursor = await getJson('point', '/api/point', [...params, ...brdfs]);
    showCursor();
    markSlices();
    drawHemisphere();
    drawPolar();
  })());
}
const fmt = (x) => (x === null ? '—' : Number(x).toPrecision(9));
function showCursor() {
  const c = cursor;
  if (!c) return;
  let html = `<p>${c.valid ? '' : 'outside the valid domain'}${pinned ? ' (pinned: click to release)' : ''}</p><table>`;
  const dirNames = ['wi_x', 'wi_y', 'wi_z', 'wo_x', 'wo_y', 'wo_z'];
  html += heading('directions', dirNames, dirNames.map(() => ''));
  html += row('', dirNames, [...c.wi, ...c.wo], 'dirs');
  for (const f of c.forms) {
    const fi = formInfo(f.space);
    html += heading(f.space, fi.columns, fi.units, f.jacobian !== undefined);
    html += row('', fi.columns, f.coords, f.space, f.jacobian);
    html += heading(`${f.space}, isotropic`, fi.iso_columns, fi.iso_units, f.iso_jacobian !== undefined);
    html += row('', fi.iso_columns, f.iso, `${f.space}-iso`, f.iso_jacobian);
  }
  html += heading('ρ', ['r', 'g', 'b'], ['sr⁻¹', 'sr⁻¹', 'sr⁻¹']);
  c.rho.forEach((r, b) => {
    if (state.hide.includes(r.brdf)) return;  // hidden: not listed
    html += row(`<span title="${escapeHtml(fullSpec(r.brdf))}">${swatch(b)} ρ ${escapeHtml(specLabel(r.brdf))}</span>`, ['r', 'g', 'b'], r.rgb, `rho-${b}`);
  });
  $('cursor').innerHTML = `${html}</table>`;
}
// The column names and units of the row below (angles in radians, as `halfback convert` prints).
function heading(title, names, units, jacobian = false) {
  let cells = names.map((n, k) => `<th scope="col">${escapeHtml(n)}${units[k] ? ` (${units[k]})` : ''}</th>`).join('');
  if (jacobian) cells += '<th scope="col" title="|det| of the map from the coordinates to the directions">Jacobian</th>';
  return `<tr class="names"><th>${escapeHtml(title)}</th>${cells}</tr>`;
}
function row(title, names, values, id, jacobian) {
  let cells = '';
  values.forEach((v, k) => { cells += `<td title="${names[k]}" id="cur-${id}-${names[k]}">${fmt(v)}</td>`; });
  if (jacobian !== undefined) cells += `<td title="Jacobian" id="cur-${id}-jacobian">J ${fmt(jacobian)}</td>`;
  return `<tr><th>${title}</th>${cells}</tr>`;
}
const escapeHtml = (s) => s.replace(/[&<>"]/g, (ch) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' }[ch]));

// The configuration turned about n so that ωo has the current azimuth (the BRDFs are isotropic
// in the views); whether its θo is the current one.
function cursorInView() {
  if (!cursor || !cursor.valid) return null;
  const [wi, w] = [cursor.wi, cursor.wo];
  const rot = state.po * DEG - Math.atan2(w[1], w[0]);
  const c = Math.cos(rot), s = Math.sin(rot);
  const thetaO = Math.acos(Math.min(1, w[2])) / DEG;
  return { wi: [c * wi[0] - s * wi[1], s * wi[0] + c * wi[1], wi[2]], exact: Math.abs(thetaO - state.to) < 0.5 };
}
function markSlices() {
  if (!cursor || !cursor.valid) return;
  for (const f of cursor.forms) {
    const fi = formInfo(f.space);
    for (const canvases of sliceRows) {
      const canvas = canvases[f.space];
      if (!canvas || !canvas.width) continue;
      V.restore(canvas);
      let d = Math.abs(f.iso[2] - state.az * DEG) % (2 * Math.PI);
      d = Math.min(d, 2 * Math.PI - d);
      V.drawMarker(canvas, f.iso[0] / fi.axes[0].max, f.iso[1] / fi.axes[1].max, d < 0.5 * DEG);
    }
  }
}
function markHemisphere() {
  const v = cursorInView();
  if (!v) return;
  const p = V.diskPoint(v.wi);
  V.drawMarker($('hemisphere'), (p[0] + 1) / 2, (p[1] + 1) / 2, v.exact);
}
function polarCursorAngle() {
  const v = cursorInView();
  if (!v || !v.exact) return null;
  const o = wo(), s = Math.hypot(o[0], o[1]);
  const c = s > 0 ? [-o[0] / s, -o[1] / s] : [1, 0];
  const across = -c[1] * v.wi[0] + c[0] * v.wi[1];
  if (Math.abs(across) > 1e-3) return null;
  return Math.atan2(c[0] * v.wi[0] + c[1] * v.wi[1], v.wi[2]) / DEG;
}

// A BRDF's whole spec: one named on the command line by what was given there, not its "arg:N".
function fullSpec(spec) {
  const arg = /^arg:(\d+)$/.exec(spec);
  return arg && info && info.specs[Number(arg[1])] !== undefined ? info.specs[Number(arg[1])] : spec;
}
// What a legend says: the whole spec, but a file by its name alone (each term of a sum); the
// whole spec is its title (on hover).
function specLabel(spec) {
  if (fitLabels.has(spec)) return fitLabels.get(spec);
  const whole = fullSpec(spec);
  const isFile = (t) => t.startsWith('file:') || /[/\\]/.test(t);
  const short = (t) => (isFile(t) ? t.replace(/^file:/, '').split(/[/\\]/).pop() : t);
  return sumTerms(whole).map(short).join('+');
}
// A spec typed in the load box, as the server reads it: a BRDF of the command line (as given
// there) is arg:N; a path, relative to a --root, is file:PATH (an absolute one ending in a file
// listed under a root is that file); models, embedded:NAME, file:PATH and arg:N stay as typed.
function typedSpec(text) {
  const given = info.specs.indexOf(text);
  if (given >= 0) return `arg:${given}`;
  if (info.files.includes(text)) return `file:${text}`;
  const term = (t) => {
    if (/^(arg|file|embedded):/.test(t) || info.models.some((m) => m.name === t.split(':')[0])) return t;
    const listed = info.files.filter((f) => t === f || t.endsWith(`/${f}`)).sort((x, y) => y.length - x.length)[0];
    if (listed) return `file:${listed}`;
    return /[/\\]/.test(t) || /\.(bsdf|binary|h5|alta|txt)$/i.test(t) ? `file:${t}` : t;
  };
  return sumTerms(text).map(term).join('+');
}

// --- model sliders -----------------------------------------------------------------------------
// The terms of a spec as the server splits a sum (load_brdf: '+' followed by a letter, '.', '/'
// or '~'; a number's exponent sign, as in 1e+3, is followed by a digit).
const sumTerms = (spec) => spec.split(/\+(?=[a-zA-Z./~])/);
// A spec's terms, each a model with its values or a fixed term (a file, an embedded material);
// null when no term is a model (nothing to slide).
function parseSpec(spec) {
  const arg = /^arg:(\d+)$/.exec(spec);  // a model named on the command line has sliders too
  if (arg && info.specs[Number(arg[1])] !== undefined) spec = info.specs[Number(arg[1])];
  const terms = sumTerms(spec).map(parseTerm);
  return terms.some((t) => t.model) ? terms : null;
}
function parseTerm(term) {
  if (/^(arg|file|embedded):/.test(term)) return { fixed: term };
  const [name, rest] = term.split(/:(.*)/s);
  const model = info.models.find((m) => m.name === name);
  if (!model) return { fixed: term };
  const values = {};
  (rest || '').split(',').filter((x) => x).forEach((item, k) => {
    const eq = item.indexOf('=');
    if (eq < 0 && k === 0 && model.params.length) values[model.params[0].name] = item.trim();
    else if (eq > 0) values[item.slice(0, eq).trim()] = item.slice(eq + 1).trim();
  });
  return { model, values };
}
let sliderTerms = null;  // what buildSliders last built: the terms of state.a
function buildSliders() {
  sliderTerms = parseSpec(state.a);
  const box = $('sliders');
  box.replaceChildren();  // never the sliders of the BRDF shown before
  $('model').hidden = !sliderTerms;
  if (!sliderTerms) return;
  const models = sliderTerms.filter((t) => t.model);
  $('model-name').textContent = sliderTerms.length === 1
    ? `${models[0].model.name}: ${models[0].model.description}`
    : `sum of ${sliderTerms.length} terms`;
  sliderTerms.forEach((term, t) => {
    const group = Object.assign(document.createElement('fieldset'), { className: 'term' });
    group.dataset.term = t;
    group.append(Object.assign(document.createElement('legend'), {
      textContent: term.model ? term.model.name : term.fixed,
      title: term.model ? term.model.description : 'not a model: fixed',
    }));
    if (term.model) for (const p of term.model.params) group.append(paramControl(term, t, p));
    box.append(group);
  });
}
function paramControl(term, t, p) {
  const { model, values } = term;
  const label = document.createElement('label');
  label.title = p.description;
  let input, current;
  if (p.choices.length) {
    input = document.createElement('select');
    p.choices.forEach((c) => input.append(new Option(c, c)));
    input.value = values[p.name] ?? p.choices[p.default];
  } else {
    input = Object.assign(document.createElement('input'), { type: 'range', min: 0, max: 1000, step: 1 });
    const map = sliderMap(p);
    current = values[p.name] !== undefined ? Number(values[p.name])
      : p.default_from ? Number(values[p.default_from] ?? model.params.find((q) => q.name === p.default_from).default) : p.default;
    input.value = map.toSlider(current);
    input.map = map;
  }
  input.dataset.param = p.name;
  input.dataset.term = t;
  // Only a parameter the spec names, or the user moved, is written into the spec.
  if (values[p.name] !== undefined) input.dataset.set = '1';
  // A parameter that defaults to another (alpha_x to alpha) follows it until it is moved.
  if (p.default_from && values[p.name] === undefined) input.dataset.follows = p.default_from;
  const out = document.createElement('output');
  // The spec's value, not the nearest slider position's (a logarithmic track has no 0.3 on it).
  out.textContent = p.choices.length ? '' : Number(current).toPrecision(3);
  input.out = out;
  input.addEventListener('input', () => {
    delete input.dataset.follows;  // moved by the user: it has its own value from now on
    input.dataset.set = '1';
    if (input.map) {
      const value = input.map.fromSlider(input.value);
      out.textContent = Number(value).toPrecision(3);
      moveFollowers(t, p.name, value);
    }
    state.a = sliderSpec();
    ensureOption($('brdf-a'), state.a);
    interactive = true;
    changed({ sphere: 'stale' });
  });
  input.addEventListener('change', () => { refineSoon(); });
  label.append(p.name, input, out);
  return label;
}
// The parameters of term t that default to `name` and were not moved (alpha_x, alpha_y of alpha)
// take its value: their sliders and numbers show it (sliderSpec leaves them out, so the server
// agrees).
function moveFollowers(t, name, value) {
  for (const f of document.querySelectorAll(`#sliders [data-term="${t}"][data-follows]`)) {
    if (f.dataset.follows !== name || !f.map) continue;
    f.value = f.map.toSlider(value);
    f.out.textContent = Number(value).toPrecision(3);
  }
}
// Logarithmic over ranges of two decades or more (a roughness in [0.001, 10]: α = 0.2 at 58 % of
// the track), and over [0, max] with max ≥ 100, from 0 at the first position, then max / 10⁴ …
// max (an index of refraction η or k in [0, 100]: η = 1.5 at 54 %), or 0.001 … max when max >
// 100; linear otherwise (albedos, f0); a position is 0 … 1000.
function sliderMap(p) {
  const lo = p.min, hi = p.max;
  const log = lo > 0 ? hi / lo >= 100 : lo === 0 && hi >= 100;
  if (!log) {
    return { toSlider: (v) => 1000 * (v - lo) / (hi - lo), fromSlider: (s) => lo + (hi - lo) * s / 1000 };
  }
  const floor = lo > 0 ? lo : hi > 100 ? 1e-3 : hi * 1e-4, a = Math.log10(floor), b = Math.log10(hi);
  return {
    toSlider: (v) => (lo === 0 && v <= 0 ? 0 : 1000 * (Math.log10(Math.min(Math.max(v, floor), hi)) - a) / (b - a)),
    fromSlider: (s) => (Number(s) === 0 ? lo : Math.min(hi, Math.pow(10, a + (b - a) * s / 1000))),
  };
}
// The spec the sliders show: every term, the fixed ones as they were, in their order.
function sliderSpec() {
  return sliderTerms.map((term, t) => {
    if (!term.model) return term.fixed;
    const items = [];
    for (const input of document.querySelectorAll(`#sliders [data-term="${t}"][data-param]`)) {
      if (input.dataset.follows || !input.dataset.set) continue;
      const v = input.map ? Number(Number(input.map.fromSlider(input.value)).toPrecision(4)) : input.value;
      items.push(`${input.dataset.param}=${v}`);
    }
    return items.length ? `${term.model.name}:${items.join(',')}` : term.model.name;
  }).join('+');
}

// --- layout --------------------------------------------------------------------------------------
// Every view grows with the window: the panels are viewSize() wide or more (CSS: --view) and
// wrap; each view takes its panel's width (the slices: fitSliceSide, the spheres: fitSphereSide),
// drawn again at its new size (a canvas at its size in device pixels).
let lobeSide = 400;
function layout() {
  document.documentElement.style.setProperty('--view', `${viewSize()}px`);
  const hemiWas = hemiN();
  hemiSide = Math.max(200, Math.min(640, plotWidth('hemisphere-panel') - 2 * HEMI_MARGIN));
  $('hemisphere').style.width = $('hemisphere').style.height = `${hemiSide}px`;
  drawHemiMarks();
  lobeSide = Math.max(240, Math.min(720, plotWidth('lobe-panel')));
  const c = $('lobe'), px = Math.round(lobeSide * (window.devicePixelRatio || 1));
  c.style.width = c.style.height = `${lobeSide}px`;
  if (c.width !== px) { c.width = px; c.height = px; if (lobe) lobe.draw(); }
  drawPolar();
  drawAlbedo();
  const rows = pairMode() ? 1 : visible().length;
  if (fitSliceSide(rows) !== sliceSide) {
    buildSlices();
    track(updateSlices());
  }
  if (hemiN() !== hemiWas) track(updateHemisphere());
  if (fitSphereSide() !== sphereSide && $('spheres').childElementCount) restartSphere();
  stats.layoutWidth = window.innerWidth;  // the window width the views were laid out for
}

// --- updates ------------------------------------------------------------------------------------
function changed({ slices = true, sphere = true, sliders = false } = {}) {
  writeHash();
  if (slices) track(updateSlices());
  track(updateHemisphere());
  track(updatePolar());
  // The lobe follows at rest only (refineSoon): with a software WebGL (no GPU) a drag would
  // redraw it at each step and halve the other views' rate.
  if (!interactive) {
    track(updateLobe());
    track(updatePointLights());
  } else {
    coarse.add('lobe');
    coarse.add('pointlights');
  }
  if (sphere === true) {  // a BRDF changed: the views that do not depend on ωo too
    showMore();
    restartSphere();
    track(updateAlbedo());
  }
  if (sphere === 'stale') sphereStale = true;
  if (sliders || sphere === true) track(showPoseControl());
  if (sliders) buildSliders();
  if (interactive) refineSoon();
}
function refineSoon() {
  clearTimeout(refineTimer);
  refineTimer = setTimeout(() => {
    if (dragging) return refineSoon();
    if (!interactive) return;
    interactive = false;
    const refine = new Set(coarse);
    coarse.clear();
    if (refine.has('slices')) track(updateSlices());
    if (refine.has('hemisphere')) track(updateHemisphere());
    if (refine.has('polar')) track(updatePolar());
    if (refine.has('lobe')) track(updateLobe());
    if (refine.has('pointlights') && !sphereStale) track(updatePointLights());
    if (sphereStale) {  // a model's parameters moved: its anisotropy may have changed too
      sphereStale = false;
      restartSphere();
      track(updateAlbedo());
      track(showPoseControl());
    }
  }, 250);
}

function ensureOption(select, value, label) {
  if (![...select.options].some((o) => o.value === value)) {
    const o = new Option(label || specLabel(value), value);
    o.title = fullSpec(value);
    select.append(o);
  }
  select.value = value;
}
function fillSelects() {
  const groups = [
    ['command line', info.specs.map((s, i) => [`arg:${i}`, specLabel(`arg:${i}`), s])],
    ['models', info.models.map((m) => [m.name, m.name])],
    ['embedded', info.embedded.map((n) => [`embedded:${n}`, n])],
    ['files', info.files.map((f) => [`file:${f}`, f])],
  ];
  for (const id of ['brdf-a', 'brdf-b']) {
    const sel = $(id);
    for (const [title, items] of groups) {
      if (!items.length) continue;
      const g = document.createElement('optgroup');
      g.label = title;
      for (const [v, l, title] of items) g.append(Object.assign(new Option(l, v), { title: title || l }));
      sel.append(g);
    }
  }
  for (const e of info.environments) $('env').append(new Option(e.replace(/^file:/, ''), e));
}

// Anisotropic BRDFs get the orientation control, and the page says which orientation it shows.
async function showPoseControl() {
  const answers = await Promise.all(loaded().map((s) => getJson(null, '/api/brdf', [['brdf', s]])));
  const anisotropic = answers.filter((r) => !r.isotropic).map((r) => r.name);
  $('pose-box').hidden = !anisotropic.length;
  $('pose-note').hidden = !anisotropic.length;
  $('pose-note').textContent = anisotropic.length
    ? `${anisotropic.join(', ')}: anisotropic; the slices show the pairs turned about the normal to the orientation ${state.pose}° (φh, φi … = ${state.pose}°), not every orientation.`
    : '';
}
function setPose(degrees) {
  state.pose = degrees;
  $('pose').value = degrees;
  showNumber($('pose-value'), degrees);
  writeHash();
  track(updateSlices());
  track(showPoseControl());
}

// Every BRDF loaded: a chip each, in the header: its colour (a colour picker), its name (the whole
// spec on hover), whether it is shown, solo (it alone; again: all of them), × to remove an
// added one.
function showMore() {
  const box = $('more');
  box.replaceChildren();
  state.hide = state.hide.filter((s) => loaded().includes(s));
  applyPalette();
  const list = loaded(), shown = visible();
  list.forEach((spec, b) => {
    const hidden = state.hide.includes(spec), name = specLabel(spec);
    const chip = Object.assign(document.createElement('span'), { className: `chip${hidden ? ' hidden' : ''}` });
    chip.dataset.spec = spec;
    chip.dataset.slot = b;
    const colour = Object.assign(document.createElement('input'), { type: 'color', className: 'colour', value: palette()[b], title: `the colour of ${name}` });
    colour.addEventListener('input', () => setColour(b, colour.value));
    const role = spec === state.a ? 'first' : spec === state.b ? 'compare' : '';
    const label = Object.assign(document.createElement('span'), { className: 'name', textContent: name, title: fullSpec(spec) });
    const show = Object.assign(document.createElement('input'), { type: 'checkbox', className: 'show', checked: !hidden, title: `show ${name} (unticked: hidden in every view)` });
    show.addEventListener('change', () => setHidden(spec, !show.checked));
    const alone = shown.length === 1 && shown[0].spec === spec && list.length > 1;
    const solo = Object.assign(document.createElement('button'), { type: 'button', className: `solo${alone ? ' on' : ''}`, textContent: 'solo',
      title: alone ? 'show every BRDF again' : `show ${name} alone` });
    solo.addEventListener('click', () => soloBrdf(spec));
    chip.append(colour, label);
    if (role) chip.append(Object.assign(document.createElement('span'), { className: 'role', textContent: role }));
    chip.append(show, solo);
    const k = state.more.indexOf(spec);
    if (k >= 0 && spec !== state.a && spec !== state.b) {
      const x = Object.assign(document.createElement('button'), { type: 'button', className: 'remove', textContent: '×', title: `remove ${name}` });
      x.addEventListener('click', () => { state.more.splice(state.more.indexOf(spec), 1); showMore(); changed(); });
      chip.append(x);
    }
    box.append(chip);
  });
}
function setHidden(spec, hide) {
  if (hide && !state.hide.includes(spec) && visible().length <= 1) {
    setStatus('one BRDF at least is shown: tick another first', true);
    showMore();
    return;
  }
  state.hide = hide ? [...state.hide.filter((s) => s !== spec), spec] : state.hide.filter((s) => s !== spec);
  showMore();
  visibilityChanged();
}
function soloBrdf(spec) {
  const shown = visible(), alone = shown.length === 1 && shown[0].spec === spec;
  state.hide = alone ? [] : loaded().filter((s) => s !== spec);
  showMore();
  visibilityChanged();
}
function setColour(b, colour) {
  state.colours = palette().map((c, k) => (k === b ? colour : state.colours[k] || ''));
  while (state.colours.length && !state.colours[state.colours.length - 1]) state.colours.pop();
  applyPalette();
  writeHash();
  drawPolar();
  drawAlbedo();
  drawLobe();
}
// A BRDF shown or hidden: every view that draws them all again.
function visibilityChanged() {
  writeHash();
  track(updateSlices());
  track(updateHemisphere());
  track(updatePolar());
  track(updateLobe());
  track(updateAlbedo());
  restartSphere();
  showCursor();
}
async function addBrdf(spec) {
  if (loaded().includes(spec)) return setStatus(`${specLabel(spec)} is already shown`);
  if (loaded().length >= COLOURS.length) {
    return setStatus(`at most ${COLOURS.length} BRDFs at once (${loaded().length} shown: remove one first)`, true);
  }
  return getJson(null, '/api/brdf', [['brdf', spec]]).then((r) => {
    state.more.push(spec);
    setStatus(`added ${r.name}`);
    showMore();
    changed();
  }).catch((err) => setStatus(err.message, true));
}

function setAzimuth(degrees) {
  state.az = degrees;
  $('azimuth').value = degrees;
  showNumber($('azimuth-value'), degrees);
  writeHash();
  track(updateSlices());
  if (cursor) markSlices();
}

function setup() {
  $('brdf-a').addEventListener('change', (e) => { state.a = e.target.value; changed({ sliders: true }); });
  $('brdf-b').addEventListener('change', (e) => {
    state.b = e.target.value;
    if (state.b && state.mode === 'a') { state.mode = 'diff'; $('mode').value = 'diff'; }
    if (!state.b) { state.mode = 'a'; $('mode').value = 'a'; }
    syncModes();
    changed();
  });
  $('mode').addEventListener('change', (e) => {
    if (e.target.value !== 'a' && !state.b) {  // nothing to compare with: say so, show the first
      setStatus(`show ${MODES[e.target.value]}: choose a compare BRDF first`, true);
      e.target.value = 'a';
      return;
    }
    state.mode = e.target.value;
    changed({ sphere: false });
  });
  $('add-brdf').addEventListener('click', () => {
    const spec = $('load-spec').value.trim();
    if (spec) addBrdf(typedSpec(spec));
  });
  $('load-form').addEventListener('submit', (e) => {
    e.preventDefault();
    const typed = $('load-spec').value.trim();
    if (!typed) return;
    const spec = typedSpec(typed);
    getJson(null, '/api/brdf', [['brdf', spec]]).then((r) => {
      state.a = spec;
      ensureOption($('brdf-a'), spec, `${specLabel(spec)} (${r.name})`);
      setStatus(`loaded ${r.name}`);
      changed({ sliders: true });
    }).catch((err) => setStatus(err.message, true));
  });
  $('azimuth').addEventListener('input', (e) => {
    interactive = true;
    setAzimuth(Number(e.target.value));
    refineSoon();
  });
  $('pose').addEventListener('input', (e) => {
    interactive = true;
    setPose(Number(e.target.value));
    refineSoon();
  });
  $('pose-value').addEventListener('change', (e) => {
    const v = typedAngle(e.target, 'the orientation', 0, 360);
    if (v === null) { e.target.value = state.pose; return; }
    setStatus('ready');
    setPose(v);
  });
  $('scale').addEventListener('change', (e) => { state.scale = e.target.value; writeHash(); drawSlices(); });
  $('levels').addEventListener('change', (e) => { state.levels = e.target.value || 'auto'; writeHash(); drawSlices(); });
  $('hemi-colour').addEventListener('change', (e) => { state.hemi = e.target.value; writeHash(); track(updateHemisphere()); });
  $('polar-scale').addEventListener('change', (e) => { state.polar = e.target.value; writeHash(); drawPolar(); });
  $('polar-quantity').addEventListener('change', (e) => { state.polarY = e.target.value; writeHash(); drawPolar(); });
  $('theta-quantity').addEventListener('change', (e) => { state.theta = e.target.value; writeHash(); drawPolar(); });
  $('theta-scale').addEventListener('change', (e) => { state.thetaScale = e.target.value; writeHash(); drawPolar(); });
  $('env').addEventListener('change', (e) => { state.env = e.target.value; writeHash(); restartSphere(); });
  $('exposure').addEventListener('input', (e) => { state.exposure = Number(e.target.value); writeHash(); redrawSpheres(); });
  setupHemisphere();
  setupTypedAngles();
  setupLobe();
  setupPolar();
  setupMesh();
  setupExports();
  setupFit();
}

// --- fit ---------------------------------------------------------------------------------------
const fitLabels = new Map();  // a fitted spec -> "fit of TARGET: MODEL (LOSS)"
let fitAnswer = null;  // the last /api/fit answer (the JSON `halfback fit` writes)
function setupFit() {
  for (const m of info.models) $('fit-models').append(new Option(m.description, m.name));
  $('fit-models').append(new Option('diffuse + specular lobe', 'lambert+ggx'));
  for (const l of info.losses) $('fit-loss').append(new Option(l, l));
  $('fit-form').addEventListener('submit', (e) => { e.preventDefault(); runFit(); });
}
async function runFit() {
  const target = state.a, model = $('fit-model').value.trim(), loss = $('fit-loss').value;
  if (!model) return setStatus('fit: name a model (lambert+ggx, ggx, …)', true);
  $('fit-run').disabled = true;
  setStatus(`fitting ${model} to ${specLabel(target)} (${loss}) …`);
  try {
    const r = await getJson(null, '/api/fit', [['brdf', target], ['model', model], ['loss', loss], ['samples', $('fit-samples').value]]);
    fitAnswer = r;
    fitLabels.set(r.spec, `fit of ${specLabel(target)}: ${model} (${loss})`);
    state.b = r.spec;
    ensureOption($('brdf-b'), r.spec, fitLabels.get(r.spec));
    syncModes();
    if (state.mode === 'a') { state.mode = 'diff'; $('mode').value = 'diff'; }
    showFit();
    setStatus(`fitted ${model} to ${specLabel(target)}: ${loss} loss ${r.loss.value.toPrecision(4)} in ${r.seconds.toFixed(2)} s`);
    changed();
  } catch (e) {
    setStatus(`fit: ${e.message}`, true);
  } finally {
    $('fit-run').disabled = false;
  }
  return undefined;
}
// The fitted parameters by term (held ones dimmed), the loss and what the fit did.
function showFit() {
  const r = fitAnswer, box = $('fit-result');
  const rows = r.terms.flatMap((t) => t.parameters.map((p) => `<tr><th>${escapeHtml(t.model)}</th><th>${escapeHtml(p.name)}</th>`
    + `<td${p.fitted ? '' : ' class="held"'}>${Number(p.value.toPrecision(6))}</td><td>${escapeHtml(p.unit)}</td>`
    + `<td${p.fitted ? '' : ' class="held"'}>${p.fitted ? 'fitted' : 'held'}</td><td>[${p.min}, ${p.max}]</td></tr>`));
  box.innerHTML = `<p class="note">${swatch(1)} fit of ${escapeHtml(specLabel(r.brdf))}: ${escapeHtml(r.loss.name)} loss `
    + `${r.loss.value.toPrecision(4)}; ${r.samples.count} samples (${escapeHtml(r.samples.layout)}), ${r.starts} starts, `
    + `${r.iterations} iterations, ${r.seconds.toFixed(2)} s</p>`
    + `<table><tr class="names"><th>term</th><th>parameter</th><th>value</th><th>unit</th><th></th><th>range</th></tr>${rows.join('')}</table>`
    + `<p class="spec" title="the fitted spec: every halfback command reads it">${escapeHtml(r.spec)}</p>`;
}
window.halfback.fit = () => fitAnswer;

// --- export ------------------------------------------------------------------------------------
function download(name, blob) {
  const a = document.createElement('a');
  a.href = URL.createObjectURL(blob);
  a.download = name;
  a.click();
  setTimeout(() => URL.revokeObjectURL(a.href), 1000);
}
function setupExports() {
  for (const span of document.querySelectorAll('.export')) {
    const target = span.dataset.target;
    for (const kind of ['PNG', 'SVG']) {
      const b = document.createElement('button');
      b.textContent = kind;
      b.addEventListener('click', () => exportView(target, kind));
      span.append(b);
    }
  }
}
// What a figure of the view says above it: the view, the BRDFs, the state that picks the slice.
function figureTitle(target) {
  const names = (target === 'hemisphere' || (target === 'slices' && pairMode()) ? specs()
    : target === 'mesh' ? meshView.view.specs : visible().map((v) => v.spec)).map(specLabel);
  const wo = `θo = ${state.to.toFixed(1)}°, φo = ${state.po.toFixed(1)}°`;
  const what = {
    slices: `slices at the relative azimuth ${state.az}°${$('pose-box').hidden ? '' : `, orientation ${state.pose}°`}`,
    hemisphere: `hemisphere of ωi, ${wo}`, polar: `polar plot of ${state.polarY === 'cos' ? 'ρ cos θi' : 'ρ'}, ${wo}`, lobe: `lobe of ρ(·, ωo), ${wo}`,
    theta: `${state.theta === 'cos' ? 'ρ cos θi' : 'ρ'} against θi (${state.thetaScale} axis), ${wo}`,
    albedo: 'directional albedo', sphere: `lit sphere, environment ${state.env}, exposure ${state.exposure}`,
    mesh: meshView.title(),
  }[target];
  const shown = state.mode !== 'a' && state.b && (target === 'slices' || target === 'hemisphere')
    ? `${{ b: 'second', diff: 'difference', ratio: 'ratio' }[state.mode]} of ${names.join(' and ')}` : names.join(', ');
  return `halfback view: ${what}; ${shown}`;
}
// The panel as an SVG figure: its pictures (canvases), plots and colour bars (SVG) and texts
// (headings, axis notes, captions, legends) where the page shows them, under a title wrapped to
// the figure's width; controls are left out. The figure is as wide as what it shows (a wide
// panel's empty right side is left out), at least FIGURE_MIN_WIDTH for its title.
const FIGURE_MIN_WIDTH = 360;
function panelFigure(target) {
  const panel = $(`${target}-panel`), box = panel.getBoundingClientRect();
  const parts = [];
  let right = 0;  // the right edge of what the figure shows
  const at = (e) => { const r = e.getBoundingClientRect(); return { x: r.left - box.left, y: r.top - box.top, w: r.width, h: r.height }; };
  const esc = (t) => t.replace(/[&<>"]/g, (ch) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' }[ch]));
  const text = (t, x, y, size, colour) => `<text x="${x}" y="${y}" font-family="sans-serif" font-size="${size}" fill="${colour}">${esc(t)}</text>`;
  for (const e of panel.querySelectorAll('canvas, svg, h2, .axis, figcaption, .note, .row-name')) {
    if (e.closest('svg') !== e && e.closest('svg')) continue;  // inside a plot: part of it
    if (e.closest('.panel-head') && e.tagName !== 'H2') continue;  // controls
    const r = at(e);
    if (!r.w || !r.h) continue;
    right = Math.max(right, r.x + r.w);
    if (e.tagName === 'CANVAS') {
      parts.push(`<image x="${r.x}" y="${r.y}" width="${r.w}" height="${r.h}" preserveAspectRatio="none" href="${e.toDataURL('image/png')}"/>`);
    } else if (e.tagName.toLowerCase() === 'svg') {
      const copy = e.cloneNode(true);
      copy.setAttribute('x', r.x); copy.setAttribute('y', r.y);
      copy.setAttribute('width', r.w); copy.setAttribute('height', r.h);
      copy.setAttribute('overflow', 'visible');  // a colour bar's unit line is wider than its bar
      if (!copy.getAttribute('viewBox')) copy.setAttribute('viewBox', `0 0 ${r.w} ${r.h}`);
      parts.push(new XMLSerializer().serializeToString(copy));
    } else if (!e.querySelector('svg, canvas')) {  // a text (a colour bar's box is drawn as its SVG)
      const h2 = e.tagName === 'H2', size = h2 ? 13 : 11;
      // In lines within the element's width, as the page wraps it, swatches in their colours.
      wrapRuns(runsOf(e, h2 ? '#e6e6ea' : '#9a9cab'), Math.max(r.w, 40), `${size}px sans-serif`).forEach((line, k) => {
        const spans = line.map(([t, fill]) => `<tspan fill="${fill}">${esc(t)}</tspan>`).join('');
        parts.push(`<text x="${r.x}" y="${r.y + 12 + k * (size + 3)}" font-family="sans-serif" font-size="${size}" xml:space="preserve">${spans}</text>`);
      });
    }
  }
  const w = Math.ceil(Math.max(Math.min(box.width, right + 8), FIGURE_MIN_WIDTH));
  const titleLines = wrapRuns([[figureTitle(target), '#e6e6ea']], w - 16, '13px sans-serif');
  const top = 10 + 18 * titleLines.length, h = Math.ceil(box.height + top);
  const title = titleLines.map((line, k) => text(line.map(([t]) => t).join(''), 8, 18 + 18 * k, 13, '#e6e6ea'));
  return { svg: `<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" width="${w}" height="${h}" viewBox="0 0 ${w} ${h}">`
    + `<rect width="${w}" height="${h}" fill="#202229"/>${title.join('')}<g transform="translate(0 ${top})">${parts.join('')}</g></svg>`, w, h };
}
// An element's text as runs [text, colour]: a swatch (class swatch-N) in its BRDF's colour.
function runsOf(e, fill) {
  const runs = [];
  const walk = (n, colour) => {
    if (n.nodeType === Node.TEXT_NODE || n.tagName === 'INPUT' || n.tagName === 'SELECT') {
      runs.push([textOf(n), colour]);
      return;
    }
    if (n.nodeType !== Node.ELEMENT_NODE) return;
    const m = /(?:^|\s)swatch-(\d)(?:\s|$)/.exec(n.getAttribute('class') || '');
    for (const c of n.childNodes) walk(c, m ? palette()[Number(m[1])] : colour);
  };
  walk(e, fill);
  return runs;
}
// Runs laid out in lines of at most `width` pixels, as the page wraps them: at spaces (not at a
// no-break space), a word wider than a line cut where the line ends (overflow-wrap: anywhere).
let measurer = null;
function wrapRuns(runs, width, font) {
  measurer ||= document.createElement('canvas').getContext('2d');
  measurer.font = font;
  const m = (t) => measurer.measureText(t).width, gap = m(' ');
  const words = [];  // [text, colour, a space before it]
  let space = false;
  for (const [t, colour] of runs) {
    for (const piece of t.split(/([ \t\n\r]+)/)) {
      if (!piece) continue;
      if (/^[ \t\n\r]+$/.test(piece)) { space = words.length > 0; continue; }
      words.push([piece.replace(/\u00a0/g, ' '), colour, space]);
      space = false;
    }
  }
  const lines = [];
  let line = [], used = 0;
  const put = (t, colour) => {
    const last = line[line.length - 1];
    if (last && last[1] === colour) last[0] += t; else line.push([t, colour]);
    used += m(t);
  };
  const breakLine = () => { if (line.length) lines.push(line); line = []; used = 0; };
  for (const [word, colour, before] of words) {
    let w = word, sep = before && line.length > 0;
    while (m(w) > width) {  // too wide for any line: fill this one with its beginning
      const room = width - used - (sep ? gap : 0);
      let n = w.length - 1;
      while (n > 0 && m(w.slice(0, n)) > room) n -= 1;
      if (n === 0 && !line.length) n = 1;
      if (n > 0) { put((sep ? ' ' : '') + w.slice(0, n), colour); w = w.slice(n); }
      breakLine();
      sep = false;
    }
    if (line.length && used + (sep ? gap : 0) + m(w) > width) { breakLine(); sep = false; }
    put((sep ? ' ' : '') + w, colour);
  }
  breakLine();
  return lines;
}
// An element's text with the values of its fields (θo = 45.0°, not θo = °).
function textOf(e) {
  if (e.nodeType === Node.TEXT_NODE) return e.textContent;
  if (e.tagName === 'INPUT') return e.value;
  if (e.tagName === 'SELECT') return e.selectedOptions[0]?.textContent || '';
  return [...e.childNodes].map(textOf).join('');
}
// The PNG of a view's figure (its SVG drawn at twice the page's size): a promise of the blob.
function figurePng(target) {
  const { svg, w, h } = panelFigure(target);
  return new Promise((resolve, reject) => {
    const img = new Image(), url = URL.createObjectURL(new Blob([svg], { type: 'image/svg+xml' }));
    img.onload = () => {
      URL.revokeObjectURL(url);
      const c = Object.assign(document.createElement('canvas'), { width: 2 * w, height: 2 * h });
      c.getContext('2d').drawImage(img, 0, 0, 2 * w, 2 * h);
      c.toBlob((blob) => (blob ? resolve(blob) : reject(new Error(`the ${target} figure: no PNG`))));
    };
    img.onerror = () => { URL.revokeObjectURL(url); reject(new Error(`the ${target} figure: its SVG does not load`)); };
    img.src = url;
  });
}
function exportView(target, kind) {
  const name = `halfback-${target}`;
  if (kind === 'SVG') return download(`${name}.svg`, new Blob([panelFigure(target).svg], { type: 'image/svg+xml' }));
  return figurePng(target).then((blob) => download(`${name}.png`, blob)).catch((e) => setStatus(e.message, true));
}
window.halfback.figure = (target) => panelFigure(target).svg;
// The PNG the export button downloads, as a data URL (the browser test reads it).
window.halfback.figurePng = (target) => figurePng(target).then((blob) => new Promise((resolve) => {
  const reader = new FileReader();
  reader.onload = () => resolve(reader.result);
  reader.readAsDataURL(blob);
}));

// "show" offers the second, the difference and the ratio only with a compare BRDF.
function syncModes() {
  for (const o of $('mode').options) o.disabled = o.value !== 'a' && !state.b;
}

async function main() {
  const named = readHash();
  try {
    info = await getJson(null, '/api/info');
  } catch (e) {
    setStatus(e.message, true);
    return;
  }
  // Every BRDF of the command line is shown (unless the URL names others): the first, the second
  // as the compare one, the others beside them in the plots.
  let note = '';
  if (!named && info.specs.length) {
    state.a = 'arg:0';
    state.b = info.specs.length > 1 ? 'arg:1' : '';
    state.more = info.specs.slice(2, COLOURS.length).map((_, k) => `arg:${k + 2}`);
    if (info.specs.length > COLOURS.length) note = `; ${info.specs.length} BRDFs given: the first ${COLOURS.length} are shown (one colour each)`;
  }
  if (!state.a) state.a = 'ggx:alpha=0.2';
  if (state.mode !== 'a' && !state.b) {
    note += `; show ${MODES[state.mode] || state.mode}: no compare BRDF, the first is shown`;
    state.mode = 'a';
  }
  fillSelects();
  ensureOption($('brdf-a'), state.a);
  if (state.b) ensureOption($('brdf-b'), state.b);
  $('mode').value = state.mode;
  syncModes();
  $('azimuth').value = state.az;
  $('azimuth-value').value = state.az;
  $('pose').value = state.pose;
  $('pose-value').value = state.pose;
  $('scale').value = state.scale;
  $('levels').value = state.levels === 'auto' ? '' : state.levels;
  for (const f of info.forms)  // the parameterizations come from the server (/api/info)
    $('hemi-colour').append(Object.assign(document.createElement('option'),
      { value: f.space, textContent: f.space, title: f.summary }));
  $('hemi-colour').value = state.hemi;
  $('polar-scale').value = state.polar;
  $('polar-quantity').value = state.polarY;
  $('theta-quantity').value = state.theta;
  $('theta-scale').value = state.thetaScale;
  ensureOption($('env'), state.env);
  $('exposure').value = state.exposure;
  applyPalette();
  document.documentElement.style.setProperty('--view', `${viewSize()}px`);
  buildSlices();
  setup();
  if (meshView.settingsNote) note += `; ${meshView.settingsNote}`;
  showMore();
  layout();
  changed({ sliders: true });
  setStatus(`ready${note}`, Boolean(note));
}
main();
