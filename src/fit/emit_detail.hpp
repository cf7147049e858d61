// What emit.cpp and emit_nodes.cpp share (private to the fit layer): a term's parameter values,
// the message for a model a renderer cannot take, numbers as text, and the node-graph targets.
#pragma once

#include <string>
#include <string_view>

#include "halfback/core/rgb.hpp"
#include "halfback/fit/emit.hpp"

namespace halfback::fit::detail {

// A parameter's value in term `term`: its own when the model holds it, else what the registry
// says a missing one takes. Throws std::invalid_argument for an undeclared name.
double value_of(const Model& m, std::size_t term, std::string_view name);
bool holds(const Model& m, std::size_t term, std::string_view name);
Rgb colour_of(const Model& m, std::size_t term, const std::string& name);  // NAME_r, _g, _b
std::string unsupported(const Model& m, Renderer r, const std::string& why);
// A microfacet term's α, refused (std::invalid_argument, unsupported()) when anisotropic: the
// renderers orient an anisotropic lobe by the mesh's texture coordinates.
double isotropic_alpha(const Model& m, std::size_t term, Renderer r);
std::string num(double v);  // the shortest decimal that reads back as the same double
std::string rgb_list(const Rgb& c, const char* sep);

// Blender and MaterialX (emit_nodes.cpp): check_emittable() and emit_material() for them.
void check_node_emittable(const Model& model, Renderer renderer);
void check_materialx_name(std::string_view name);
std::string emit_blender(const Model& model, std::string_view name);
std::string emit_materialx(const Model& model, std::string_view name);

}  // namespace halfback::fit::detail
