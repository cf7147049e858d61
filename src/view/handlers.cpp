#include "handlers.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <numbers>
#include <span>

#include "fields.hpp"
#include "fit/fit_json.hpp"
#include "halfback/brdf/albedo.hpp"
#include "halfback/core/batch.hpp"
#include "halfback/core/parallel.hpp"
#include "halfback/figure/coordinates.hpp"
#include "halfback/fit/fit.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/render/brdf_sampler.hpp"
#include "halfback/render/mesh.hpp"
#include "halfback/render/renderer.hpp"
#include "json.hpp"

namespace halfback::view {

Budget::Budget(double seconds, const std::function<bool()>& abandoned,
               const std::atomic<bool>& stopping)
    : seconds_(seconds),
      deadline_(std::chrono::steady_clock::now() +
                std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                    std::chrono::duration<double>(seconds))),
      abandoned_(abandoned),
      stopping_(stopping) {}

bool Budget::expired() const {
  return stopping_ || std::chrono::steady_clock::now() >= deadline_ || (abandoned_ && abandoned_());
}

double Budget::seconds_left() const {
  const auto left = deadline_ - std::chrono::steady_clock::now();
  return std::max(0.0, std::chrono::duration<double>(left).count());
}

void Budget::check(std::string_view what) const {
  if (stopping_) throw RequestError(503, fmt::format("{} was stopped: the server stops", what));
  if (abandoned_ && abandoned_())
    throw RequestError(503, fmt::format("{} was stopped: the client left", what));
  if (std::chrono::steady_clock::now() >= deadline_)
    throw RequestError(503, fmt::format("{} did not end within {} s, the limit of a request's "
                                        "computation: ask for less (fewer samples, terms or "
                                        "pixels)",
                                        what, seconds_));
}

namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

const std::string& required(const Request& r, std::string_view key) {
  const std::string* v = r.param(key);
  if (!v) throw RequestError(400, fmt::format("missing query parameter '{}'", key));
  return *v;
}

double parse_finite(std::string_view text, std::string_view what) {
  double x = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, x);
  if (ec != std::errc() || ptr != end || !std::isfinite(x))
    throw RequestError(400,
                       fmt::format("{}: '{}' is not a finite number", what, text.substr(0, 64)));
  return x;
}

double number(const Request& r, std::string_view key, double fallback, double lo, double hi) {
  const std::string* v = r.param(key);
  if (!v) return fallback;
  const double x = parse_finite(*v, fmt::format("parameter '{}'", key));
  if (x < lo || x > hi)
    throw RequestError(400, fmt::format("parameter '{}': {} is outside [{}, {}]", key, x, lo, hi));
  return x;
}

std::size_t whole(const Request& r, std::string_view key, std::size_t fallback, std::size_t lo,
                  std::size_t hi) {
  const double x = number(r, key, double(fallback), double(lo), double(hi));
  if (x != std::floor(x))
    throw RequestError(400, fmt::format("parameter '{}': {} is not a whole number", key, x));
  return std::size_t(x);
}

// The names a form parameter accepts, for its error message.
std::string form_names(bool allow_dirs) {
  return fmt::format("{}{}, or dupuy-jakob:BRDF", allow_dirs ? "rho, dirs, " : "",
                     parameterization_names(", "));
}

// The parameterization a request names (Catalog::form: confined, never registered).
ViewForm form_of(const Catalog& catalog, std::string_view key, std::string_view name,
                 bool allow_dirs) {
  const auto f = name == "dirs" ? std::optional<ViewForm>(ViewForm()) : catalog.form(name);
  if (!f || (f->is_dirs() && !allow_dirs))
    throw RequestError(400, fmt::format("parameter '{}': '{}' is not one of {}", key,
                                        name.substr(0, 64), form_names(allow_dirs)));
  return *f;
}

ViewForm space_param(const Catalog& catalog, const Request& r, std::string_view key,
                     bool allow_dirs) {
  return form_of(catalog, key, required(r, key), allow_dirs);
}

std::vector<double> number_list(std::string_view text, std::string_view what, std::size_t count) {
  std::vector<double> v;
  std::size_t start = 0;
  while (v.size() <= count) {
    const std::size_t comma = text.find(',', start);
    v.push_back(parse_finite(text.substr(start, comma - start), what));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  if (v.size() != count)
    throw RequestError(400, fmt::format("{}: expected {} comma-separated numbers", what, count));
  return v;
}

Vec3<double> direction_param(const Request& r, std::string_view key) {
  const auto v = number_list(required(r, key), fmt::format("parameter '{}'", key), 3);
  return {v[0], v[1], v[2]};
}

// ωo from theta_o and phi_o (degrees; the figures' default azimuth, 180°).
Vec3<double> outgoing(const Request& r) {
  const double theta = number(r, "theta_o", 45, 0, 90) * kDegree;
  const double phi = number(r, "phi_o", 180, -360, 720) * kDegree;
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

// [r, g, b], as the page reads a colour.
Json rgb_json(const Rgb& x) {
  return Json::array({x.r, x.g, x.b});
}

Json rgb_list(const std::vector<Rgb>& v) {
  Json list = Json::array();
  for (const Rgb& x : v) list.push_back(rgb_json(x));
  return list;
}

Response json(const Json& j) {
  Response res;
  res.body = json_text(j);
  return res;
}

// Float32 fields, one after the other in the body, each width × height × channels.
Response floats(std::span<const std::vector<float>> fields, std::size_t width, std::size_t height,
                std::size_t channels) {
  Response res;
  res.content_type = "application/octet-stream";
  std::size_t bytes = 0;
  for (const auto& f : fields) bytes += f.size() * sizeof(float);
  res.body.resize(bytes);
  std::size_t offset = 0;
  for (const auto& f : fields) {
    if (!f.empty()) std::memcpy(res.body.data() + offset, f.data(), f.size() * sizeof(float));
    offset += f.size() * sizeof(float);
  }
  res.headers.emplace_back("X-Halfback-Width", std::to_string(width));
  res.headers.emplace_back("X-Halfback-Height", std::to_string(height));
  res.headers.emplace_back("X-Halfback-Channels", std::to_string(channels));
  return res;
}

Response floats(const std::vector<float>& values, std::size_t width, std::size_t height,
                std::size_t channels) {
  return floats({&values, 1}, width, height, channels);
}

// Every value of a repeated key (brdf=...), in order.
std::vector<const std::string*> all_params(const Request& r, std::string_view key) {
  std::vector<const std::string*> out;
  for (const auto& [k, v] : r.query)
    if (k == key) out.push_back(&v);
  return out;
}

// The BRDFs of a request's brdf= (1 to kMaxBrdfsPerRequest, in order): a view of N BRDFs is one
// request, one round trip.
std::vector<std::pair<std::string, BrdfPtr>> brdfs_param(const Catalog& catalog, const Request& r) {
  const std::vector<const std::string*> specs = all_params(r, "brdf");
  if (specs.empty()) throw RequestError(400, "missing query parameter 'brdf'");
  if (specs.size() > kMaxBrdfsPerRequest)
    throw RequestError(413, fmt::format("at most {} brdf= per request (got {})",
                                        kMaxBrdfsPerRequest, specs.size()));
  std::vector<std::pair<std::string, BrdfPtr>> out;
  for (const std::string* s : specs) out.emplace_back(*s, catalog.brdf(*s));
  return out;
}

// The bytes of `count` float fields of n × n × channels, or a 400 above kMaxSlicesBytes.
void check_field_bytes(std::string_view what, std::size_t count, std::size_t n,
                       std::size_t channels) {
  const std::size_t bytes = count * n * n * channels * sizeof(float);
  if (bytes > kMaxSlicesBytes)
    throw RequestError(400, fmt::format("{}: {} field(s) of {}² pixels x {} channel(s) is {} "
                                        "bytes, above the limit of {} (fewer BRDFs or pixels)",
                                        what, count, n, channels, bytes, kMaxSlicesBytes));
}

// `values=`: rgb (the default) or luminance.
RhoValues values_param(const Request& r) {
  const std::string* v = r.param("values");
  if (!v || *v == "rgb") return RhoValues::rgb;
  if (*v == "luminance") return RhoValues::luminance;
  throw RequestError(
      400, fmt::format("parameter 'values': '{}' is not rgb or luminance", v->substr(0, 64)));
}

// The isotropic forms of `forms=` (comma-separated, each at most once, at most
// kMaxCachedForms built for the request); all the registered ones by default.
std::vector<ViewForm> forms_param(const Catalog& catalog, const Request& r) {
  const std::string* text = r.param("forms");
  std::vector<ViewForm> forms;
  if (!text) {
    for (const Space s : parameterizations()) forms.emplace_back(s);
    return forms;
  }
  std::vector<std::string_view> names;
  std::size_t built = 0;
  for (std::string_view rest = *text;;) {
    const std::size_t comma = rest.find(',');
    const std::string_view name = rest.substr(0, comma);
    if (std::find(names.begin(), names.end(), name) != names.end())
      throw RequestError(400,
                         fmt::format("parameter 'forms': '{}' is named twice", name.substr(0, 64)));
    names.push_back(name);
    forms.push_back(form_of(catalog, "forms", name, false));
    if (forms.back().own && ++built > kMaxCachedForms)
      throw RequestError(413, fmt::format("parameter 'forms': at most {} dupuy-jakob:BRDF per "
                                          "request",
                                          kMaxCachedForms));
    if (comma == std::string_view::npos) return forms;
    rest = rest.substr(comma + 1);
  }
}

Json models_json() {
  Json models = Json::array();
  for (const std::string& name : model_registry().names()) {
    const ModelInfo* m = model_registry().find(name);
    if (!m) continue;
    Json params = Json::array();
    for (const ModelParam& p : m->params) {
      Json param;
      param["name"] = p.name;
      param["description"] = p.description;
      param["default"] = p.default_value;
      param["min"] = p.min;
      param["max"] = p.max;
      param["default_from"] = p.default_from;
      param["choices"] = p.choices;
      params.push_back(std::move(param));
    }
    Json model;
    model["name"] = m->name;
    model["description"] = m->description;
    model["params"] = std::move(params);
    models.push_back(std::move(model));
  }
  return models;
}

Json forms_json() {
  Json forms = Json::array();
  for (const Space s : parameterizations()) {
    Json form;
    form["space"] = name_of(s);
    form["summary"] = s.param().summary();
    form["azimuth_label"] = figure::relative_azimuth_label(s);
    form["axes"] = Json::array();
    for (const auto& c : figure::iso_coordinates(s)) {
      Json axis;
      axis["label"] = c.label;
      axis["max"] = c.max;
      axis["angle"] = c.angle;
      form["axes"].push_back(std::move(axis));
    }
    for (const bool iso : {false, true}) {
      Json& columns = form[iso ? "iso_columns" : "columns"] = Json::array();
      for (const auto c : column_names(Form{s, iso})) columns.push_back(c);
    }
    for (const bool iso : {false, true}) {  // of the columns: "rad" or "" (a length)
      Json& units = form[iso ? "iso_units" : "units"] = Json::array();
      for (const Axis& a : s.param().axes(iso)) units.push_back(a.unit());
    }
    forms.push_back(std::move(form));
  }
  return forms;
}

}  // namespace

Response info_response(const Catalog& catalog) {
  Json j;
  j["specs"] = catalog.specs();
  j["models"] = models_json();
  j["forms"] = forms_json();
  j["embedded"] = embedded_material_names();
  const Catalog::Listing files = catalog.list_files(1000);
  j["files"] = files.brdfs;
  Json& environments = j["environments"] = Json::array({"sky", "studio", "sunset"});
  for (const std::string& f : files.environments) environments.push_back("file:" + f);
  Json& meshes = j["meshes"] = Json::array({"embedded:" + std::string(kEmbeddedMesh)});
  for (const std::string& f : files.meshes) meshes.push_back("file:" + f);
  Json& limits = j["limits"];
  limits["grid"] = kMaxGridSide;
  limits["polar"] = kMaxPolarSamples;
  limits["render"] = kMaxRenderSide;
  limits["spp"] = kMaxRenderSpp;
  limits["fit_samples"] = kMaxFitSamples;
  limits["brdfs"] = kMaxBrdfsPerRequest;
  limits["slices_bytes"] = kMaxSlicesBytes;
  Json& losses = j["losses"] = Json::array();
  for (const fit::Loss l : fit::kLosses) losses.push_back(fit::name_of(l));
  return json(j);
}

Response brdf_response(const Catalog& catalog, const Request& request) {
  const std::string& spec = required(request, "brdf");
  const BrdfPtr brdf = catalog.brdf(spec);
  Json j;
  j["spec"] = spec;
  j["name"] = brdf->name();
  j["description"] = brdf->description();
  j["isotropic"] = brdf->isotropic();
  j["reciprocal"] = brdf->reciprocal();
  Json& facts = j["facts"] = Json::array();
  for (const Brdf::Fact& f : brdf->facts()) {
    Json fact;
    fact["label"] = f.label;
    fact["value"] = f.value;
    facts.push_back(std::move(fact));
  }
  return json(j);
}

Response slices_response(const Catalog& catalog, const Request& request, int threads,
                         const Budget& budget) {
  const std::vector<ViewForm> forms = forms_param(catalog, request);
  double azimuth = std::fmod(number(request, "azimuth", 0, -360, 720), 360.0);
  if (azimuth < 0) azimuth += 360.0;
  double radians = azimuth * kDegree;
  if (radians >= 2 * std::numbers::pi) radians = 0;
  // The orientation of the slices about the normal (anisotropic BRDFs), in degrees.
  const double pose = number(request, "pose", 0, -360, 360) * kDegree;
  const std::size_t n = whole(request, "n", 256, 2, kMaxGridSide);
  const RhoValues values = values_param(request);
  const std::vector<const std::string*> specs = all_params(request, "brdf");
  if (specs.empty()) throw RequestError(400, "missing query parameter 'brdf'");
  if (specs.size() > kMaxBrdfsPerRequest)
    throw RequestError(413, fmt::format("at most {} brdf= per /api/slices request (got {})",
                                        kMaxBrdfsPerRequest, specs.size()));
  const std::size_t bytes = specs.size() * forms.size() * n * n * channels_of(values) * 4;
  if (bytes > kMaxSlicesBytes)
    throw RequestError(
        400,
        fmt::format("/api/slices: {} BRDF(s) x {} form(s) x {}² pixels x {} channel(s) is {} "
                    "bytes, above the limit of {} (ask fewer forms, a smaller n, or "
                    "values=luminance)",
                    specs.size(), forms.size(), n, channels_of(values), bytes, kMaxSlicesBytes));
  std::vector<BrdfPtr> brdfs;
  for (const std::string* s : specs) brdfs.push_back(catalog.brdf(*s));
  // One field per (BRDF, form), computed in parallel: a slider update is one request.
  std::vector<std::vector<float>> fields(brdfs.size() * forms.size());
  parallel_for(
      fields.size(), 1,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t k = begin; k < end && !budget.expired(); ++k)
          fields[k] = slice_field(*brdfs[k / forms.size()], forms[k % forms.size()], radians, n,
                                  threads, values, pose, [&] { return budget.expired(); });
      },
      threads);
  budget.check("the slices");
  Response res = floats(fields, n, n, channels_of(values));
  std::string names;
  for (const ViewForm& f : forms) {
    if (!names.empty()) names += ',';
    names += f.name();
  }
  res.headers.emplace_back("X-Halfback-Forms", names);
  res.headers.emplace_back("X-Halfback-Brdfs", std::to_string(brdfs.size()));
  return res;
}

Response hemisphere_response(const Catalog& catalog, const Request& request, int threads,
                             const Budget& budget) {
  const std::string* colour = request.param("colour");
  ViewForm space;
  if (colour && *colour != "rho") space = space_param(catalog, request, "colour", true);
  const std::size_t n = whole(request, "n", 128, 2, kMaxGridSide);
  const Vec3<double> wo = outgoing(request);
  const RhoValues values = space.is_dirs() ? values_param(request) : RhoValues::rgb;
  const auto expired = [&] { return budget.expired(); };
  if (!space.is_dirs()) {
    budget.check("the hemisphere");
    const std::vector<float> field =
        hemisphere_field(nullptr, space, wo, n, threads, values, expired);
    budget.check("the hemisphere");
    return floats(field, n, n, channels_of(values));
  }
  // ρ of every BRDF of brdf= (one field each, in order): one request for all the BRDFs shown.
  const auto brdfs = brdfs_param(catalog, request);
  check_field_bytes("/api/hemisphere", brdfs.size(), n, channels_of(values));
  std::vector<std::vector<float>> fields;
  for (const auto& [spec, brdf] : brdfs) {
    budget.check("the hemisphere");
    fields.push_back(hemisphere_field(brdf.get(), space, wo, n, threads, values, expired));
  }
  budget.check("the hemisphere");
  Response res = floats(fields, n, n, channels_of(values));
  res.headers.emplace_back("X-Halfback-Brdfs", std::to_string(brdfs.size()));
  return res;
}

Response polar_response(const Catalog& catalog, const Request& request) {
  const std::size_t n = whole(request, "n", 181, 2, kMaxPolarSamples);
  const Vec3<double> wo = outgoing(request);
  const auto brdfs = brdfs_param(catalog, request);
  // `curves`: one per brdf= (in order); the first one's also at the top level.
  Json j, curves = Json::array();
  for (const auto& [spec, brdf] : brdfs) {
    const PolarCurves c = polar_curves(*brdf, wo, n);
    if (curves.empty()) {
      j["angles_deg"] = c.angles_deg;
      j["in_plane"] = rgb_list(c.in_plane);
      j["across"] = rgb_list(c.across);
    }
    Json curve;
    curve["brdf"] = spec;
    curve["in_plane"] = rgb_list(c.in_plane);
    curve["across"] = rgb_list(c.across);
    curves.push_back(std::move(curve));
  }
  j["curves"] = std::move(curves);
  return json(j);
}

Response albedo_response(const Catalog& catalog, const Request& request, int threads,
                         const Budget& budget) {
  const std::size_t angles = whole(request, "angles", 90, 2, kMaxAlbedoAngles);  // 0°, 1°, …, 89°
  const int n = int(whole(request, "n", 64, 1, kMaxAlbedoSamples));
  const auto brdfs = brdfs_param(catalog, request);
  // θi from 0° to 89° (90° itself grazes: the cosine-weighted integral is 0 there for most BRDFs
  // and undefined for measured ones), each estimate the one `halfback info` prints (same seed).
  std::vector<double> theta(angles);
  for (std::size_t k = 0; k < angles; ++k) theta[k] = 89.0 * double(k) / double(angles - 1);
  std::vector<AlbedoEstimate> a(angles * brdfs.size());
  parallel_for(
      a.size(), 1,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t k = begin; k < end && !budget.expired(); ++k) {
          const double t = theta[k % angles] * kDegree;
          a[k] = directional_albedo(*brdfs[k / angles].second, {std::sin(t), 0, std::cos(t)}, n);
        }
      },
      threads);
  budget.check("the albedo curve");
  // `curves`: one per brdf= (in order); the first one's also at the top level.
  Json j, curves = Json::array();
  j["samples"] = n * n;
  j["theta_deg"] = theta;
  for (std::size_t b = 0; b < brdfs.size(); ++b) {
    const auto rgbs = [&](Rgb AlbedoEstimate::*member) {
      Json list = Json::array();
      for (std::size_t k = 0; k < angles; ++k) list.push_back(rgb_json(a[b * angles + k].*member));
      return list;
    };
    Json curve;
    curve["brdf"] = brdfs[b].second->name();
    curve["spec"] = brdfs[b].first;
    curve["samples"] = n * n;
    curve["theta_deg"] = theta;
    curve["albedo"] = rgbs(&AlbedoEstimate::mean);
    curve["standard_error"] = rgbs(&AlbedoEstimate::standard_error);
    Json& measured = curve["measured"] = Json::array();
    for (std::size_t k = 0; k < angles; ++k) measured.push_back(a[b * angles + k].measured);
    if (b == 0)
      for (const char* key : {"brdf", "albedo", "standard_error", "measured"}) j[key] = curve[key];
    curves.push_back(std::move(curve));
  }
  j["curves"] = std::move(curves);
  return json(j);
}

namespace {

// The pair a /api/point request names: wi and wo, or form (+ iso) and coords.
bool point_pair(const Catalog& catalog, const Request& request, DirPair<double>& pair) {
  if (request.param("wi") || request.param("wo")) {
    pair = {direction_param(request, "wi"), direction_param(request, "wo")};
    const PairStatus status = accept_pair(pair);
    if (status == PairStatus::not_finite || status == PairStatus::wi_not_unit ||
        status == PairStatus::wo_not_unit)
      throw RequestError(400, std::string(describe(status)));
    return true;
  }
  const ViewForm form = space_param(catalog, request, "form", false);
  const std::string* iso_text = request.param("iso");
  const bool iso = iso_text && *iso_text == "1";
  std::vector<double> q =
      number_list(required(request, "coords"), "parameter 'coords'", iso ? 3 : 4);
  if (form.own) {  // a request's parameterization: its own checked inverse
    std::vector<DirPair<double>> pairs;
    std::vector<std::uint8_t> valid;
    form_to_pairs(form, iso, q, pairs, valid, 1);
    pair = pairs[0];
    return valid[0] != 0;
  }
  const Form from{form.space, iso};
  double d[6];
  const bool ok = convert_one<double>(from, Form{Space::dirs, false}, q, d);
  pair = {{d[0], d[1], d[2]}, {d[3], d[4], d[5]}};
  return ok;
}

Json coordinates_json(const DirPair<double>& pair, bool valid) {
  const double d[6] = {pair.wi.x, pair.wi.y, pair.wi.z, pair.wo.x, pair.wo.y, pair.wo.z};
  Json forms = Json::array();
  for (const Space s : parameterizations()) {
    Json form;
    form["space"] = name_of(s);
    for (const bool iso : {false, true}) {
      const Form to{s, iso};
      double q[4] = {NAN, NAN, NAN, NAN}, jacobian = NAN;
      if (valid)
        convert_one<double>(Form{Space::dirs, false}, to, d, {q, dimension(to)}, &jacobian);
      form[iso ? "iso" : "coords"] = std::vector<double>(q, q + dimension(to));
      form[iso ? "iso_jacobian" : "jacobian"] = jacobian;
    }
    forms.push_back(std::move(form));
  }
  return forms;
}

}  // namespace

Response point_response(const Catalog& catalog, const Request& request) {
  std::vector<BrdfPtr> brdfs;
  const std::vector<const std::string*> specs = all_params(request, "brdf");
  if (specs.size() > kMaxBrdfsPerRequest)
    throw RequestError(413, fmt::format("at most {} brdf= per request", kMaxBrdfsPerRequest));
  for (const std::string* s : specs) brdfs.push_back(catalog.brdf(*s));
  DirPair<double> pair{};
  const bool valid = point_pair(catalog, request, pair);
  Json j;
  j["valid"] = valid;
  j["wi"] = {pair.wi.x, pair.wi.y, pair.wi.z};
  j["wo"] = {pair.wo.x, pair.wo.y, pair.wo.z};
  j["forms"] = coordinates_json(pair, valid);
  Json& rho_list = j["rho"] = Json::array();
  for (std::size_t b = 0; b < brdfs.size(); ++b) {
    Rgb rho{NAN, NAN, NAN};
    if (valid) brdfs[b]->eval_batch({&pair, 1}, {&rho, 1});  // as `halfback eval` does
    Json entry;
    entry["brdf"] = *specs[b];
    entry["rgb"] = rgb_json(rho);
    rho_list.push_back(std::move(entry));
  }
  return json(j);
}

Response render_response(const Catalog& catalog, const Request& request, int threads,
                         const Budget& budget) {
  render::RenderSettings s;
  s.width = s.height = int(whole(request, "size", 128, 8, std::size_t(kMaxRenderSide)));
  s.spp = int(whole(request, "spp", 4, 1, std::size_t(kMaxRenderSpp)));
  s.seed = whole(request, "pass", 0, 0, 1u << 20) + 1;  // each pass an independent estimate
  s.threads = threads;
  const std::string* env_spec = request.param("env");
  const auto env = catalog.environment(env_spec ? std::string_view(*env_spec) : "sky");
  const BrdfPtr brdf = catalog.sampled_brdf(required(request, "brdf"));
  budget.check("the render");
  s.time_budget = std::max(budget.seconds_left(), 1e-3);  // fewer samples (X-Halfback-Spp) past it
  render::RenderResult result;
  try {
    result = render::render_sampled(*brdf, *env, s);
  } catch (const render::TimeBudgetExceeded&) {
    budget.check("the render");
    throw RequestError(503, "the render did not take one sample per pixel within its time");
  }
  Response res = floats(result.image.rgb, std::size_t(s.width), std::size_t(s.height), 3);
  res.headers.emplace_back("X-Halfback-Spp", std::to_string(result.spp));
  return res;
}

// The sphere under a distant light from (theta_l, phi_l) in camera space (degrees; θ = 0: from
// the camera, φ = 0: from the right), evaluated at k × k positions per pixel (no noise).
Response point_light_response(const Catalog& catalog, const Request& request, int threads,
                              const Budget& budget) {
  render::RenderSettings s;
  s.width = s.height = int(whole(request, "size", 128, 8, std::size_t(kMaxRenderSide)));
  s.spp = int(whole(request, "spp", 4, 1, std::size_t(kMaxRenderSpp)));
  s.threads = threads;
  const double theta = number(request, "theta_l", 0, 0, 90) * kDegree;
  const double phi = number(request, "phi_l", 0, -360, 360) * kDegree;
  const Vec3<double> light{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                           std::cos(theta)};
  // Every BRDF of brdf= (one image each, in order): one request for all the spheres shown.
  const auto brdfs = brdfs_param(catalog, request);
  check_field_bytes("/api/pointlight", brdfs.size(), std::size_t(s.width), 3);
  std::vector<std::vector<float>> images;
  int spp = 0;
  for (const auto& [spec, brdf] : brdfs) {
    budget.check("the point-light image");
    s.time_budget = std::max(budget.seconds_left(), 1e-3);  // checked at every row of the image
    render::RenderResult result;
    try {
      result = render::render_point_light(*brdf, light, s);
    } catch (const render::TimeBudgetExceeded&) {
      budget.check("the point-light image");
      throw RequestError(503, "the point-light image was not complete within its time");
    }
    images.push_back(std::move(result.image.rgb));
    spp = result.spp;
  }
  Response res = floats(images, std::size_t(s.width), std::size_t(s.height), 3);
  res.headers.emplace_back("X-Halfback-Spp", std::to_string(spp));
  res.headers.emplace_back("X-Halfback-Brdfs", std::to_string(brdfs.size()));
  return res;
}

// The mesh of `mesh=` (embedded:NAME or file:PATH.obj) under a point light (light=point, from
// theta_l, phi_l in camera space as /api/pointlight) or an environment (light=env, env= as
// /api/render; pass= the seed), turned by yaw and pitch (degrees): one image per brdf=.
Response mesh_response(const Catalog& catalog, const Request& request, int threads,
                       const Budget& budget) {
  render::MeshSettings s;
  s.width = s.height = int(whole(request, "size", 256, 8, std::size_t(kMaxRenderSide)));
  s.spp = int(whole(request, "spp", 4, 1, std::size_t(kMaxRenderSpp)));
  s.supersample = 2;
  s.seed = whole(request, "pass", 0, 0, 1u << 20) + 1;
  s.yaw_deg = number(request, "yaw", 35, -360, 360);
  s.pitch_deg = number(request, "pitch", 25, -90, 90);
  s.threads = threads;
  const std::string* light = request.param("light");
  const bool point = !light || *light == "point";
  if (!point && *light != "env")
    throw RequestError(
        400, fmt::format("parameter 'light': '{}' is not point or env", light->substr(0, 64)));
  const std::string* mesh_spec = request.param("mesh");
  const std::string default_mesh = "embedded:" + std::string(kEmbeddedMesh);
  const auto mesh = catalog.mesh(mesh_spec ? *mesh_spec : default_mesh);
  const auto brdfs = brdfs_param(catalog, request);
  check_field_bytes("/api/mesh", brdfs.size(), std::size_t(s.width), 3);
  std::shared_ptr<const render::EnvMap> env;
  Vec3<double> dir{0, 0, 1};
  if (point) {
    const double theta = number(request, "theta_l", 0, 0, 90) * kDegree;
    const double phi = number(request, "phi_l", 0, -360, 360) * kDegree;
    dir = {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
  } else {
    const std::string* env_spec = request.param("env");
    env = catalog.environment(env_spec ? std::string_view(*env_spec) : "sky");
  }
  // The deadline (and the client's leaving) polled at every row of each BRDF's image.
  s.cancelled = [&budget] { return budget.expired(); };
  std::vector<std::vector<float>> images;
  for (const auto& [spec, brdf] : brdfs) {
    budget.check("the mesh");
    render::Image image;
    try {
      image = point ? render::render_mesh_point_light(*brdf, *mesh, dir, s)
                    : render::render_mesh_environment(*catalog.sampled_brdf(spec), *env, *mesh, s);
    } catch (const render::MeshRenderCancelled&) {
      budget.check("the mesh");
      throw RequestError(503, "the mesh was stopped");
    }
    images.push_back(std::move(image.rgb));
  }
  budget.check("the mesh");
  Response res = floats(images, std::size_t(s.width), std::size_t(s.height), 3);
  res.headers.emplace_back("X-Halfback-Brdfs", std::to_string(brdfs.size()));
  res.headers.emplace_back("X-Halfback-Triangles", std::to_string(mesh->triangles.size()));
  return res;
}

namespace {

// Counts a fit in progress for its lifetime; a second one at the same time is refused (503).
class FitSlot {
 public:
  explicit FitSlot(std::atomic<int>& running) : running_(running) {
    if (running_.fetch_add(1) > 0) {
      running_.fetch_sub(1);
      throw RequestError(503, "another fit is running (one at a time): try again when it ends");
    }
  }
  ~FitSlot() { running_.fetch_sub(1); }
  FitSlot(const FitSlot&) = delete;
  FitSlot& operator=(const FitSlot&) = delete;

 private:
  std::atomic<int>& running_;
};

}  // namespace

// The model of `model=` (a sum of lobes of the registry) fitted to `brdf=` under `loss=`, with
// `samples=` pairs (docs/fit.md); the answer is the JSON `halfback fit` writes.
Response fit_response(const Catalog& catalog, const Request& request, int threads,
                      std::atomic<int>& running, const Budget& budget) {
  const std::string& spec = required(request, "brdf");
  const std::string& model = required(request, "model");
  if (model.size() > kMaxSpecBytes)
    throw RequestError(413, fmt::format("model longer than {} bytes", kMaxSpecBytes));
  refuse_paths(model);  // a model never names a file
  fit::FitOptions options;
  const std::string* loss = request.param("loss");
  if (loss) {
    const auto parsed = fit::parse_loss(*loss);
    if (!parsed)
      throw RequestError(400, fmt::format("parameter 'loss': '{}' is not one of {}",
                                          loss->substr(0, 64), fit::loss_names()));
    options.loss = *parsed;
  }
  options.samples = whole(request, "samples", 5000, 100, kMaxFitSamples);
  options.threads = threads;
  options.cancelled = [&budget] { return budget.expired(); };
  // A bad model is a 400 before the BRDF is loaded, and so is one too large to fit in time.
  const std::size_t terms = fit::parse_model(model).terms.size();
  if (terms * options.samples > kMaxFitTermSamples)
    throw RequestError(400, fmt::format("a fit of {} term(s) at {} samples is {} term-samples, "
                                        "above the limit of {}: fewer terms, or samples <= {}",
                                        terms, options.samples, terms * options.samples,
                                        kMaxFitTermSamples, kMaxFitTermSamples / terms));
  const BrdfPtr target = catalog.brdf(spec);
  const FitSlot slot(running);
  fit::FitResult result;
  try {
    result = fit::fit(*target, model, options);
  } catch (const fit::FitCancelled&) {
    budget.check("the fit");
    throw RequestError(503, "the fit was stopped");
  } catch (const fit::FitDataError& e) {
    throw RequestError(422,
                       fmt::format("'{}' cannot be fitted: {}", spec.substr(0, 128), e.what()));
  }
  return json(fit::fit_json(result, spec, model, fit::fitted_energy(result.spec)));
}

}  // namespace halfback::view
