// Fitted models as node graphs: a Blender (Cycles) script and a MaterialX document
// (include/halfback/fit/emit.hpp). Each renderer fact used here, with the source file it comes
// from, and the differences measured in Cycles renders: docs/fit.md, "Renderer-ready output".
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "emit_detail.hpp"

namespace halfback::fit::detail {

namespace {

constexpr double kPi = std::numbers::pi;

bool is_node_term(const std::string& name) {
  return name == "lambert" || name == "oren-nayar" || name == "ggx" || name == "disney";
}

void check_term(const Model& m, std::size_t t, Renderer r) {
  const std::string& name = m.terms[t];
  if (!is_node_term(name))
    throw std::invalid_argument(unsupported(
        m, r,
        name == "beckmann"
            ? "its microfacet nodes use the GGX distribution only"
            : fmt::format("the renderer has no '{}' lobe (it takes lambert, oren-nayar, ggx and "
                          "disney)",
                          name)));
  if (name == "ggx") {
    const double alpha = isotropic_alpha(m, t, r);
    const double eta = value_of(m, t, "eta"), k = value_of(m, t, "k");
    if (eta == 0 && k > 0) throw std::invalid_argument("ggx: k needs eta > 0");
    if (r == Renderer::blender && eta > 0)
      throw std::invalid_argument(unsupported(
          m, r,
          "a ggx lobe with the exact Fresnel of an index (eta, k) has no Cycles node (the "
          "Principled BSDF's Fresnel is Schlick-like; the Glossy BSDF has none)"));
    if (r == Renderer::blender && alpha > 1)
      throw std::invalid_argument(unsupported(
          m, r,
          fmt::format("alpha = {} > 1: the Principled BSDF's roughness (sqrt(alpha)) is at "
                      "most 1",
                      alpha)));
  }
  if (name == "disney" && value_of(m, t, "anisotropic") != 0)
    throw std::invalid_argument(unsupported(
        m, r,
        "an anisotropic lobe (disney's anisotropic > 0) is not emitted (the renderers orient it "
        "by the mesh's texture coordinates)"));
  if (name == "disney" && r == Renderer::materialx && m.terms.size() > 1)
    throw std::invalid_argument(unsupported(
        m, r,
        "disney_brdf_2012 is a surface shader, not a BSDF: it cannot be added to other terms"));
}

// Oren–Nayar's qualitative model as Cycles' Diffuse BSDF (Fujii's form, bsdf_oren_nayar.h):
// Cycles' ρ = colour (a + b t), a = 1 / (π + c r), b = r a, c = (3π − 4)/6, t the same
// geometric term as Oren–Nayar's where cos(φi − φo) ≥ 0. Equal to albedo/π (A + B t) there when
// r = B/A (≤ 0.9 for every σ) and colour = albedo (A + c B/π) (≤ 1).
struct CyclesDiffuse {
  Rgb colour;
  double roughness;
};
CyclesDiffuse cycles_oren_nayar(const Rgb& albedo, double sigma) {
  const double s2 = sigma * sigma;
  const double a = 1 - 0.5 * s2 / (s2 + 0.33), b = 0.45 * s2 / (s2 + 0.09);
  const double c = (3 * kPi - 4) / 6;
  return {albedo * (a + c * b / kPi), b / a};
}

std::string py_rgba(const Rgb& c) {
  return fmt::format("({}, {}, {}, 1.0)", num(c.r), num(c.g), num(c.b));
}

std::string comment_lines(const std::string& prefix, const std::vector<std::string>& lines) {
  std::string s;
  for (const std::string& l : lines) s += prefix + l + "\n";
  return s;
}

}  // namespace

void check_node_emittable(const Model& model, Renderer renderer) {
  for (std::size_t t = 0; t < model.terms.size(); ++t) check_term(model, t, renderer);
}

void check_materialx_name(std::string_view name) {
  const auto letter = [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
  };
  const auto digit = [](char c) { return c >= '0' && c <= '9'; };
  if (name.size() > 200)
    throw std::invalid_argument("material name: longer than 200 characters (MaterialX)");
  for (std::size_t i = 0; i < name.size(); ++i)
    if (!(letter(name[i]) || (i > 0 && digit(name[i])))) {
      // Up to the offending byte the name is ASCII: it is shown that far, the byte in hex.
      throw std::invalid_argument(fmt::format(
          "material name '{}…': a MaterialX element name is ASCII letters, digits and '_', not "
          "starting with a digit (byte {:#04x} at {})",
          name.substr(0, std::min<std::size_t>(i, 64)), static_cast<unsigned char>(name[i]), i));
    }
}

// ---- Blender ----------------------------------------------------------------------------------

namespace {

// The Python statements that make term t's node `n`, and what the conversion loses.
std::string blender_term(const Model& m, std::size_t t, std::vector<std::string>& notes) {
  const std::string& name = m.terms[t];
  std::string s = fmt::format("# term {}: {}\n", t + 1, name);
  if (name == "lambert") {
    s += "n = nodes.new('ShaderNodeBsdfDiffuse')\n";
    s += fmt::format("put(n, 'Color', {})\nput(n, 'Roughness', 0.0)\n",
                     py_rgba(colour_of(m, t, "albedo")));
    notes.push_back("lambert: Diffuse BSDF, roughness 0 (exact)");
  } else if (name == "oren-nayar") {
    const CyclesDiffuse d = cycles_oren_nayar(colour_of(m, t, "albedo"), value_of(m, t, "sigma"));
    s += "n = nodes.new('ShaderNodeBsdfDiffuse')\n";
    s += fmt::format("put(n, 'Color', {})\nput(n, 'Roughness', {})\n", py_rgba(d.colour),
                     num(d.roughness));
    notes.push_back(
        "oren-nayar: Diffuse BSDF (Fujii's form) with roughness B/A and colour albedo (A + "
        "c B/pi), c = (3 pi - 4)/6: equal where cos(phi_i - phi_o) >= 0; behind, Cycles "
        "subtracts b |t| where Oren-Nayar adds 0");
  } else if (name == "ggx") {
    s += "n = principled()\n";
    s += fmt::format("put(n, 'Base Color', {})\nput(n, 'Metallic', 1.0)\nput(n, 'Roughness', {})\n",
                     py_rgba(colour_of(m, t, "f0")), num(std::sqrt(value_of(m, t, "alpha_x"))));
    notes.push_back(
        "ggx: Principled BSDF, metallic 1, base colour f0, roughness sqrt(alpha), GGX; Cycles' "
        "Fresnel rises from f0 to 1 as a dielectric's of index 1.5 does (not Schlick's "
        "(1 - cos)^5), and its Smith G is separable (halfback's height-correlated)");
  } else {  // disney
    s += "n = principled()\n";
    s += fmt::format("put(n, 'Base Color', {})\n",
                     py_rgba({value_of(m, t, "base_color_red"), value_of(m, t, "base_color_green"),
                              value_of(m, t, "base_color_blue")}));
    for (const auto& [input, param] :
         std::vector<std::pair<const char*, const char*>>{{"Subsurface", "subsurface"},
                                                          {"Metallic", "metallic"},
                                                          {"Specular", "specular"},
                                                          {"Specular Tint", "specular_tint"},
                                                          {"Roughness", "roughness"},
                                                          {"Sheen", "sheen"},
                                                          {"Sheen Tint", "sheen_tint"},
                                                          {"Clearcoat", "clearcoat"}})
      s += fmt::format("put(n, '{}', {})\n", input, num(value_of(m, t, param)));
    // Cycles squares the clearcoat roughness into GTR1's alpha (svm_closure.h).
    const double gloss = value_of(m, t, "clearcoat_gloss");
    s += fmt::format("put(n, 'Clearcoat Roughness', {})\n",
                     num(std::sqrt(0.1 + (0.001 - 0.1) * gloss)));
    notes.push_back(
        "disney: Principled BSDF (Blender 3's, Burley's parameters), clearcoat roughness "
        "sqrt(0.1 - 0.099 gloss); Cycles' specular Fresnel is a dielectric's rescaled between "
        "Cspec0 and 1 (not Schlick's), its clearcoat Fresnel a dielectric's of index 1.5");
    if (value_of(m, t, "subsurface") > 0)
      notes.push_back(
          "disney: subsurface > 0 is true subsurface scattering in Cycles (random walk), not "
          "Burley's BRDF lobe: expect a softer, brighter diffuse");
  }
  return s + "terms.append(n)\n";
}

}  // namespace

std::string emit_blender(const Model& model, std::string_view name) {
  std::vector<std::string> notes;
  std::string body;
  for (std::size_t t = 0; t < model.terms.size(); ++t) body += blender_term(model, t, notes);
  const bool disney =
      std::find(model.terms.begin(), model.terms.end(), "disney") != model.terms.end();
  std::string s = fmt::format("# halfback fit: {}\n", spec_of(model));
  s += "# Blender (Cycles) nodes, the terms added by Add Shader nodes:\n";
  s += comment_lines("#   ", notes);
  s += "# Run: blender -b SCENE.blend --python THIS.py (or in Blender's text editor); it creates\n"
       "# or replaces the material named below. docs/fit.md, \"Renderer-ready output\".\n";
  s += "import bpy\n\n";
  // A JSON string is a Python string literal (its escapes are Python's).
  s += fmt::format("NAME = {}\n\n", nlohmann::json(std::string(name)).dump());
  if (disney)
    s += "if bpy.app.version >= (4, 0, 0):\n"
         "    raise RuntimeError('this material uses Blender 3\\'s Principled BSDF (Burley 2012); "
         "Blender 4\\'s is another model')\n\n";
  s += "\ndef put(node, name, value):\n"
       "    if name not in node.inputs:\n"
       "        raise KeyError(f'{node.bl_idname} has no input {name!r}')\n"
       "    node.inputs[name].default_value = value\n\n\n"
       "def principled():\n"
       "    n = nodes.new('ShaderNodeBsdfPrincipled')\n"
       "    n.distribution = 'GGX'\n"
       "    for name in ('Sheen', 'Clearcoat', 'Subsurface', 'Specular Tint', 'Anisotropic'):\n"
       "        if name in n.inputs and n.inputs[name].type == 'VALUE':\n"
       "            n.inputs[name].default_value = 0.0\n"
       "    return n\n\n\n";
  s += "material = bpy.data.materials.get(NAME) or bpy.data.materials.new(NAME)\n"
       "material.use_nodes = True\n"
       "nodes, links = material.node_tree.nodes, material.node_tree.links\n"
       "nodes.clear()\n"
       "terms = []\n";
  s += body;
  s += "shader = terms[0].outputs[0]\n"
       "for n in terms[1:]:\n"
       "    add = nodes.new('ShaderNodeAddShader')\n"
       "    links.new(shader, add.inputs[0])\n"
       "    links.new(n.outputs[0], add.inputs[1])\n"
       "    shader = add.outputs[0]\n"
       "output = nodes.new('ShaderNodeOutputMaterial')\n"
       "links.new(shader, output.inputs['Surface'])\n";
  return s;
}

// ---- MaterialX --------------------------------------------------------------------------------

namespace {

std::string mx_input(const std::string& name, const std::string& type, const std::string& value) {
  return fmt::format("    <input name=\"{}\" type=\"{}\" value=\"{}\" />\n", name, type, value);
}

std::string mx_link(const std::string& name, const std::string& type, const std::string& node) {
  return fmt::format("    <input name=\"{}\" type=\"{}\" nodename=\"{}\" />\n", name, type, node);
}

std::string mx_node(const std::string& category, const std::string& name, const std::string& type,
                    const std::string& inputs) {
  return fmt::format("  <{0} name=\"{1}\" type=\"{2}\">\n{3}  </{0}>\n", category, name, type,
                     inputs);
}

// Term t as a pbrlib BSDF node named `node`.
std::string mx_term(const Model& m, std::size_t t, const std::string& node,
                    std::vector<std::string>& notes) {
  const std::string& name = m.terms[t];
  if (name == "lambert" || name == "oren-nayar") {
    const double sigma = name == "lambert" ? 0.0 : value_of(m, t, "sigma");
    notes.push_back(name + ": oren_nayar_diffuse_bsdf, roughness = sigma in radians (exact)");
    return mx_node("oren_nayar_diffuse_bsdf", node, "BSDF",
                   mx_input("color", "color3", rgb_list(colour_of(m, t, "albedo"), ", ")) +
                       mx_input("roughness", "float", num(sigma)));
  }
  // ggx
  const double alpha = value_of(m, t, "alpha_x"), eta = value_of(m, t, "eta");
  const double k = value_of(m, t, "k");
  const std::string roughness = mx_input("roughness", "vector2", num(alpha) + ", " + num(alpha));
  if (eta > 0 && k > 0) {
    notes.push_back("ggx: conductor_bsdf with ior = eta, extinction = k (exact)");
    return mx_node("conductor_bsdf", node, "BSDF",
                   mx_input("ior", "color3", rgb_list({eta, eta, eta}, ", ")) +
                       mx_input("extinction", "color3", rgb_list({k, k, k}, ", ")) + roughness);
  }
  if (eta > 0) {
    notes.push_back("ggx: dielectric_bsdf, reflection only, ior = eta (exact)");
    return mx_node(
        "dielectric_bsdf", node, "BSDF",
        mx_input("ior", "float", num(eta)) + roughness + mx_input("scatter_mode", "string", "R"));
  }
  notes.push_back(
      "ggx: generalized_schlick_bsdf, color0 = f0, color90 = 1, exponent 5, roughness = "
      "(alpha, alpha) (exact: GGX, height-correlated Smith G, Schlick's Fresnel; MaterialX's "
      "GLSL adds its own multiple-scattering compensation)");
  return mx_node("generalized_schlick_bsdf", node, "BSDF",
                 mx_input("color0", "color3", rgb_list(colour_of(m, t, "f0"), ", ")) +
                     mx_input("color90", "color3", "1, 1, 1") + mx_input("exponent", "float", "5") +
                     roughness);
}

std::string mx_disney(const Model& m, const std::string& node) {
  std::string inputs =
      mx_input("baseColor", "color3",
               rgb_list({value_of(m, 0, "base_color_red"), value_of(m, 0, "base_color_green"),
                         value_of(m, 0, "base_color_blue")},
                        ", "));
  for (const auto& [input, param] :
       std::vector<std::pair<const char*, const char*>>{{"metallic", "metallic"},
                                                        {"subsurface", "subsurface"},
                                                        {"specular", "specular"},
                                                        {"roughness", "roughness"},
                                                        {"specularTint", "specular_tint"},
                                                        {"anisotropic", "anisotropic"},
                                                        {"sheen", "sheen"},
                                                        {"sheenTint", "sheen_tint"},
                                                        {"clearcoat", "clearcoat"},
                                                        {"clearcoatGloss", "clearcoat_gloss"}})
    inputs += mx_input(input, "float", num(value_of(m, 0, param)));
  return mx_node("disney_brdf_2012", node, "surfaceshader", inputs);
}

std::string mx_comment(const Model& m, const std::vector<std::string>& notes) {
  std::string s = fmt::format("halfback fit: {}\n", spec_of(m));
  for (const std::string& n : notes) s += "     " + n + "\n";
  for (std::size_t at; (at = s.find("--")) != std::string::npos;) s.replace(at, 2, "- -");
  return "<!-- " + s + "     docs/fit.md, \"Renderer-ready output\" -->\n";
}

}  // namespace

std::string emit_materialx(const Model& model, std::string_view name_view) {
  const std::string name(name_view), shader = name + "_shader";
  std::vector<std::string> notes;
  std::string nodes;
  if (model.terms.front() == "disney") {
    notes.push_back(
        "disney: disney_brdf_2012 (Burley's parameters; the node has no graph in MaterialX's "
        "libraries: renderers implement it natively)");
    nodes = mx_disney(model, shader);
  } else {
    std::string last;
    for (std::size_t t = 0; t < model.terms.size(); ++t) {
      const std::string node = fmt::format("{}_term{}", name, t + 1);
      nodes += mx_term(model, t, node, notes);
      if (t == 0) {
        last = node;
        continue;
      }
      const std::string sum = fmt::format("{}_sum{}", name, t + 1);
      nodes +=
          mx_node("add", sum, "BSDF", mx_link("in1", "BSDF", last) + mx_link("in2", "BSDF", node));
      last = sum;
    }
    nodes += mx_node("surface", shader, "surfaceshader", mx_link("bsdf", "BSDF", last));
  }
  nodes += mx_node("surfacematerial", name, "material",
                   mx_link("surfaceshader", "surfaceshader", shader));
  return "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n" + mx_comment(model, notes) +
         "<materialx version=\"1.38\" colorspace=\"lin_rec709\">\n" + nodes + "</materialx>\n";
}

}  // namespace halfback::fit::detail
