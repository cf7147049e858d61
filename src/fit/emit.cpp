// Fitted models as Mitsuba 3 and pbrt-v4 materials (include/halfback/fit/emit.hpp). The
// conversions are derived in docs/fit.md, "Renderer-ready output (`--emit`)"; each renderer fact
// used here is cited there with the file of the renderer's source it comes from.
#include "halfback/fit/emit.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <stdexcept>
#include <vector>

#include "emit_detail.hpp"
#include "halfback/core/rgb.hpp"
#include "halfback/loader/load.hpp"
#include "halfback/util/text_encoding.hpp"

namespace halfback::fit {

std::string_view name_of(Renderer renderer) {
  switch (renderer) {
    case Renderer::mitsuba3:
      return "mitsuba3";
    case Renderer::pbrt_v4:
      return "pbrt-v4";
    case Renderer::blender:
      return "blender";
    case Renderer::materialx:
      return "materialx";
  }
  return "?";
}

std::string_view display_name(Renderer renderer) {
  switch (renderer) {
    case Renderer::mitsuba3:
      return "Mitsuba 3";
    case Renderer::pbrt_v4:
      return "pbrt-v4";
    case Renderer::blender:
      return "Blender (Cycles)";
    case Renderer::materialx:
      return "MaterialX";
  }
  return "?";
}

std::optional<Renderer> parse_renderer(std::string_view name) {
  for (Renderer r : kRenderers)
    if (name_of(r) == name) return r;
  return std::nullopt;
}

std::string renderer_names() {
  std::vector<std::string_view> names;
  for (Renderer r : kRenderers) names.push_back(name_of(r));
  return fmt::format("{}", fmt::join(names, ", "));
}

// ---- Schlick's f0 as a conductor --------------------------------------------------------------

namespace {

// Unpolarized Fresnel reflectance at cos θ = c of an interface to a medium of index n = η + i k
// (Snell's law with a complex cosine of refraction). c + n cos θt ≠ 0 unless n = 1 at c = 0,
// which conductor_for_schlick() never asks for.
double conductor_fresnel(double eta, double k, double c) {
  const std::complex<double> n(eta, k);
  const std::complex<double> ct = std::sqrt(1.0 - (1 - c * c) / (n * n));
  const std::complex<double> rs = (c - n * ct) / (c + n * ct);
  const std::complex<double> rp = (n * c - ct) / (n * c + ct);
  return 0.5 * (std::norm(rs) + std::norm(rp));
}

double schlick(double f0, double c) {
  const double m = 1 - c, m2 = m * m;
  return f0 + (1 - f0) * m2 * m2 * m;
}

// The k that puts the reflectance at normal incidence at f0 for a given η (0 < f0 < 1).
double k_for(double f0, double eta) {
  const double k2 = (f0 * (eta + 1) * (eta + 1) - (eta - 1) * (eta - 1)) / (1 - f0);
  return std::sqrt(std::max(0.0, k2));
}

// max |F_conductor − F_Schlick| over n evenly spaced cosines in [0, 1].
double largest_difference(double f0, double eta, int n) {
  const double k = k_for(f0, eta);
  double worst = 0;
  for (int i = 0; i < n; ++i) {
    const double c = double(i) / (n - 1);
    worst = std::max(worst, std::abs(conductor_fresnel(eta, k, c) - schlick(f0, c)));
  }
  return worst;
}

}  // namespace

// η ranges over [(1−√f0)/(1+√f0), (1+√f0)/(1−√f0)], where k² ≥ 0; the largest difference is
// scanned on a log grid of η, the bracket around the best point narrowed five times.
ConductorIor conductor_for_schlick(double f0) {
  if (!(f0 >= 0 && f0 <= 1))
    throw std::invalid_argument(fmt::format("f0 must be in [0, 1], got {}", f0));
  if (f0 == 1) return {0, 1, 0};  // |r_s| = |r_p| = 1 at every angle
  if (f0 == 0) return {1, 0, 1};  // no interface: F ≡ 0, Schlick's grazing 1 lost
  const double r = std::sqrt(f0);
  const double lo = std::log((1 - r) / (1 + r)), hi = std::log(std::min((1 + r) / (1 - r), 1e4));
  double a = lo, b = hi, best = 0.5 * (lo + hi), best_error = 2;
  constexpr int kSteps = 32;
  for (int round = 0; round < 5; ++round) {
    for (int i = 0; i <= kSteps; ++i) {
      const double x = a + (b - a) * i / kSteps;
      const double e = largest_difference(f0, std::exp(x), 257);
      if (e < best_error) best_error = e, best = x;
    }
    const double step = (b - a) / kSteps;
    a = std::max(lo, best - step);
    b = std::min(hi, best + step);
  }
  const double eta = std::exp(best);
  return {eta, k_for(f0, eta), largest_difference(f0, eta, 4097)};
}

// ---- The model's terms ----------------------------------------------------------------------

namespace detail {

// A parameter's value in the model: its own when the model holds it, else what the registry
// says a missing one takes (the parameter it defaults to, or its default).
double value_of(const Model& m, std::size_t term, std::string_view name) {
  for (const Param& p : m.params)
    if (p.term == term && p.name == name) return p.value;
  const ModelInfo* info = model_registry().find(m.terms[term]);
  if (info)
    for (const ModelParam& p : info->params)
      if (p.name == name)
        return p.default_from.empty() ? p.default_value : value_of(m, term, p.default_from);
  throw std::invalid_argument(fmt::format("{}: no parameter '{}'", m.terms[term], name));
}

bool holds(const Model& m, std::size_t term, std::string_view name) {
  return std::any_of(m.params.begin(), m.params.end(),
                     [&](const Param& p) { return p.term == term && p.name == name; });
}

Rgb colour_of(const Model& m, std::size_t term, const std::string& name) {
  return {value_of(m, term, name + "_r"), value_of(m, term, name + "_g"),
          value_of(m, term, name + "_b")};
}

std::string unsupported(const Model& m, Renderer r, const std::string& why) {
  return fmt::format(
      "--emit {}: '{}' has no {} material: {}. Write the BRDF as a table instead: `halfback "
      "export-rgl --brdf SPEC -o FILE.bsdf` (read by Mitsuba 3's and pbrt-v4's `measured`; "
      "docs/formats.md) or `halfback export-merl`",
      name_of(r), fmt::join(m.terms, "+"), display_name(r), why);
}

std::string num(double v) {
  return fmt::format("{}", v);  // the shortest decimal that reads back as the same double
}

std::string rgb_list(const Rgb& c, const char* sep) {
  return fmt::format("{}{}{}{}{}", num(c.r), sep, num(c.g), sep, num(c.b));
}

double isotropic_alpha(const Model& m, std::size_t t, Renderer r) {
  const bool given_x = holds(m, t, "alpha_x"), given_y = holds(m, t, "alpha_y");
  const double ax = value_of(m, t, "alpha_x"), ay = value_of(m, t, "alpha_y");
  if (given_x != given_y || ax != ay)
    throw std::invalid_argument(unsupported(
        m, r,
        "an anisotropic lobe (alpha_x, alpha_y) is not emitted (the renderers orient it by the "
        "mesh's texture coordinates)"));
  return ax;
}

}  // namespace detail

namespace {

using detail::colour_of;
using detail::holds;
using detail::num;
using detail::rgb_list;
using detail::unsupported;
using detail::value_of;

// A microfacet term (ggx or beckmann) at its values.
struct Lobe {
  bool ggx = true;
  double alpha = 0;
  bool exact_fresnel = false;  // eta > 0: Fresnel of the index eta + i k (k = 0: a dielectric)
  Rgb f0;                      // Schlick's, when !exact_fresnel
  double eta = 0, k = 0;
};

Lobe lobe_of(const Model& m, std::size_t t, Renderer r) {
  Lobe lobe;
  lobe.ggx = m.terms[t] == "ggx";
  lobe.alpha = detail::isotropic_alpha(m, t, r);
  lobe.eta = value_of(m, t, "eta");
  lobe.k = value_of(m, t, "k");
  if (lobe.eta == 0 && lobe.k > 0)
    throw std::invalid_argument(fmt::format("{}: k needs eta > 0", m.terms[t]));
  lobe.exact_fresnel = lobe.eta > 0;
  lobe.f0 = colour_of(m, t, "f0");
  return lobe;
}

// Where the terms are: a Lambert term and a microfacet lobe, either optional, not both absent.
struct Terms {
  std::optional<std::size_t> lambert, lobe;
};

Terms terms_of(const Model& m, Renderer r) {
  Terms t;
  for (std::size_t i = 0; i < m.terms.size(); ++i) {
    const std::string& name = m.terms[i];
    std::optional<std::size_t>& slot = name == "lambert" ? t.lambert : t.lobe;
    if (name != "lambert" && name != "ggx" && name != "beckmann")
      throw std::invalid_argument(
          unsupported(m, r, fmt::format("the renderer has no '{}' lobe", name)));
    if (slot)
      throw std::invalid_argument(unsupported(
          m, r, "only a single lobe, or Lambert plus one ggx or beckmann lobe, is emitted"));
    slot = i;
  }
  if (t.lobe && m.terms[*t.lobe] == "beckmann" && r == Renderer::pbrt_v4)
    throw std::invalid_argument(unsupported(
        m, r, "pbrt-v4's microfacet materials use the Trowbridge-Reitz (GGX) distribution only"));
  if (t.lobe && t.lambert && r == Renderer::pbrt_v4)
    throw std::invalid_argument(unsupported(
        m, r,
        "pbrt-v4 has no plain sum of a diffuse and a glossy lobe (coateddiffuse is a layered "
        "model, and mix chooses one material or the other with weights that add to 1, so it "
        "cannot scale the conductor up)"));
  return t;
}

// ---- Text -----------------------------------------------------------------------------------

// What one lobe's conversion loses, for the file's comment.
struct LobeText {
  Rgb eta, k;  // the conductor's index per channel
  std::vector<std::string> notes;
};

LobeText conductor_of(const Lobe& lobe) {
  LobeText out;
  if (lobe.exact_fresnel) {
    out.eta = {lobe.eta, lobe.eta, lobe.eta};
    out.k = {lobe.k, lobe.k, lobe.k};
    out.notes.push_back(fmt::format("Fresnel: the index eta = {}, k = {}, as halfback's",
                                    num(lobe.eta), num(lobe.k)));
    return out;
  }
  const ConductorIor r = conductor_for_schlick(lobe.f0.r), g = conductor_for_schlick(lobe.f0.g),
                     b = conductor_for_schlick(lobe.f0.b);
  out.eta = {r.eta, g.eta, b.eta};
  out.k = {r.k, g.k, b.k};
  out.notes.push_back(
      fmt::format("Fresnel: a conductor equal to Schlick's f0 at normal incidence; elsewhere "
                  "|F - F_Schlick| <= {:.3g}, {:.3g}, {:.3g} (r, g, b)",
                  r.max_error, g.max_error, b.max_error));
  return out;
}

// ---- Mitsuba 3 ------------------------------------------------------------------------------

constexpr const char* kMitsubaSeparable =
    "Smith G: Mitsuba's is separable, G1(wi) G1(wo); halfback's height-correlated, "
    "1 / (1 + L(wi) + L(wo)): Mitsuba's rho is lower by the fraction (1 - G1(wi)) (1 - G1(wo))";
constexpr const char* kMitsubaBeckmannG1 =
    "Mitsuba's Beckmann G1 is a rational approximation (< 0.35 % relative, its source says)";

std::string xml_diffuse(const Rgb& reflectance, const std::string& pad) {
  return fmt::format(
      "{0}<bsdf type=\"diffuse\">\n{0}    <rgb name=\"reflectance\" value=\"{1}\"/>\n"
      "{0}</bsdf>\n",
      pad, rgb_list(reflectance, ", "));
}

// roughconductor, its Fresnel as conductor_of(), scaled by `scale` (specular_reflectance).
std::string xml_roughconductor(const Lobe& lobe, const LobeText& c, double scale,
                               const std::string& pad) {
  std::string s = fmt::format("{}<bsdf type=\"roughconductor\">\n", pad);
  const std::string in = pad + "    ";
  s += fmt::format("{}<string name=\"distribution\" value=\"{}\"/>\n", in,
                   lobe.ggx ? "ggx" : "beckmann");
  s += fmt::format("{}<float name=\"alpha\" value=\"{}\"/>\n", in, num(lobe.alpha));
  s += fmt::format("{}<rgb name=\"eta\" value=\"{}\"/>\n", in, rgb_list(c.eta, ", "));
  s += fmt::format("{}<rgb name=\"k\" value=\"{}\"/>\n", in, rgb_list(c.k, ", "));
  if (scale != 1)
    s += fmt::format("{}<float name=\"specular_reflectance\" value=\"{}\"/>\n", in, num(scale));
  return s + pad + "</bsdf>\n";
}

// principled with metallic = 1: GGX with Schlick's Fresnel of f0 = base_color, α = roughness².
std::string xml_principled(const Lobe& lobe, const std::string& pad) {
  const std::string in = pad + "    ";
  return fmt::format(
      "{0}<bsdf type=\"principled\">\n{1}<rgb name=\"base_color\" value=\"{2}\"/>\n"
      "{1}<float name=\"metallic\" value=\"1\"/>\n{1}<float name=\"roughness\" value=\"{3}\"/>\n"
      "{0}</bsdf>\n",
      pad, in, rgb_list(lobe.f0, ", "), num(std::sqrt(lobe.alpha)));
}

// The weight of the lobe in a blendbsdf: (1 − w) diffuse(albedo / (1 − w)) + w lobe(× 1/w) is
// the sum when the diffuse reflectance stays ≤ 1 (Mitsuba refuses an RGB reflectance above 1).
double blend_weight(const Rgb& albedo) {
  const double top = std::max({albedo.r, albedo.g, albedo.b});
  if (top >= 1)
    throw std::invalid_argument(
        "--emit mitsuba3: an albedo of 1 leaves the glossy lobe no weight in a blendbsdf "
        "(Mitsuba's diffuse reflectance is at most 1); write the BRDF with `halfback export-rgl`");
  return std::min(0.5, 1 - top);
}

// An XML comment may not hold "--": a spec's text is written with its dashes spaced.
std::string xml_comment(const Model& m, const std::string& form,
                        const std::vector<std::string>& notes) {
  std::string s = fmt::format("halfback fit: {}\n     Mitsuba 3: {}\n", spec_of(m), form);
  for (const std::string& n : notes) s += fmt::format("     {}\n", n);
  for (std::size_t at; (at = s.find("--")) != std::string::npos;) s.replace(at, 2, "- -");
  return "<!-- " + s + "     docs/fit.md, \"Renderer-ready output\" -->\n";
}

// The name as an XML attribute value: & < > " ' as character references (util's escape_xml, and
// the apostrophe, which it leaves).
std::string xml_attribute(std::string_view name) {
  std::string out;
  for (const char c : escape_xml(name)) {
    if (c == '\'')
      out += "&apos;";
    else
      out += c;
  }
  return out;
}

std::string emit_mitsuba(const Model& m, const Terms& t, std::string_view name) {
  const std::string id = fmt::format("id=\"{}\"", xml_attribute(name));
  std::string body, form;
  std::vector<std::string> notes;
  const std::string pad = "        ";
  if (!t.lobe) {
    body = xml_diffuse(colour_of(m, *t.lambert, "albedo"), "    ");
    form = "diffuse, reflectance = albedo (exact)";
  } else {
    const Lobe lobe = lobe_of(m, *t.lobe, Renderer::mitsuba3);
    notes.push_back(kMitsubaSeparable);
    if (!lobe.ggx) notes.push_back(kMitsubaBeckmannG1);
    if (!t.lambert && lobe.ggx && !lobe.exact_fresnel) {
      body = xml_principled(lobe, "    ");
      form =
          "principled, metallic = 1, base_color = f0 (Schlick's Fresnel, exact), roughness = "
          "sqrt(alpha)";
    } else {
      const LobeText c = conductor_of(lobe);
      notes.insert(notes.end(), c.notes.begin(), c.notes.end());
      if (!t.lambert) {
        body = xml_roughconductor(lobe, c, 1, "    ");
        form = "roughconductor, alpha as halfback's";
      } else {
        const Rgb albedo = colour_of(m, *t.lambert, "albedo");
        const double w = blend_weight(albedo);
        body = fmt::format(
            "    <bsdf type=\"blendbsdf\">\n        <float name=\"weight\" "
            "value=\"{}\"/>\n{}{}    </bsdf>\n",
            num(w), xml_diffuse(albedo * (1 / (1 - w)), pad),
            xml_roughconductor(lobe, c, 1 / w, pad));
        form = fmt::format(
            "blendbsdf, weight w = {0}: (1 - w) diffuse(albedo / (1 - w)) + w "
            "roughconductor(specular_reflectance = 1 / w), the sum of the two terms",
            num(w));
      }
    }
  }
  body.replace(body.find("<bsdf ") + 5, 0, " " + id);  // the outer bsdf is the named one
  return "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n" + xml_comment(m, form, notes) +
         "<scene version=\"3.0.0\">\n" + body + "</scene>\n";
}

// ---- pbrt-v4 --------------------------------------------------------------------------------

std::string emit_pbrt(const Model& m, const Terms& t, std::string_view name) {
  std::string s = fmt::format("# halfback fit: {}\n", spec_of(m));
  if (!t.lobe) {
    s += "# pbrt-v4: diffuse, reflectance = albedo (exact)\n";
    s += "# docs/fit.md, \"Renderer-ready output\"\n";
    return s + fmt::format(
                   "MakeNamedMaterial \"{}\"\n    \"string type\" \"diffuse\"\n"
                   "    \"rgb reflectance\" [ {} ]\n",
                   name, rgb_list(colour_of(m, *t.lambert, "albedo"), " "));
  }
  const Lobe lobe = lobe_of(m, *t.lobe, Renderer::pbrt_v4);
  const LobeText c = conductor_of(lobe);
  s += "# pbrt-v4: conductor, Trowbridge-Reitz (GGX) with the height-correlated Smith G as "
       "halfback's; roughness = alpha with remaproughness false\n";
  for (const std::string& n : c.notes) s += "# " + n + "\n";
  s += "# docs/fit.md, \"Renderer-ready output\"\n";
  return s + fmt::format(
                 "MakeNamedMaterial \"{}\"\n    \"string type\" \"conductor\"\n"
                 "    \"float roughness\" [ {} ]\n    \"bool remaproughness\" false\n"
                 "    \"rgb eta\" [ {} ]\n    \"rgb k\" [ {} ]\n",
                 name, num(lobe.alpha), rgb_list(c.eta, " "), rgb_list(c.k, " "));
}

}  // namespace

void check_emittable(const Model& model, Renderer renderer) {
  if (model.terms.empty()) throw std::invalid_argument("--emit: the model has no terms");
  if (renderer == Renderer::blender || renderer == Renderer::materialx) {
    detail::check_node_emittable(model, renderer);
    return;
  }
  const Terms t = terms_of(model, renderer);
  if (t.lobe) (void)lobe_of(model, *t.lobe, renderer);
}

void check_material_name(std::string_view name, Renderer renderer) {
  if (name.empty()) throw std::invalid_argument("material name: empty");
  if (renderer == Renderer::materialx) {
    detail::check_materialx_name(name);
    return;
  }
  for (const char c : name) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f)
      throw std::invalid_argument(fmt::format(
          "material name '{}': a control character (byte {:#04x}; a line break would end the "
          "{} statement) is not allowed",
          name.substr(0, 64), u, renderer == Renderer::mitsuba3 ? "XML" : "pbrt-v4"));
    if (renderer == Renderer::pbrt_v4 && (c == '"' || c == '\\'))
      throw std::invalid_argument(fmt::format(
          "material name '{}': '{}' is not allowed in a pbrt-v4 string (it would end or escape "
          "the quoted name)",
          name.substr(0, 64), c));
  }
}

std::string emit_material(const Model& model, Renderer renderer, std::string_view name) {
  check_material_name(name, renderer);
  check_emittable(model, renderer);
  if (renderer == Renderer::blender) return detail::emit_blender(model, name);
  if (renderer == Renderer::materialx) return detail::emit_materialx(model, name);
  const Terms t = terms_of(model, renderer);
  return renderer == Renderer::mitsuba3 ? emit_mitsuba(model, t, name) : emit_pbrt(model, t, name);
}

}  // namespace halfback::fit
