// Requests to the halfback view server. Every request carries the token of the page's URL (the
// server also accepts the cookie that the first load set). A request given a slot cancels the
// older one of the same slot (the sphere's passes, the hovered point); the views that follow a
// slider or a drag are coalesced in app.js instead (one in flight, one waiting).
const token = new URLSearchParams(location.search).get('token') || '';

function url(path, params) {
  const q = new URLSearchParams();
  for (const [k, v] of params) if (v !== undefined && v !== null) q.append(k, String(v));
  if (token) q.append('token', token);
  return `${path}?${q}`;
}

async function check(response) {
  if (response.ok) return response;
  let message = `${response.status} ${response.statusText}`;
  try {
    message = (await response.json()).error || message;
  } catch (e) { /* not JSON */ }
  const error = new Error(message);
  error.status = response.status;
  throw error;
}

const controllers = new Map();

// fetch() of path?params, cancelling the previous request with the same `slot`.
async function request(slot, path, params) {
  if (slot) {
    controllers.get(slot)?.abort();
    const c = new AbortController();
    controllers.set(slot, c);
    return check(await fetch(url(path, params), { signal: c.signal, credentials: 'same-origin' }));
  }
  return check(await fetch(url(path, params), { credentials: 'same-origin' }));
}

export async function getJson(slot, path, params = []) {
  return (await request(slot, path, params)).json();
}

// Float32 fields, one after the other in the body, all of the same size: { fields: [{ width,
// height, channels, data: Float32Array }], headers }. /api/slices answers several at once.
export async function getFields(slot, path, params) {
  const r = await request(slot, path, params);
  const buffer = await r.arrayBuffer();
  const width = Number(r.headers.get('X-Halfback-Width'));
  const height = Number(r.headers.get('X-Halfback-Height'));
  const channels = Number(r.headers.get('X-Halfback-Channels'));
  const size = width * height * channels, fields = [];
  for (let offset = 0; size > 0 && offset + 4 * size <= buffer.byteLength; offset += 4 * size)
    fields.push({ width, height, channels, data: new Float32Array(buffer, offset, size) });
  return { fields, headers: r.headers };
}

// One float32 field: { width, height, channels, data: Float32Array }.
export async function getField(slot, path, params) {
  return (await getFields(slot, path, params)).fields[0];
}

export function isAbort(e) {
  return e && e.name === 'AbortError';
}
