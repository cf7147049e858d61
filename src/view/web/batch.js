// One request per view for every BRDF shown (docs/view.md, "API"): the hemisphere, the lobe, the
// polar plot, the albedo plot, the point-lit spheres and the lit mesh ask the server once with
// brdf= repeated (at most `limit` per request: 8), and get one part per BRDF in order.
import { getJson, getFields } from './api.js';

const LIMIT = 8;

// The lists of at most LIMIT specs that a list is sent in (one request each; one for 8 or fewer).
function groups(specs) {
  const out = [];
  for (let k = 0; k < specs.length; k += LIMIT) out.push(specs.slice(k, k + LIMIT));
  return out;
}
const brdfParams = (specs) => specs.map((s) => ['brdf', s]);

// Float32 fields, one per spec (in order): /api/hemisphere (colour=rho), /api/pointlight,
// /api/mesh.
export async function fieldsOf(slot, path, specs, params) {
  const answers = await Promise.all(groups(specs).map((g, k) =>
    getFields(slot && `${slot}-${k}`, path, [...brdfParams(g), ...params])));
  return answers.flatMap((a) => a.fields);
}

// The polar curves of every spec, each { angles_deg, in_plane, across } as /api/polar answers
// one BRDF.
export async function polarCurves(slot, specs, params) {
  const answers = await Promise.all(groups(specs).map((g, k) =>
    getJson(slot && `${slot}-${k}`, '/api/polar', [...brdfParams(g), ...params])));
  return answers.flatMap((r) => r.curves.map((c) => ({ angles_deg: r.angles_deg, in_plane: c.in_plane, across: c.across })));
}

// The albedo curves of every spec, each as /api/albedo answers one BRDF.
export async function albedoCurves(slot, specs, params) {
  const answers = await Promise.all(groups(specs).map((g, k) =>
    getJson(slot && `${slot}-${k}`, '/api/albedo', [...brdfParams(g), ...params])));
  return answers.flatMap((r) => r.curves);
}
