// A fitted model written as a renderer's own material (`halfback fit --emit`): Mitsuba 3 XML or
// pbrt-v4 scene text, for the models those renderers have (Lambert; GGX and Beckmann with
// Schlick or exact Fresnel; Lambert plus one of them); a Blender script or a MaterialX document
// for sums of lambert, oren-nayar and ggx terms, and for disney (Burley's principled BRDF). The
// conversions, and what each one loses, are derived in docs/fit.md, "Renderer-ready output
// (`--emit`)".
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "halfback/fit/fit.hpp"

namespace halfback::fit {

// blender: a Python script that builds the material in Blender (Cycles' nodes); materialx: a
// MaterialX document (pbrlib's BSDF nodes, or disney_brdf_2012).
enum class Renderer { mitsuba3, pbrt_v4, blender, materialx };
inline constexpr Renderer kRenderers[] = {Renderer::mitsuba3, Renderer::pbrt_v4, Renderer::blender,
                                          Renderer::materialx};
std::string_view name_of(Renderer renderer);       // "mitsuba3", "pbrt-v4", "blender", "materialx"
std::string_view display_name(Renderer renderer);  // "Mitsuba 3", ..., "Blender (Cycles)"
std::optional<Renderer> parse_renderer(std::string_view name);  // nullopt when unknown
std::string renderer_names();  // "mitsuba3, pbrt-v4, blender, materialx"

// The conductor (complex index η + i k) whose Fresnel reflectance equals Schlick's f0 at normal
// incidence and is closest to Schlick's F(cos θ) = f0 + (1 − f0)(1 − cos θ)⁵ elsewhere: among the
// indices with ((η−1)² + k²) / ((η+1)² + k²) = f0, the η minimising the largest difference over
// cos θ ∈ [0, 1]. max_error is that largest difference |F_conductor − F_Schlick|, measured on 4097
// evenly spaced cosines. f0 = 1 gives η = 0, k = 1 (F ≡ 1, exact); f0 = 0 gives η = 1, k = 0
// (F ≡ 0: Schlick's rise to 1 at grazing is lost, max_error = 1). Throws std::invalid_argument
// for f0 outside [0, 1].
struct ConductorIor {
  double eta = 1, k = 0;
  double max_error = 0;
};
ConductorIor conductor_for_schlick(double f0);

// Throws std::invalid_argument, with a message for users, unless `renderer` has a material for
// the model's terms at the values the model holds (before a fit: the terms, and the parameters
// given in the model spec): Mitsuba 3 has lambert, ggx, beckmann and lambert + one of them;
// pbrt-v4 has lambert and ggx (no Beckmann distribution, no plain sum of a diffuse and a glossy
// lobe); Blender and MaterialX have any sum of lambert, oren-nayar and ggx terms (Blender: ggx
// with Schlick's f0 only; MaterialX: Schlick's f0 or the exact Fresnel), and disney alone (in
// Blender also in a sum). Anisotropic lobes (alpha_x ≠ alpha_y, disney's anisotropic > 0) are
// refused: the renderers' tangent frames follow
// the mesh's texture coordinates, which halfback does not know. The message names the model and
// the renderer and points to `halfback export-rgl`.
void check_emittable(const Model& model, Renderer renderer);

// The rule for a material's name (emit_material's `name`): not empty, no control character (a
// line break would start a statement of the renderer's own in the file); for pbrt-v4 no '"' or
// '\\' either (they would end or escape the quoted name). Mitsuba 3's id is written with the
// XML attribute escapes (&amp; &lt; &gt; &quot; &apos;), so any other text is the id as given;
// Blender's is a Python string literal with its escapes. A MaterialX name is an element name:
// [A-Za-z_][A-Za-z0-9_]*, at most 200 characters.
// Throws std::invalid_argument naming the character.
void check_material_name(std::string_view name, Renderer renderer);

// The model at its parameters' values (e.g. FitResult::model, or parse_model(spec)) as the
// renderer's material, named `name`: a whole Mitsuba 3 scene file (`<scene>` holding one `<bsdf
// id="NAME">`, for `<include>` and `<ref id>`) or pbrt-v4 text (`MakeNamedMaterial "NAME"`, for
// `Include` in the world block and `NamedMaterial`), a Python script for Blender (`blender -b
// FILE.blend --python SCRIPT`: it creates or replaces the material NAME) or a MaterialX 1.38
// document (a `surfacematerial` NAME). A comment at the top gives the spec, the
// renderer's form and what the conversion loses. Throws std::invalid_argument as
// check_emittable(), and for a Lambert + lobe sum in Mitsuba 3 whose albedo is 1 in some channel
// (a blendbsdf leaves the lobe no weight then; docs/fit.md), and as check_material_name().
std::string emit_material(const Model& model, Renderer renderer,
                          std::string_view name = "halfback_fit");

}  // namespace halfback::fit
