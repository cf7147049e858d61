// The published fits of Ngan et al. 2005 as BBM distributes them (../shared/data/fits/, format in
// ../shared/README.md): one material a line, "NAME = Aggregate(Lambertian(albedo = [r, g, b]),
// MODEL(key = value or [r, g, b], ...))", '#' comments. This reads the expressions and turns them
// into halfback specs of the registry's models that restate BBM's (docs/models.md, docs/fit.md).
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace halfback::fit {

struct PublishedLobe {
  std::string model;  // "Lambertian", "NganCookTorrance", ...
  // Each value: one number, or several ("[r, g, b]"; a list of lists, "[[r, g, b], [r, g, b]]",
  // row by row).
  std::vector<std::pair<std::string, std::vector<double>>> params;
};

struct PublishedFit {
  std::string material;
  std::vector<PublishedLobe> lobes;  // the terms of Aggregate(...), or the one model
  std::size_t line = 0;              // 1-based
};

// Throws FormatError ("SOURCE: line N, column C: PROBLEM") on the first malformed line, a
// number that is not finite, a repeated material or parameter.
std::vector<PublishedFit> parse_published_fits(std::string_view text, const std::string& source);
// The file's content through parse_published_fits; FormatError when it cannot be read.
std::vector<PublishedFit> read_published_fits(const std::filesystem::path& path);

// The registry's name of a BBM model ("NganWard" -> "ward", "Lambertian" -> "lambert"), or ""
// when halfback has no model of that name.
std::string_view registry_name_of(std::string_view bbm_model);

// The fit as a spec every command reads: its lobes summed, each model by registry_name_of, each
// parameter by its name in lower case ("fresnelReflectance" -> "f0"), an [r, g, b] value as
// NAME_r, NAME_g, NAME_b ("lambert:albedo_r=0.0143,...+ward:albedo_r=...,roughness=0.0162").
// Throws std::invalid_argument naming a model halfback does not have, or a value that is neither
// one number nor three.
std::string spec_of(const PublishedFit& fit);
// Its terms' models as fit() takes them: "lambert+ward".
std::string model_of(const PublishedFit& fit);

}  // namespace halfback::fit
