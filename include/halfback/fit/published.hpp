// The published fits of Ngan et al. 2005 as BBM distributes them (../shared/data/fits/, format in
// ../shared/README.md): one material a line, "NAME = Aggregate(Lambertian(albedo = [r, g, b]),
// MODEL(key = value or [r, g, b], ...))", '#' comments. This reads the expressions; what each
// model's parameters mean is docs/fit.md's business (not evaluated yet).
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
  // Each value: one number, or several ("[r, g, b]").
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

}  // namespace halfback::fit
