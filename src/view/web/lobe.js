// The 3D lobe of ρ(·, ωo): for the current ωo, each direction ωi of the upper hemisphere pushed
// out to a radius that grows with ρ (or ρ cos θi), one surface per BRDF in its colour, with the
// normal, ωo and its mirror direction as lines; WebGL 2, turned by dragging. The surface is built
// from the hemisphere fields of /api/hemisphere (ρ at the equal-area grid's pixel centres), so the
// radii are the server's values.
import { diskDirection } from './views.js';

const VERTEX = `#version 300 es
uniform mat4 view;
in vec3 position;
out vec3 world;
void main() { world = position; gl_Position = view * vec4(position, 1.0); }`;
const FRAGMENT = `#version 300 es
precision highp float;
uniform vec4 colour;
uniform int lit;
uniform vec3 eye;
in vec3 world;
out vec4 outColour;
void main() {
  if (lit == 0) { outColour = colour; return; }
  vec3 n = normalize(cross(dFdx(world), dFdy(world)));  // flat shading, either side
  float light = 0.35 + 0.65 * abs(dot(n, normalize(eye - world)));
  outColour = vec4(colour.rgb * light, colour.a);
}`;

function compile(gl, type, source) {
  const s = gl.createShader(type);
  gl.shaderSource(s, source);
  gl.compileShader(s);
  if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
  return s;
}

// Column-major 4 × 4 matrices.
function multiply(a, b) {
  const out = new Float32Array(16);
  for (let c = 0; c < 4; ++c)
    for (let r = 0; r < 4; ++r) {
      let v = 0;
      for (let k = 0; k < 4; ++k) v += a[k * 4 + r] * b[c * 4 + k];
      out[c * 4 + r] = v;
    }
  return out;
}
function perspective(fovDeg, aspect, near, far) {
  const f = 1 / Math.tan(fovDeg * Math.PI / 360), d = near - far;
  return new Float32Array([f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) / d, -1, 0, 0, 2 * far * near / d, 0]);
}
// A camera on a sphere of radius `distance` around (0, 0, 0.3), z up, at azimuth `yaw` and
// elevation `pitch` (radians): the view matrix and the eye position.
function orbit(yaw, pitch, distance) {
  const target = [0, 0, 0.3];
  const eye = [target[0] + distance * Math.cos(pitch) * Math.cos(yaw),
    target[1] + distance * Math.cos(pitch) * Math.sin(yaw), target[2] + distance * Math.sin(pitch)];
  const f = normalize3([target[0] - eye[0], target[1] - eye[1], target[2] - eye[2]]);
  const s = normalize3(cross3(f, [0, 0, 1])), u = cross3(s, f);
  const m = new Float32Array([s[0], u[0], -f[0], 0, s[1], u[1], -f[1], 0, s[2], u[2], -f[2], 0,
    -dot3(s, eye), -dot3(u, eye), dot3(f, eye), 1]);
  return { matrix: m, eye };
}
const dot3 = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross3 = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const normalize3 = (a) => { const l = Math.hypot(...a); return a.map((x) => x / l); };

// The lobe's vertices (one per pixel centre inside the disk) and triangles (cells whose four
// corners are inside) from a luminance field; radius = value / max, or log-scaled over 3 decades.
export function lobeMesh(field, { cosine = false, log = false, max } = {}) {
  const { width: n, data } = field;
  const dirs = new Float32Array(3 * n * n), values = new Float32Array(n * n).fill(NaN);
  for (let j = 0; j < n; ++j)
    for (let i = 0; i < n; ++i) {
      const d = diskDirection(-1 + (2 * i + 1) / n, -1 + (2 * j + 1) / n), k = j * n + i;
      if (!d || !Number.isFinite(data[k])) continue;
      dirs.set(d, 3 * k);
      values[k] = cosine ? data[k] * d[2] : data[k];
    }
  let top = max;
  if (top === undefined) { top = 0; for (const v of values) if (v > top) top = v; }
  const radius = (v) => {
    if (!(v > 0) || !(top > 0)) return 0;
    return log ? Math.max(0, 1 + Math.log10(v / top) / 3) : v / top;
  };
  const positions = new Float32Array(3 * n * n);
  for (let k = 0; k < n * n; ++k) {
    const r = radius(values[k]);
    positions[3 * k] = r * dirs[3 * k];
    positions[3 * k + 1] = r * dirs[3 * k + 1];
    positions[3 * k + 2] = r * dirs[3 * k + 2];
  }
  const indices = [];
  const ok = (i, j) => Number.isFinite(values[j * n + i]);
  for (let j = 0; j + 1 < n; ++j)
    for (let i = 0; i + 1 < n; ++i) {
      if (!(ok(i, j) && ok(i + 1, j) && ok(i, j + 1) && ok(i + 1, j + 1))) continue;
      const a = j * n + i, b = a + 1, c = a + n, d = c + 1;
      indices.push(a, b, d, a, d, c);
    }
  return { positions, indices: new Uint32Array(indices), values, dirs, max: top, n };
}

export class LobeView {
  constructor(canvas) {
    this.canvas = canvas;
    this.gl = canvas.getContext('webgl2', { antialias: true, preserveDrawingBuffer: true });
    this.yaw = -Math.PI / 2 - 0.5;
    this.pitch = 0.45;
    this.meshes = [];
    this.lines = [];
    this.opacity = 0.55;  // of every surface: below 1 each shows through the others
    this.zoom = 1;
    if (!this.gl) return;
    const gl = this.gl, p = gl.createProgram();
    gl.attachShader(p, compile(gl, gl.VERTEX_SHADER, VERTEX));
    gl.attachShader(p, compile(gl, gl.FRAGMENT_SHADER, FRAGMENT));
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
    this.program = p;
    this.at = { view: gl.getUniformLocation(p, 'view'), colour: gl.getUniformLocation(p, 'colour'),
      lit: gl.getUniformLocation(p, 'lit'), eye: gl.getUniformLocation(p, 'eye'),
      position: gl.getAttribLocation(p, 'position') };
    this.setupDrag();
  }

  get available() { return Boolean(this.gl); }

  setupDrag() {
    let last = null;
    this.canvas.addEventListener('mousedown', (e) => { last = [e.clientX, e.clientY]; });
    window.addEventListener('mouseup', () => { last = null; });
    window.addEventListener('mousemove', (e) => {
      if (!last) return;
      this.yaw -= (e.clientX - last[0]) * 0.01;
      this.pitch = Math.min(1.5, Math.max(-0.2, this.pitch + (e.clientY - last[1]) * 0.01));
      last = [e.clientX, e.clientY];
      this.draw();
    });
  }

  buffer(data, target = this.gl.ARRAY_BUFFER) {
    const gl = this.gl, b = gl.createBuffer();
    gl.bindBuffer(target, b);
    gl.bufferData(target, data, gl.STATIC_DRAW);
    return b;
  }

  // meshes: [{ mesh (lobeMesh), colour: [r, g, b] in 0 … 1 }]; wo: the outgoing direction.
  set(meshes, wo) {
    if (!this.gl) return;
    const gl = this.gl;
    for (const m of this.meshes) { gl.deleteBuffer(m.vertices); gl.deleteBuffer(m.elements); }
    this.meshes = meshes.map(({ mesh, colour }) => ({
      vertices: this.buffer(mesh.positions), elements: this.buffer(mesh.indices, gl.ELEMENT_ARRAY_BUFFER),
      count: mesh.indices.length, colour,
    }));
    // Rings on the ground at radius 1 (the largest value shown) and ½: the scale.
    const circle = [], half = [];
    for (let k = 0; k < 64; ++k) {
      const a = 2 * Math.PI * k / 64, b = 2 * Math.PI * (k + 1) / 64;
      circle.push(Math.cos(a), Math.sin(a), 0, Math.cos(b), Math.sin(b), 0);
      half.push(0.5 * Math.cos(a), 0.5 * Math.sin(a), 0, 0.5 * Math.cos(b), 0.5 * Math.sin(b), 0);
    }
    const mirror = [-wo[0], -wo[1], wo[2]];
    for (const l of this.lines) gl.deleteBuffer(l.vertices);
    this.lines = [
      { data: circle, colour: [0.45, 0.47, 0.55, 1] },
      { data: half, colour: [0.33, 0.35, 0.42, 1] },
      { data: [0, 0, 0, 0, 0, 1.15], colour: [0.75, 0.75, 0.8, 1] },  // the normal
      { data: [0, 0, 0, ...wo.map((x) => 1.15 * x)], colour: [1, 0.23, 0.42, 1] },  // ωo
      { data: [0, 0, 0, ...mirror.map((x) => 1.15 * x)], colour: [1, 1, 1, 1] },  // its mirror
    ].map((l) => ({ vertices: this.buffer(new Float32Array(l.data)), count: l.data.length / 3, colour: l.colour }));
    this.draw();
  }

  draw() {
    if (!this.gl) return;
    const gl = this.gl, c = this.canvas;
    gl.viewport(0, 0, c.width, c.height);
    gl.clearColor(0.067, 0.071, 0.09, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    gl.useProgram(this.program);
    const { matrix, eye } = orbit(this.yaw, this.pitch, 3.2 / (this.zoom || 1));
    gl.uniformMatrix4fv(this.at.view, false, multiply(perspective(35, c.width / c.height, 0.1, 20), matrix));
    gl.uniform3fv(this.at.eye, eye);
    const attrib = (b) => {
      gl.bindBuffer(gl.ARRAY_BUFFER, b);
      gl.enableVertexAttribArray(this.at.position);
      gl.vertexAttribPointer(this.at.position, 3, gl.FLOAT, false, 0, 0);
    };
    gl.uniform1i(this.at.lit, 0);
    for (const l of this.lines) {
      attrib(l.vertices);
      gl.uniform4fv(this.at.colour, l.colour);
      gl.drawArrays(gl.LINES, 0, l.count);
    }
    gl.uniform1i(this.at.lit, 1);
    // See-through surfaces write no depth, so that none hides another (an opaque first surface
    // around the others hid them); at opacity 1 they are solid and the nearest one shows.
    const opacity = Math.min(1, Math.max(0.05, this.opacity));
    if (opacity < 1) {
      gl.enable(gl.BLEND);
      gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA);
      gl.depthMask(false);
    }
    this.meshes.forEach((m) => {
      attrib(m.vertices);
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, m.elements);
      gl.uniform4fv(this.at.colour, [...m.colour, opacity]);
      gl.drawElements(gl.TRIANGLES, m.count, gl.UNSIGNED_INT, 0);
    });
    gl.depthMask(true);
    gl.disable(gl.BLEND);
  }
}
