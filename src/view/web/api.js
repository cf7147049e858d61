// Requests to the halfback view server. Every request carries the token of the page's URL (the
// server also accepts the cookie that the first load set), and a newer request of the same kind
// cancels the older one, so that dragging never queues stale work.
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

// A float32 field: { width, height, channels, data: Float32Array }.
export async function getField(slot, path, params) {
  const r = await request(slot, path, params);
  const buffer = await r.arrayBuffer();
  return {
    width: Number(r.headers.get('X-Halfback-Width')),
    height: Number(r.headers.get('X-Halfback-Height')),
    channels: Number(r.headers.get('X-Halfback-Channels')),
    data: new Float32Array(buffer),
  };
}

export function isAbort(e) {
  return e && e.name === 'AbortError';
}
