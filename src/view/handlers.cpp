#include "handlers.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <numbers>
#include <span>

#include "fields.hpp"
#include "fit_json.hpp"
#include "halfback/brdf/albedo.hpp"
#include "halfback/core/batch.hpp"
#include "halfback/core/parallel.hpp"
#include "halfback/figure/coordinates.hpp"
#include "halfback/fit/fit.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/render/renderer.hpp"
#include "json.hpp"

namespace halfback::view {

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

Space space_param(const Request& r, std::string_view key, bool allow_dirs) {
  const std::string& name = required(r, key);
  const auto s = space_from_name(name);
  if (!s || (*s == Space::dirs && !allow_dirs))
    throw RequestError(
        400, fmt::format("parameter '{}': '{}' is not one of {}", key, name.substr(0, 64),
                         allow_dirs ? "rho, " + space_names() : parameterization_names(", ")));
  return *s;
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

Response json(const JsonWriter& w) {
  Response res;
  res.body = w.str();
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

// `values=`: rgb (the default) or luminance.
RhoValues values_param(const Request& r) {
  const std::string* v = r.param("values");
  if (!v || *v == "rgb") return RhoValues::rgb;
  if (*v == "luminance") return RhoValues::luminance;
  throw RequestError(
      400, fmt::format("parameter 'values': '{}' is not rgb or luminance", v->substr(0, 64)));
}

// The isotropic forms of `forms=` (comma-separated, each at most once); all by default.
std::vector<Space> forms_param(const Request& r) {
  const std::string* text = r.param("forms");
  if (!text) return parameterizations();
  std::vector<Space> forms;
  std::string_view rest = *text;
  while (true) {
    const std::size_t comma = rest.find(',');
    const std::string_view name = rest.substr(0, comma);
    const auto s = space_from_name(name);
    if (!s || *s == Space::dirs)
      throw RequestError(400, fmt::format("parameter 'forms': '{}' is not one of {} "
                                          "(comma-separated)",
                                          name.substr(0, 64), parameterization_names(", ")));
    if (std::find(forms.begin(), forms.end(), *s) != forms.end())
      throw RequestError(400, fmt::format("parameter 'forms': '{}' is named twice", name));
    forms.push_back(*s);
    if (comma == std::string_view::npos) return forms;
    rest = rest.substr(comma + 1);
  }
}

void write_models(JsonWriter& w) {
  w.key("models").begin_array();
  for (const std::string& name : model_registry().names()) {
    const ModelInfo* m = model_registry().find(name);
    if (!m) continue;
    w.begin_object().field("name", m->name).field("description", m->description);
    w.key("params").begin_array();
    for (const ModelParam& p : m->params) {
      w.begin_object().field("name", p.name).field("description", p.description);
      w.field("default", p.default_value).field("min", p.min).field("max", p.max);
      w.field("default_from", p.default_from).key("choices").begin_array();
      for (const std::string& c : p.choices) w.value(c);
      w.end_array().end_object();
    }
    w.end_array().end_object();
  }
  w.end_array();
}

void write_forms(JsonWriter& w) {
  w.key("forms").begin_array();
  for (const Space s : parameterizations()) {
    const auto coords = figure::iso_coordinates(s);
    w.begin_object().field("space", name_of(s)).field("summary", s.param().summary());
    w.field("azimuth_label", figure::relative_azimuth_label(s)).key("axes").begin_array();
    for (const auto& c : coords)
      w.begin_object()
          .field("label", c.label)
          .field("max", c.max)
          .field("angle", c.angle)
          .end_object();
    w.end_array().key("columns").begin_array();
    for (const auto c : column_names(Form{s, false})) w.value(c);
    w.end_array().key("iso_columns").begin_array();
    for (const auto c : column_names(Form{s, true})) w.value(c);
    w.end_array().key("units").begin_array();  // of the columns: "rad" or "" (a length)
    for (const Axis& a : s.param().axes(false)) w.value(a.unit());
    w.end_array().key("iso_units").begin_array();
    for (const Axis& a : s.param().axes(true)) w.value(a.unit());
    w.end_array().end_object();
  }
  w.end_array();
}

}  // namespace

Response info_response(const Catalog& catalog) {
  JsonWriter w;
  w.begin_object().key("specs").begin_array();
  for (const std::string& s : catalog.specs()) w.value(s);
  w.end_array();
  write_models(w);
  write_forms(w);
  w.key("embedded").begin_array();
  for (const std::string& name : embedded_material_names()) w.value(name);
  w.end_array();
  const Catalog::Listing files = catalog.list_files(1000);
  w.key("files").begin_array();
  for (const std::string& f : files.brdfs) w.value(f);
  w.end_array().key("environments").begin_array();
  for (const char* e : {"sky", "studio", "sunset"}) w.value(e);
  for (const std::string& f : files.environments) w.value("file:" + f);
  w.end_array().key("limits").begin_object();
  w.field("grid", kMaxGridSide).field("polar", kMaxPolarSamples);
  w.field("render", kMaxRenderSide).field("spp", kMaxRenderSpp);
  w.field("fit_samples", kMaxFitSamples).end_object();
  w.key("losses").begin_array();
  for (const fit::Loss l : fit::kLosses) w.value(fit::name_of(l));
  w.end_array().end_object();
  return json(w);
}

Response brdf_response(const Catalog& catalog, const Request& request) {
  const std::string& spec = required(request, "brdf");
  const BrdfPtr brdf = catalog.brdf(spec);
  JsonWriter w;
  w.begin_object().field("spec", spec).field("name", brdf->name());
  w.field("description", brdf->description()).field("isotropic", brdf->isotropic());
  w.field("reciprocal", brdf->reciprocal()).key("facts").begin_array();
  for (const Brdf::Fact& f : brdf->facts())
    w.begin_object().field("label", f.label).field("value", f.value).end_object();
  w.end_array().end_object();
  return json(w);
}

Response slices_response(const Catalog& catalog, const Request& request, int threads) {
  const std::vector<Space> forms = forms_param(request);
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
  if (specs.size() > kMaxBrdfsPerSlices)
    throw RequestError(413, fmt::format("at most {} brdf= per /api/slices request (got {})",
                                        kMaxBrdfsPerSlices, specs.size()));
  std::vector<BrdfPtr> brdfs;
  for (const std::string* s : specs) brdfs.push_back(catalog.brdf(*s));
  // One field per (BRDF, form), computed in parallel: a slider update is one request.
  std::vector<std::vector<float>> fields(brdfs.size() * forms.size());
  parallel_for(
      fields.size(), 1,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t k = begin; k < end; ++k)
          fields[k] = slice_field(*brdfs[k / forms.size()], forms[k % forms.size()], radians, n,
                                  threads, values, pose);
      },
      threads);
  Response res = floats(fields, n, n, channels_of(values));
  std::string names;
  for (const Space s : forms) {
    if (!names.empty()) names += ',';
    names += name_of(s);
  }
  res.headers.emplace_back("X-Halfback-Forms", names);
  res.headers.emplace_back("X-Halfback-Brdfs", std::to_string(brdfs.size()));
  return res;
}

Response hemisphere_response(const Catalog& catalog, const Request& request, int threads) {
  const std::string* colour = request.param("colour");
  Space space = Space::dirs;
  if (colour && *colour != "rho") space = space_param(request, "colour", true);
  const std::size_t n = whole(request, "n", 128, 2, kMaxGridSide);
  const Vec3<double> wo = outgoing(request);
  const RhoValues values = space == Space::dirs ? values_param(request) : RhoValues::rgb;
  BrdfPtr brdf;
  if (space == Space::dirs) brdf = catalog.brdf(required(request, "brdf"));
  return floats(hemisphere_field(brdf.get(), space, wo, n, threads, values), n, n,
                channels_of(values));
}

Response polar_response(const Catalog& catalog, const Request& request) {
  const std::size_t n = whole(request, "n", 181, 2, kMaxPolarSamples);
  const Vec3<double> wo = outgoing(request);
  const BrdfPtr brdf = catalog.brdf(required(request, "brdf"));
  const PolarCurves c = polar_curves(*brdf, wo, n);
  JsonWriter w;
  w.begin_object().key("angles_deg").begin_array();
  for (const double a : c.angles_deg) w.value(a);
  w.end_array();
  const auto curve = [&](std::string_view name, const std::vector<Rgb>& v) {
    w.key(name).begin_array();
    for (const Rgb& x : v) w.begin_array().value(x.r).value(x.g).value(x.b).end_array();
    w.end_array();
  };
  curve("in_plane", c.in_plane);
  curve("across", c.across);
  w.end_object();
  return json(w);
}

Response albedo_response(const Catalog& catalog, const Request& request, int threads) {
  const std::size_t angles = whole(request, "angles", 90, 2, kMaxAlbedoAngles);  // 0°, 1°, …, 89°
  const int n = int(whole(request, "n", 64, 1, kMaxAlbedoSamples));
  const BrdfPtr brdf = catalog.brdf(required(request, "brdf"));
  // θi from 0° to 89° (90° itself grazes: the cosine-weighted integral is 0 there for most BRDFs
  // and undefined for measured ones), each estimate the one `halfback info` prints (same seed).
  std::vector<double> theta(angles);
  std::vector<AlbedoEstimate> a(angles);
  for (std::size_t k = 0; k < angles; ++k) theta[k] = 89.0 * double(k) / double(angles - 1);
  parallel_for(
      angles, 1,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t k = begin; k < end; ++k) {
          const double t = theta[k] * kDegree;
          a[k] = directional_albedo(*brdf, {std::sin(t), 0, std::cos(t)}, n);
        }
      },
      threads);
  JsonWriter w;
  w.begin_object().field("brdf", brdf->name()).field("samples", n * n);
  w.key("theta_deg").begin_array();
  for (const double t : theta) w.value(t);
  w.end_array();
  const auto rgbs = [&](std::string_view name, auto member) {
    w.key(name).begin_array();
    for (const AlbedoEstimate& e : a) {
      const Rgb& x = e.*member;
      w.begin_array().value(x.r).value(x.g).value(x.b).end_array();
    }
    w.end_array();
  };
  rgbs("albedo", &AlbedoEstimate::mean);
  rgbs("standard_error", &AlbedoEstimate::standard_error);
  w.key("measured").begin_array();
  for (const AlbedoEstimate& e : a) w.value(e.measured);
  w.end_array().end_object();
  return json(w);
}

namespace {

// The pair a /api/point request names: wi and wo, or form (+ iso) and coords.
bool point_pair(const Request& request, DirPair<double>& pair) {
  if (request.param("wi") || request.param("wo")) {
    pair = {direction_param(request, "wi"), direction_param(request, "wo")};
    const PairStatus status = accept_pair(pair);
    if (status == PairStatus::not_finite || status == PairStatus::wi_not_unit ||
        status == PairStatus::wo_not_unit)
      throw RequestError(400, std::string(describe(status)));
    return true;
  }
  const Space space = space_param(request, "form", false);
  const std::string* iso_text = request.param("iso");
  const bool iso = iso_text && *iso_text == "1";
  const Form from{space, iso};
  const std::vector<double> q =
      number_list(required(request, "coords"), "parameter 'coords'", dimension(from));
  double d[6];
  const bool ok = convert_one<double>(from, Form{Space::dirs, false}, q, d);
  pair = {{d[0], d[1], d[2]}, {d[3], d[4], d[5]}};
  return ok;
}

void write_coordinates(JsonWriter& w, const DirPair<double>& pair, bool valid) {
  const double d[6] = {pair.wi.x, pair.wi.y, pair.wi.z, pair.wo.x, pair.wo.y, pair.wo.z};
  w.key("forms").begin_array();
  for (const Space s : parameterizations()) {
    w.begin_object().field("space", name_of(s));
    for (const bool iso : {false, true}) {
      const Form to{s, iso};
      double q[4] = {NAN, NAN, NAN, NAN}, jacobian = NAN;
      if (valid)
        convert_one<double>(Form{Space::dirs, false}, to, d, {q, dimension(to)}, &jacobian);
      w.key(iso ? "iso" : "coords").begin_array();
      for (std::size_t k = 0; k < dimension(to); ++k) w.value(q[k]);
      w.end_array().field(iso ? "iso_jacobian" : "jacobian", jacobian);
    }
    w.end_object();
  }
  w.end_array();
}

}  // namespace

Response point_response(const Catalog& catalog, const Request& request) {
  std::vector<BrdfPtr> brdfs;
  const std::vector<const std::string*> specs = all_params(request, "brdf");
  if (specs.size() > kMaxBrdfsPerRequest)
    throw RequestError(413, fmt::format("at most {} brdf= per request", kMaxBrdfsPerRequest));
  for (const std::string* s : specs) brdfs.push_back(catalog.brdf(*s));
  DirPair<double> pair{};
  const bool valid = point_pair(request, pair);
  JsonWriter w;
  w.begin_object().field("valid", valid);
  w.key("wi").begin_array().value(pair.wi.x).value(pair.wi.y).value(pair.wi.z).end_array();
  w.key("wo").begin_array().value(pair.wo.x).value(pair.wo.y).value(pair.wo.z).end_array();
  write_coordinates(w, pair, valid);
  w.key("rho").begin_array();
  for (std::size_t b = 0; b < brdfs.size(); ++b) {
    Rgb rho{NAN, NAN, NAN};
    if (valid) brdfs[b]->eval_batch({&pair, 1}, {&rho, 1});  // as `halfback eval` does
    w.begin_object().field("brdf", *specs[b]).key("rgb").begin_array();
    w.value(rho.r).value(rho.g).value(rho.b).end_array().end_object();
  }
  w.end_array().end_object();
  return json(w);
}

Response render_response(const Catalog& catalog, const Request& request, int threads) {
  render::RenderSettings s;
  s.width = s.height = int(whole(request, "size", 128, 8, std::size_t(kMaxRenderSide)));
  s.spp = int(whole(request, "spp", 4, 1, std::size_t(kMaxRenderSpp)));
  s.seed = whole(request, "pass", 0, 0, 1u << 20) + 1;  // each pass an independent estimate
  s.threads = threads;
  const std::string* env_spec = request.param("env");
  const auto env = catalog.environment(env_spec ? std::string_view(*env_spec) : "sky");
  const BrdfPtr brdf = catalog.sampled_brdf(required(request, "brdf"));
  const render::RenderResult result = render::render_sampled(*brdf, *env, s);
  Response res = floats(result.image.rgb, std::size_t(s.width), std::size_t(s.height), 3);
  res.headers.emplace_back("X-Halfback-Spp", std::to_string(result.spp));
  return res;
}

// The sphere under a distant light from (theta_l, phi_l) in camera space (degrees; θ = 0: from
// the camera, φ = 0: from the right), evaluated at k × k positions per pixel (no noise).
Response point_light_response(const Catalog& catalog, const Request& request, int threads) {
  render::RenderSettings s;
  s.width = s.height = int(whole(request, "size", 128, 8, std::size_t(kMaxRenderSide)));
  s.spp = int(whole(request, "spp", 4, 1, std::size_t(kMaxRenderSpp)));
  s.threads = threads;
  const double theta = number(request, "theta_l", 0, 0, 90) * kDegree;
  const double phi = number(request, "phi_l", 0, -360, 360) * kDegree;
  const Vec3<double> light{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                           std::cos(theta)};
  const BrdfPtr brdf = catalog.brdf(required(request, "brdf"));
  const render::RenderResult result = render::render_point_light(*brdf, light, s);
  Response res = floats(result.image.rgb, std::size_t(s.width), std::size_t(s.height), 3);
  res.headers.emplace_back("X-Halfback-Spp", std::to_string(result.spp));
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
                      std::atomic<int>& running) {
  const std::string& spec = required(request, "brdf");
  const std::string& model = required(request, "model");
  if (model.size() > kMaxSpecBytes)
    throw RequestError(413, fmt::format("model longer than {} bytes", kMaxSpecBytes));
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
  (void)fit::parse_model(model);  // a bad model is a 400 before the BRDF is loaded
  const BrdfPtr target = catalog.brdf(spec);
  const FitSlot slot(running);
  fit::FitResult result;
  try {
    result = fit::fit(*target, model, options);
  } catch (const fit::FitDataError& e) {
    throw RequestError(422,
                       fmt::format("'{}' cannot be fitted: {}", spec.substr(0, 128), e.what()));
  }
  JsonWriter w;
  write_fit(w, result, spec, model);
  return json(w);
}

}  // namespace halfback::view
