// Drawing: colour maps, scalar fields with hatching and isolines, markers, the polar plot and
// the tone-mapped sphere. Fields arrive as float32 RGB with row 0 at the bottom (y up).

const VIRIDIS = [[68, 1, 84], [72, 40, 120], [62, 74, 137], [49, 104, 142], [38, 130, 142],
  [31, 158, 137], [53, 183, 121], [109, 205, 89], [180, 222, 44], [253, 231, 37]];

function ramp(stops, t) {
  if (!(t >= 0)) t = 0;
  if (t > 1) t = 1;
  const x = t * (stops.length - 1), i = Math.min(Math.floor(x), stops.length - 2), f = x - i;
  const a = stops[i], b = stops[i + 1];
  return [a[0] + (b[0] - a[0]) * f, a[1] + (b[1] - a[1]) * f, a[2] + (b[2] - a[2]) * f];
}
export const viridis = (t) => ramp(VIRIDIS, t);
const DIVERGING = [[33, 102, 172], [103, 169, 207], [209, 229, 240], [247, 247, 247],
  [253, 219, 199], [239, 138, 98], [178, 24, 43]];
export const diverging = (t) => ramp(DIVERGING, t);

// The luminance of ρ per pixel: a field of RGB, or of the luminance alone (values=luminance).
export function luminanceOf(field) {
  const { data: d, channels } = field;
  if (channels === 1) return d;
  const n = field.width * field.height, y = new Float32Array(n);
  for (let k = 0; k < n; ++k) y[k] = 0.2126 * d[3 * k] + 0.7152 * d[3 * k + 1] + 0.0722 * d[3 * k + 2];
  return y;
}

// The scalar a slice shows: the luminance of the first or second BRDF, their difference or ratio.
export function sliceScalar(a, b, mode) {
  const ya = luminanceOf(a);
  if (!b || mode === 'a') return ya;
  const yb = luminanceOf(b);
  if (mode === 'b') return yb;
  const n = a.width * a.height, out = new Float32Array(n);
  for (let k = 0; k < n; ++k) out[k] = mode === 'diff' ? ya[k] - yb[k] : ya[k] / yb[k];
  return out;
}

function percentile(sorted, p) {
  if (!sorted.length) return NaN;
  return sorted[Math.min(sorted.length - 1, Math.round(p * (sorted.length - 1)))];
}
// The scale's percentiles come from at most this many values, spread evenly over all its fields:
// they need no more, and sorting every pixel of the 24 slices of three BRDFs took longer than
// drawing them.
const SCALE_SAMPLE = 16384;
// The least step ≥ `from` that shares no factor with any field's length: a stride through an
// n × n field that is a multiple of n's factors would visit a few columns only (step 96 on
// 256-wide rows: every 32nd column).
function coprimeStep(from, fields) {
  const gcd = (a, b) => (b ? gcd(b, a % b) : a);
  let step = from;
  while (step > 1 && fields.some((x) => gcd(step, x.length) !== 1)) ++step;
  return step;
}
// Every step-th value of each field with f(value) finite, mapped by f, sorted; step spreads
// SCALE_SAMPLE values over all the fields (each gives at least its first value).
function sortedSample(fields, f) {
  const total = fields.reduce((n, x) => n + x.length, 0);
  const step = coprimeStep(Math.max(1, Math.floor(total / SCALE_SAMPLE)), fields);
  const out = new Float64Array(Math.ceil(total / step) + fields.length);
  let m = 0;
  for (const x of fields) {
    for (let k = 0; k < x.length; k += step) {
      const t = f(x[k]);
      if (Number.isFinite(t)) out[m++] = t;
    }
  }
  return out.subarray(0, m).sort();
}

// A colour scale shared by several fields: transform (value -> t), range [lo, hi], colour map.
export function makeScale(fields, mode, kind) {
  const diverge = mode === 'diff' || mode === 'ratio';
  // A signed logarithm for differences on the log scale: linear below eps (a tenth of the
  // median difference), logarithmic above, so that both small and peak differences show.
  let eps = 1;
  if (mode === 'diff' && kind === 'log') {
    eps = Math.max((percentile(sortedSample(fields, Math.abs), 0.5) || 1) / 10, 1e-12);
  }
  const tf = mode === 'ratio' ? (v) => (v > 0 ? Math.log2(v) : NaN)
    : mode === 'diff' ? (kind === 'log' ? (v) => Math.sign(v) * Math.log10(1 + Math.abs(v) / eps) : (v) => v)
      : kind === 'log' ? (v) => (v > 0 ? Math.log10(v) : NaN) : (v) => v;
  const sorted = sortedSample(fields, diverge ? (v) => Math.abs(tf(v)) : tf);
  let lo, hi;
  if (diverge) {
    hi = percentile(sorted, 0.99) || 1;
    lo = -hi;
  } else if (kind === 'log') {
    hi = percentile(sorted, 0.995);
    lo = Math.max(percentile(sorted, 0.01), hi - 4);
  } else {
    lo = 0;
    hi = percentile(sorted, 0.995);
  }
  if (!(hi > lo)) hi = lo + 1;
  return { tf, lo, hi, map: diverge ? diverging : viridis, diverge, kind, mode, eps,
    line: diverge ? [20, 20, 20] : [255, 255, 255] };
}

// Isoline levels in transformed units: 'none', 'auto' (decades or tenths), or a list of values.
export function isoLevels(text, scale) {
  const t = (text || 'auto').trim();
  if (t === 'none') return [];
  if (t !== 'auto') {
    return t.split(',').map(Number).filter(Number.isFinite).map(scale.tf).filter(Number.isFinite);
  }
  const out = [];
  if (scale.kind === 'log' || scale.diverge) {
    for (let v = Math.ceil(scale.lo); v <= scale.hi; v += 1) out.push(v);
  } else {
    for (let k = 1; k < 10; ++k) out.push(scale.lo + (scale.hi - scale.lo) * k / 10);
  }
  return out;
}

// A colour map tabulated at 1024 points (RGB bytes): drawing looks each pixel up instead of
// interpolating the stops (a 256² slice is 65 536 pixels; the table's steps are below a byte).
const TABLE = 1024;
const tables = new Map();
function colourTable(map) {
  let table = tables.get(map);
  if (!table) {
    table = new Uint8ClampedArray(3 * TABLE);
    for (let k = 0; k < TABLE; ++k) table.set(map(k / (TABLE - 1)).map(Math.round), 3 * k);
    tables.set(map, table);
  }
  return table;
}

// Draws n × n scalars (row 0 at the bottom) into a canvas: colour, hatching where NaN, isolines.
export function drawScalar(canvas, values, w, h, scale, levels) {
  if (canvas.width !== w) canvas.width = w;
  if (canvas.height !== h) canvas.height = h;
  const ctx = canvas.getContext('2d');
  const img = ctx.createImageData(w, h), px = img.data;
  const t = new Float32Array(w * h);
  for (let k = 0; k < w * h; ++k) t[k] = scale.tf(values[k]);
  const table = colourTable(scale.map), last = TABLE - 1;
  const lo = scale.lo, inv = 1 / (scale.hi - scale.lo), line = scale.line;
  for (let j = 0; j < h; ++j) {
    const y = h - 1 - j;
    for (let i = 0; i < w; ++i) {
      const k = j * w + i, p = 4 * (y * w + i);
      if (Number.isNaN(values[k])) {
        const light = ((i + y) % 8) < 2;  // hatched
        px[p] = px[p + 1] = light ? 110 : 40;
        px[p + 2] = light ? 118 : 46;
      } else if (isIsoline(t, w, h, i, j, levels)) {
        px[p] = line[0]; px[p + 1] = line[1]; px[p + 2] = line[2];
      } else {
        const x = (t[k] - lo) * inv;  // NaN (ρ ≤ 0 on a log scale) takes the first colour
        const e = 3 * (x > 0 ? Math.min(last, Math.round(x * last)) : 0);
        px[p] = table[e]; px[p + 1] = table[e + 1]; px[p + 2] = table[e + 2];
      }
      px[p + 3] = 255;
    }
  }
  ctx.putImageData(img, 0, 0);
  canvas.base = img;  // markers are drawn over a copy of this
}

// Puts a canvas' picture back (without the markers drawn on it since).
export function restore(canvas) {
  if (canvas.base) canvas.getContext('2d').putImageData(canvas.base, 0, 0);
}

function crosses(v, u, levels) {
  if (!Number.isFinite(u)) return false;
  for (const L of levels) if ((v - L) * (u - L) < 0) return true;
  return false;
}
function isIsoline(t, w, h, i, j, levels) {
  if (!levels.length) return false;
  const v = t[j * w + i];
  if (!Number.isFinite(v)) return false;
  return (i + 1 < w && crosses(v, t[j * w + i + 1], levels)) ||
    (j + 1 < h && crosses(v, t[(j + 1) * w + i], levels));
}

// Hemisphere coloured by the first two coordinates (red, green) of a parameterization.
export function drawCoordinates(canvas, field, axes) {
  const { width: w, height: h, data } = field;
  canvas.width = w;
  canvas.height = h;
  const ctx = canvas.getContext('2d');
  const img = ctx.createImageData(w, h);
  for (let j = 0; j < h; ++j) {
    for (let i = 0; i < w; ++i) {
      const k = j * w + i, p = 4 * ((h - 1 - j) * w + i);
      const a = data[3 * k] / axes[0].max, b = data[3 * k + 1] / axes[1].max;
      const inside = Number.isFinite(a);
      img.data[p] = inside ? 255 * a : 0;
      img.data[p + 1] = inside ? 255 * b : 0;
      img.data[p + 2] = inside ? 40 : 0;
      img.data[p + 3] = 255;
    }
  }
  ctx.putImageData(img, 0, 0);
}

// Ticks of a colour scale in the units a reader knows: positions in transformed units (t, as
// scale.lo … scale.hi) with labels in ρ's own units (a decade, a difference, a ratio).
export function scaleTicks(scale) {
  const inRange = (t) => t >= scale.lo - 1e-9 && t <= scale.hi + 1e-9;
  const ticks = [];
  if (scale.mode === 'ratio') {
    const step = scale.hi - scale.lo > 8 ? 2 : 1;
    for (let k = Math.ceil(scale.lo / step) * step; k <= scale.hi; k += step) ticks.push({ t: k, label: `×${shortNumber(2 ** k)}` });
  } else if (scale.mode === 'diff' && scale.kind === 'log') {
    ticks.push({ t: 0, label: '0' });
    for (let k = -12; k <= 12; ++k) {
      const v = 10 ** k, t = scale.tf(v);
      if (inRange(t) && t >= 0.3) ticks.push({ t, label: shortNumber(v) }, { t: -t, label: shortNumber(-v) });
    }
  } else if (scale.kind === 'log' && !scale.diverge) {
    // Decades; over less than two of them, also 2 and 5 (or every digit under half a decade).
    const span = scale.hi - scale.lo;
    const mantissas = span >= 2 ? [1] : span >= 0.5 ? [1, 2, 5] : [1, 2, 3, 4, 5, 6, 7, 8, 9];
    for (let k = Math.floor(scale.lo); k <= Math.ceil(scale.hi); ++k) {
      for (const m of mantissas) ticks.push({ t: k + Math.log10(m), label: shortNumber(m * 10 ** k) });
    }
  } else {
    const step = niceStep((scale.hi - scale.lo) / 5);
    for (let v = Math.ceil(scale.lo / step) * step; v <= scale.hi + 1e-9 * step; v += step) ticks.push({ t: v, label: shortNumber(Math.abs(v) < step / 2 ? 0 : v) });
  }
  return ticks.filter((k) => inRange(k.t)).sort((a, b) => a.t - b.t);
}
export function niceStep(raw) {
  if (!(raw > 0)) return 1;
  const p = 10 ** Math.floor(Math.log10(raw)), f = raw / p;
  return p * (f < 1.5 ? 1 : f < 3.5 ? 2 : f < 7.5 ? 5 : 10);
}
export function shortNumber(v) {
  if (v === 0) return '0';
  const a = Math.abs(v);
  if (a >= 1e4 || a < 1e-3) return v.toExponential(0).replace('e+', 'e');
  return String(Number(v.toPrecision(3)));
}

// A colour bar as SVG (vector, so that it exports): the ramp, ticks with labels, a unit line.
export function colourbarSvg(scale, unit, width = 256) {
  const h = 46, barH = 12, pad = 14;
  const svg = el('svg', { width: width + 2 * pad, height: h, viewBox: `0 0 ${width + 2 * pad} ${h}`, class: 'colourbar' });
  const id = `ramp-${Math.random().toString(36).slice(2)}`;
  const grad = el('linearGradient', { id });
  for (let k = 0; k <= 32; ++k) {
    const c = scale.map(k / 32).map(Math.round);
    grad.append(el('stop', { offset: k / 32, 'stop-color': `rgb(${c})` }));
  }
  svg.append(el('defs', {}), el('rect', { x: pad, y: 0, width, height: barH, fill: `url(#${id})` }));
  svg.firstChild.append(grad);
  for (const tick of spacedTicks(scale, width)) {
    const x = pad + width * (tick.t - scale.lo) / (scale.hi - scale.lo);
    svg.append(el('line', { x1: x, x2: x, y1: barH, y2: barH + 4, stroke: '#9a9cab' }));
    svg.append(text(tick.label, { x, y: barH + 14, 'text-anchor': 'middle', class: 'tick' }));
  }
  svg.append(text(unit, { x: pad, y: h - 3 }));
  return svg;
}
// The ticks of a colour bar `width` pixels wide whose labels (10 px) do not touch: the ones that
// would are left out, the more important first kept — 0 and then the outer decades of a
// difference (each ± pair kept or left out together), else from left to right.
let measurer = null;
function labelWidth(label) {
  measurer ||= document.createElement('canvas').getContext('2d');
  measurer.font = '10px system-ui, sans-serif';
  return measurer.measureText(label).width;
}
export function spacedTicks(scale, width) {
  const ticks = scaleTicks(scale).map((k) => ({ ...k, x: width * (k.t - scale.lo) / (scale.hi - scale.lo), w: labelWidth(k.label) }));
  let groups = ticks.map((k) => [k]);
  if (scale.diverge) {
    const byMagnitude = new Map();
    for (const k of ticks) {
      const key = Math.abs(k.t).toFixed(9);
      byMagnitude.set(key, [...(byMagnitude.get(key) || []), k]);
    }
    groups = [...byMagnitude.entries()].sort((p, q) => Number(p[0]) - Number(q[0]));
    groups = [...groups.slice(0, 1), ...groups.slice(1).reverse()].map((e) => e[1]);
  }
  const kept = [], gap = 4;
  const free = (k) => kept.every((q) => k.x + k.w / 2 + gap <= q.x - q.w / 2 || q.x + q.w / 2 + gap <= k.x - k.w / 2);
  for (const g of groups) if (g.every(free)) kept.push(...g);
  return kept.sort((p, q) => p.t - q.t);
}
function text(content, attrs) {
  const t = el('text', { fill: '#9a9cab', 'font-size': 10, 'font-family': 'system-ui, sans-serif', ...attrs });
  t.textContent = content;
  return t;
}

// Ticks of an axis of a parameterization (degrees for angles, plain numbers for lengths), as
// fractions of the axis' extent [0, max].
export function axisTicks(axis) {
  if (axis.angle) {
    const maxDeg = axis.max * 180 / Math.PI, step = maxDeg > 120 ? 60 : 30;
    const out = [];
    for (let d = 0; d <= maxDeg + 1e-9; d += step) out.push({ f: d / maxDeg, label: `${d}°` });
    return out;
  }
  const step = niceStep(axis.max / 4), out = [];
  for (let v = 0; v <= axis.max + 1e-9 * step; v += step) out.push({ f: v / axis.max, label: shortNumber(v) });
  return out;
}
// The x and y axes of a slice as SVG around a square of `size` pixels: ticks and labels.
export function sliceAxes(axes, labels, size = 256) {
  const left = 34, bottom = 30;
  const svg = el('svg', { width: size + left + 14, height: size + bottom + 4, class: 'slice-axes' });
  const frame = '#6a6d7a';
  axisTicks(axes[0]).forEach(({ f, label }) => {
    const x = left + f * size;
    svg.append(el('line', { x1: x, x2: x, y1: size + 2, y2: size + 6, stroke: frame }));
    svg.append(text(label, { x, y: size + 16, 'text-anchor': 'middle' }));
  });
  axisTicks(axes[1]).forEach(({ f, label }) => {
    const y = 2 + (1 - f) * size;
    svg.append(el('line', { x1: left - 6, x2: left - 2, y1: y, y2: y, stroke: frame }));
    svg.append(text(label, { x: left - 8, y: y + 3, 'text-anchor': 'end' }));
  });
  svg.append(text(labels[0], { x: left + size / 2, y: size + 28, 'text-anchor': 'middle', fill: '#e6e6ea' }));
  const yl = text(labels[1], { x: 0, y: 0, 'text-anchor': 'middle', fill: '#e6e6ea', transform: `translate(9 ${2 + size / 2}) rotate(-90)` });
  svg.append(yl);
  return svg;
}

// A marker on a canvas at fractional position (x, y) in [0, 1]² (y up): filled when exact,
// hollow when the configuration lies on another slice.
export function drawMarker(canvas, x, y, exact, shape = 'circle') {
  const ctx = canvas.getContext('2d'), w = canvas.width, h = canvas.height;
  const px = x * w, py = (1 - y) * h, r = Math.max(3, w / 60);
  ctx.save();
  ctx.lineWidth = Math.max(1.5, w / 160);
  ctx.strokeStyle = '#fff';
  ctx.fillStyle = '#ff3b6b';
  ctx.beginPath();
  if (shape === 'cross') {
    ctx.moveTo(px - r, py - r); ctx.lineTo(px + r, py + r);
    ctx.moveTo(px - r, py + r); ctx.lineTo(px + r, py - r);
    ctx.stroke();
  } else {
    ctx.arc(px, py, r, 0, 2 * Math.PI);
    if (exact) ctx.fill();
    ctx.stroke();
  }
  ctx.restore();
}

// The equal-area projection of the hemisphere seen from above: disk point of a direction.
export function diskPoint(w) {
  const psi = Math.acos(Math.max(-1, Math.min(1, w[2])));
  const r = Math.SQRT2 * Math.sin(psi / 2), s = Math.hypot(w[0], w[1]);
  return s > 0 ? [r * w[0] / s, r * w[1] / s] : [0, 0];
}
export function diskDirection(u, v) {
  const r = Math.hypot(u, v);
  if (r > 1) return null;
  const psi = 2 * Math.asin(r / Math.SQRT2), s = r > 0 ? Math.sin(psi) / r : 0;
  return [s * u, s * v, Math.cos(psi)];
}

const SVG = 'http://www.w3.org/2000/svg';
function el(name, attrs) {
  const e = document.createElementNS(SVG, name);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  return e;
}

// The values a curve of /api/polar gives a plot: the luminance of ρ, or of ρ cos θi (quantity
// 'cos'); in the plane of incidence θi is the angle t itself, across it (t from the mirror
// direction, turned about the horizontal perpendicular to the plane) cos θi = cos θo cos t.
export function polarValues(curve, key, quantity, thetaO) {
  return curve.angles_deg.map((deg, i) => {
    const y = lum(curve[key][i]), t = deg * Math.PI / 180;
    if (quantity !== 'cos') return y;
    return y * Math.max(0, key === 'in_plane' ? Math.cos(t) : Math.cos(thetaO * Math.PI / 180) * Math.cos(t));
  });
}

// The polar plot: per BRDF, ρ (or ρ cos θi) along the two curves as the radius (t from the
// vertical), `width` CSS pixels wide; texts 11 px whatever the width. The legend is below the
// plot, a row per BRDF (its title, on hover, the whole spec: titles).
export function drawPolar(svg, curves, kind, colours, cursor, names = [], titles = names,
  { quantity = 'rho', thetaO = 45, width = 460 } = {}) {
  svg.replaceChildren();
  const u = 2.3 / width;  // viewBox units per pixel
  const below = names.length ? (50 + 16 * names.length) * u : 40 * u;
  const height = 1.15 + below;
  svg.setAttribute('viewBox', `-1.15 -1.15 2.3 ${height}`);
  svg.setAttribute('width', width);
  svg.setAttribute('height', Math.round(width * height / 2.3));
  svg.append(el('rect', { x: -1.15, y: -1.15, width: 2.3, height, fill: '#111217' }));
  for (const r of [0.25, 0.5, 0.75, 1]) {
    svg.append(el('path', { d: `M ${-r} 0 A ${r} ${r} 0 0 1 ${r} 0`, fill: 'none', stroke: '#333842', 'stroke-width': 0.005 }));
  }
  for (let a = -90; a <= 90; a += 30) {
    const t = a * Math.PI / 180;
    svg.append(el('line', { x1: 0, y1: 0, x2: Math.sin(t), y2: -Math.cos(t), stroke: '#333842', 'stroke-width': 0.005 }));
  }
  const values = curves.map((c) => ({ in_plane: polarValues(c, 'in_plane', quantity, thetaO), across: polarValues(c, 'across', quantity, thetaO) }));
  let max = 0, min = Infinity;
  for (const c of values) for (const k of ['in_plane', 'across']) for (const y of c[k]) {
    if (y > max) max = y;
    if (y > 0 && y < min) min = y;
  }
  const lo = Math.max(Math.log10(min), Math.log10(max) - 4);
  const radius = (y) => kind === 'log' ? Math.max(0, (Math.log10(Math.max(y, 1e-30)) - lo) / (Math.log10(max) - lo || 1)) : y / (max || 1);
  curves.forEach((c, b) => {
    for (const k of ['in_plane', 'across']) {
      let d = '';
      c.angles_deg.forEach((deg, i) => {
        const t = deg * Math.PI / 180, r = radius(values[b][k][i]);
        d += `${i ? 'L' : 'M'} ${(r * Math.sin(t)).toFixed(5)} ${(-r * Math.cos(t)).toFixed(5)} `;
      });
      svg.append(el('path', { d, fill: 'none', stroke: colours[b], 'stroke-width': 0.012, 'stroke-dasharray': k === 'across' ? '0.04 0.025' : 'none' }));
    }
  });
  // Angles from the normal along the arc; the radius' values (luminance of ρ) along the base.
  const fs = 11 * u;
  const small = (content, x, y, anchor = 'middle') => {
    const t = el('text', { x, y, fill: '#9a9cab', 'font-size': fs, 'text-anchor': anchor, 'font-family': 'system-ui, sans-serif' });
    t.textContent = content;
    svg.append(t);
  };
  for (let a = -90; a <= 90; a += 30) {  // ±90° above the base line, clear of the radii's values
    const t = a * Math.PI / 180;
    small(`${Math.abs(a)}°`, (1 + 0.085 * 460 * u) * Math.sin(t), Math.abs(a) === 90 ? -5 * u : -(1 + 0.08 * 460 * u) * Math.cos(t) + 4 * u);
  }
  names.forEach((name, b) => {  // the legend, below the radius' label
    const y = 58 * u + 16 * u * b;
    const g = el('g', { class: 'legend' });
    const title = el('title', {});
    title.textContent = titles[b] || name;
    g.append(title, el('line', { x1: -1.1, x2: -1.1 + 20 * u, y1: y - 4 * u, y2: y - 4 * u, stroke: colours[b], 'stroke-width': 3 * u }));
    svg.append(g);
    const t = el('text', { x: -1.1 + 26 * u, y, fill: '#9a9cab', 'font-size': fs, 'font-family': 'system-ui, sans-serif' });
    t.textContent = name;
    g.append(t);
  });
  const valueAt = (r) => (kind === 'log' ? 10 ** (lo + r * (Math.log10(max) - lo)) : r * max);
  if (max > 0) for (const r of [0.25, 0.5, 0.75, 1]) small(shortNumber(Number(valueAt(r).toPrecision(2))), r, 15 * u);
  if (cursor !== null && cursor !== undefined) {
    const t = cursor * Math.PI / 180;
    svg.append(el('line', { x1: 0, y1: 0, x2: 1.05 * Math.sin(t), y2: -1.05 * Math.cos(t), stroke: '#ff3b6b', 'stroke-width': 0.01 }));
  }
  const label = el('text', { x: -1.1, y: 34 * u, fill: '#9a9cab', 'font-size': 12 * u, 'font-family': 'system-ui, sans-serif' });
  label.textContent = `radius: luminance of ${quantity === 'cos' ? 'ρ cos θi' : 'ρ'} (sr⁻¹${kind === 'log' ? ', log scale' : ''}); ← back   mirror →`;
  svg.append(label);
}

// ρ (or ρ cos θi) against the angle, the polar plot's curves drawn flat: x from −90° (the side
// of ωo) to 90° (the mirror side), y linear or logarithmic (decades), `width` × `height` CSS
// pixels; a legend at the top right; the cursor's angle as a vertical line.
export function drawTheta(svg, curves, colours, names, titles, { quantity = 'rho', scale = 'log', thetaO = 45, width = 460, height = 270, cursor = null } = {}) {
  svg.replaceChildren();
  const W = width, H = height, left = 52, right = 12, top = 12, bottom = 40;
  const total = H + (names.length ? 8 + 14 * names.length : 0);  // the legend below the plot
  svg.setAttribute('width', W);
  svg.setAttribute('height', total);
  svg.setAttribute('viewBox', `0 0 ${W} ${total}`);
  svg.append(el('rect', { x: 0, y: 0, width: W, height: total, fill: '#111217' }));
  const values = curves.map((c) => ({ in_plane: polarValues(c, 'in_plane', quantity, thetaO), across: polarValues(c, 'across', quantity, thetaO) }));
  let max = 0, min = Infinity;
  for (const c of values) for (const k of ['in_plane', 'across']) for (const y of c[k]) {
    if (y > max) max = y;
    if (y > 0 && y < min) min = y;
  }
  if (!(max > 0)) { max = 1; min = 0.1; }
  let y0, y1, ticks;
  if (scale === 'log') {  // whole decades, at most 8 of them below the largest value
    y1 = Math.ceil(Math.log10(max) - 1e-9);
    y0 = Math.max(Math.floor(Math.log10(min)), y1 - 8);
    if (y0 >= y1) y0 = y1 - 1;
    ticks = [];
    for (let k = y0; k <= y1; ++k) ticks.push({ v: k, label: shortNumber(10 ** k) });
  } else {
    const step = niceStep(max / 4);
    y0 = 0;
    y1 = Math.ceil(max / step - 1e-9) * step;
    ticks = [];
    for (let v = 0; v <= y1 + 1e-9 * step; v += step) ticks.push({ v, label: shortNumber(Number(v.toPrecision(6))) });
  }
  const tf = (v) => (scale === 'log' ? (v > 0 ? Math.log10(v) : NaN) : v);
  const x = (deg) => left + (W - left - right) * (deg + 90) / 180;
  const y = (t) => top + (H - top - bottom) * (1 - (t - y0) / (y1 - y0));
  svg.append(el('rect', { x: left, y: top, width: W - left - right, height: H - top - bottom, fill: '#0b0c10' }));
  for (let d = -90; d <= 90; d += 30) {
    svg.append(el('line', { x1: x(d), x2: x(d), y1: y(y0), y2: y(y0) + 4, stroke: '#6a6d7a' }));
    svg.append(text(`${d}°`, { x: x(d), y: y(y0) + 15, 'text-anchor': 'middle', class: 'x-tick' }));
  }
  for (const t of ticks) {
    svg.append(el('line', { x1: left, x2: W - right, y1: y(t.v), y2: y(t.v), stroke: '#262932' }));
    svg.append(text(t.label, { x: left - 6, y: y(t.v) + 3, 'text-anchor': 'end', class: 'y-tick' }));
  }
  svg.append(text('θi, solid; angle from the mirror, dashed (mirror side →)',
    { x: (left + W - right) / 2, y: H - 6, 'text-anchor': 'middle', fill: '#e6e6ea' }));
  svg.append(text(`${quantity === 'cos' ? 'ρ cos θi' : 'ρ'} (sr⁻¹${scale === 'log' ? ', log' : ''})`,
    { x: 0, y: 0, 'text-anchor': 'middle', fill: '#e6e6ea', transform: `translate(12 ${(top + H - bottom) / 2}) rotate(-90)` }));
  curves.forEach((c, b) => {
    for (const k of ['in_plane', 'across']) {
      let d = '', pen = false;
      c.angles_deg.forEach((deg, i) => {
        const t = tf(values[b][k][i]);
        if (!Number.isFinite(t)) { pen = false; return; }
        const ty = Math.max(y0, Math.min(y1, t));
        d += `${pen ? 'L' : 'M'}${x(deg).toFixed(2)},${y(ty).toFixed(2)} `;
        pen = true;
      });
      svg.append(el('path', { d, fill: 'none', stroke: colours[b], 'stroke-width': 2, 'stroke-dasharray': k === 'across' ? '6 4' : 'none', class: `curve-${k}` }));
    }
    const ly = H + 10 + 14 * b;
    svg.append(el('line', { x1: left, x2: left + 18, y1: ly - 4, y2: ly - 4, stroke: colours[b], 'stroke-width': 2 }));
    const g = el('g', { class: 'legend' }), title = el('title', {});
    title.textContent = titles[b] || names[b];
    g.append(title, text(names[b], { x: left + 22, y: ly, fill: '#e6e6ea' }));
    svg.append(g);
  });
  if (cursor !== null && cursor !== undefined) {
    svg.append(el('line', { x1: x(cursor), x2: x(cursor), y1: top, y2: y(y0), stroke: '#ff3b6b', 'stroke-width': 1.5 }));
  }
  return { y0, y1, scale, ticks };
}
const lum = (v) => (v[0] === null ? 0 : 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2]);

// Mean of the accumulated passes, exposed and encoded as sRGB.
export function drawSphere(canvas, sum, passes, w, h, exposure) {
  canvas.width = w;
  canvas.height = h;
  const ctx = canvas.getContext('2d'), img = ctx.createImageData(w, h);
  const scale = Math.pow(2, exposure) / Math.max(passes, 1);
  const srgb = (x) => {
    x = Math.max(0, Math.min(1, x * scale));
    return 255 * (x <= 0.0031308 ? 12.92 * x : 1.055 * Math.pow(x, 1 / 2.4) - 0.055);
  };
  for (let k = 0; k < w * h; ++k) {
    img.data[4 * k] = srgb(sum[3 * k]);
    img.data[4 * k + 1] = srgb(sum[3 * k + 1]);
    img.data[4 * k + 2] = srgb(sum[3 * k + 2]);
    img.data[4 * k + 3] = 255;
  }
  ctx.putImageData(img, 0, 0);
}


// The albedo plot: per BRDF, the luminance of its directional albedo against θi (degrees), with
// a band of ±2 standard errors; axes ticked; a legend; the dashed line at 1.
export function drawAlbedo(svg, curves, colours, names, titles = names, width = 460, height = 270) {
  svg.replaceChildren();
  const W = width, H = height, left = 48, right = 12, top = 12, bottom = 40;
  svg.setAttribute('width', W);
  svg.setAttribute('height', H);
  svg.setAttribute('viewBox', `0 0 ${W} ${H}`);
  const lumOf = (v) => 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2];
  let ymax = 0;
  for (const c of curves) c.albedo.forEach((a, k) => { ymax = Math.max(ymax, lumOf(a) + 2 * lumOf(c.standard_error[k])); });
  const step = niceStep(Math.max(ymax, 0.05) / 4);
  ymax = Math.ceil(Math.max(ymax, 0.05) / step) * step;
  const x = (deg) => left + (W - left - right) * deg / 90, y = (v) => top + (H - top - bottom) * (1 - v / ymax);
  svg.append(el('rect', { x: left, y: top, width: W - left - right, height: H - top - bottom, fill: '#111217' }));
  for (let d = 0; d <= 90; d += 15) {
    svg.append(el('line', { x1: x(d), x2: x(d), y1: y(0), y2: y(0) + 4, stroke: '#6a6d7a' }));
    svg.append(text(`${d}°`, { x: x(d), y: y(0) + 15, 'text-anchor': 'middle' }));
  }
  for (let v = 0; v <= ymax + 1e-9 * step; v += step) {
    svg.append(el('line', { x1: left, x2: W - right, y1: y(v), y2: y(v), stroke: '#262932' }));
    svg.append(text(shortNumber(Number(v.toPrecision(6))), { x: left - 6, y: y(v) + 3, 'text-anchor': 'end' }));
  }
  if (ymax >= 1) svg.append(el('line', { x1: left, x2: W - right, y1: y(1), y2: y(1), stroke: '#9a9cab', 'stroke-dasharray': '4 3' }));
  svg.append(text('θi', { x: (left + W - right) / 2, y: H - 6, 'text-anchor': 'middle', fill: '#e6e6ea' }));
  svg.append(text('albedo', { x: 0, y: 0, 'text-anchor': 'middle', fill: '#e6e6ea', transform: `translate(12 ${(top + H - bottom) / 2}) rotate(-90)` }));
  curves.forEach((c, b) => {
    const lum = c.albedo.map(lumOf), se = c.standard_error.map(lumOf);
    const finite = (k) => Number.isFinite(lum[k]);
    let band = '', line = '';
    c.theta_deg.forEach((t, k) => { if (finite(k)) line += `${line ? 'L' : 'M'}${x(t).toFixed(2)},${y(lum[k]).toFixed(2)} `; });
    c.theta_deg.forEach((t, k) => { if (finite(k)) band += `${band ? 'L' : 'M'}${x(t).toFixed(2)},${y(Math.min(ymax, lum[k] + 2 * se[k])).toFixed(2)} `; });
    [...c.theta_deg].reverse().forEach((t, r) => {
      const k = c.theta_deg.length - 1 - r;
      if (finite(k)) band += `L${x(t).toFixed(2)},${y(Math.max(0, lum[k] - 2 * se[k])).toFixed(2)} `;
    });
    svg.append(el('path', { d: `${band}Z`, fill: colours[b], 'fill-opacity': 0.25, stroke: 'none' }));
    svg.append(el('path', { d: line, fill: 'none', stroke: colours[b], 'stroke-width': 2 }));
    svg.append(el('line', { x1: left + 8, x2: left + 26, y1: top + 12 + 14 * b, y2: top + 12 + 14 * b, stroke: colours[b], 'stroke-width': 2 }));
    const g = el('g', { class: 'legend' }), title = el('title', {});
    title.textContent = titles[b] || names[b] || c.brdf;
    g.append(title, text(names[b] || c.brdf, { x: left + 30, y: top + 16 + 14 * b, fill: '#e6e6ea' }));
    svg.append(g);
  });
}
