// A recursive-descent reader of BBM's fit lines (include/halfback/fit/published.hpp).
#include "halfback/fit/published.hpp"

#include <fmt/format.h>

#include <cctype>
#include <charconv>
#include <cmath>
#include <set>
#include <stdexcept>

#include "halfback/util/bounded_read.hpp"
#include "halfback/util/format_error.hpp"
#include "halfback/util/text_encoding.hpp"

namespace halfback::fit {

namespace {

// One line's cursor; every error names the source, the line and the column.
class LineReader {
 public:
  LineReader(std::string_view text, const std::string& source, std::size_t line)
      : text_(text), source_(source), line_(line) {}

  [[noreturn]] void fail(const std::string& problem) const {
    throw FormatError(source_, fmt::format("line {}, column {}", line_, pos_ + 1), problem);
  }
  void skip_space() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  }
  bool at_end() {
    skip_space();
    return pos_ == text_.size();
  }
  bool accept(char c) {
    skip_space();
    if (pos_ < text_.size() && text_[pos_] == c) return ++pos_, true;
    return false;
  }
  void expect(char c) {
    if (!accept(c))
      fail(pos_ < text_.size() ? fmt::format("expected '{}', found {}", c, found())
                               : fmt::format("expected '{}' at the end of the line", c));
  }
  // The character at the cursor, quoted and whole (all the bytes of a UTF-8 sequence, not its
  // first: a message must be UTF-8, or Python shows the exception without its text; invalid
  // bytes as U+FFFD).
  std::string found() const {
    std::size_t end = pos_ + 1;
    while (end < text_.size() && (static_cast<unsigned char>(text_[end]) & 0xC0) == 0x80) ++end;
    const std::string c = "'" + valid_utf8(text_.substr(pos_, end - pos_)) + "'";
    if (static_cast<unsigned char>(text_[pos_]) < 0x80) return c;
    return c + " (names are of ASCII letters, digits, '_' and '-')";
  }
  // A name: letters, digits, '_', '-' (material names such as "blue-acrylic").
  std::string name(const char* what) {
    skip_space();
    const std::size_t start = pos_;
    while (pos_ < text_.size() && (std::isalnum(static_cast<unsigned char>(text_[pos_])) ||
                                   text_[pos_] == '_' || text_[pos_] == '-'))
      ++pos_;
    if (pos_ == start) fail(fmt::format("expected {}", what));
    return std::string(text_.substr(start, pos_ - start));
  }
  double number() {
    skip_space();
    double v = 0;
    const char* first = text_.data() + pos_;
    const auto [end, ec] = std::from_chars(first, text_.data() + text_.size(), v);
    if (ec != std::errc() || !std::isfinite(v)) fail("expected a finite number");
    pos_ += std::size_t(end - first);
    return v;
  }
  // A number, a list [a, b, ...], or a list of lists of one length ([[a, b], [c, d]]: Bagher et
  // al.'s complex indices), read row by row into one list.
  std::vector<double> value() {
    if (!accept('[')) return {number()};
    skip_space();
    if (pos_ < text_.size() && text_[pos_] == '[') {
      std::vector<double> v = row();
      const std::size_t width = v.size();
      while (accept(',')) {
        const std::vector<double> r = row();
        if (r.size() != width)
          fail(fmt::format("a row of {} numbers where the first had {}", r.size(), width));
        v.insert(v.end(), r.begin(), r.end());
      }
      expect(']');
      return v;
    }
    std::vector<double> v{number()};
    while (accept(',')) v.push_back(number());
    expect(']');
    return v;
  }
  std::vector<double> row() {
    expect('[');
    std::vector<double> v{number()};
    while (accept(',')) v.push_back(number());
    expect(']');
    return v;
  }
  // MODEL(key = value, ...) after its name.
  PublishedLobe lobe(std::string model) {
    PublishedLobe l{std::move(model), {}};
    expect('(');
    std::set<std::string> seen;
    if (!accept(')')) {
      do {
        std::string key = name("a parameter name");
        if (!seen.insert(key).second) fail(fmt::format("parameter '{}' repeated", key));
        expect('=');
        l.params.emplace_back(std::move(key), value());
      } while (accept(','));
      expect(')');
    }
    return l;
  }

  PublishedFit fit() {
    PublishedFit f;
    f.line = line_;
    f.material = name("a material name");
    expect('=');
    std::string model = name("a model name");
    if (model == "Aggregate") {
      expect('(');
      do f.lobes.push_back(lobe(name("a model name")));
      while (accept(','));
      expect(')');
    } else {
      f.lobes.push_back(lobe(std::move(model)));
    }
    if (!at_end()) fail("unexpected text after the expression");
    return f;
  }

 private:
  std::string_view text_;
  const std::string& source_;
  std::size_t line_;
  std::size_t pos_ = 0;
};

}  // namespace

std::vector<PublishedFit> parse_published_fits(std::string_view text, const std::string& source) {
  std::vector<PublishedFit> fits;
  std::set<std::string> materials;
  std::size_t number = 0;
  while (!text.empty()) {
    const std::size_t nl = text.find('\n');
    std::string_view line = text.substr(0, nl);
    text = nl == std::string_view::npos ? std::string_view{} : text.substr(nl + 1);
    ++number;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    LineReader r(line, source, number);
    if (r.at_end() || line.find_first_not_of(" \t") == line.find('#')) continue;  // blank, comment
    PublishedFit f = r.fit();
    if (!materials.insert(f.material).second)
      throw FormatError(source, fmt::format("line {}", number),
                        fmt::format("material '{}' repeated", f.material));
    fits.push_back(std::move(f));
  }
  return fits;
}

std::vector<PublishedFit> read_published_fits(const std::filesystem::path& path) {
  // Text read line by line within bounds (util/bounded_read.hpp): a NUL byte (binary data, the
  // zeros of a file extended past its end) or a file above 64 MB (the published ones are 15 KB)
  // is refused before it is held.
  TextLines lines(path, std::uint64_t(64) << 20);
  std::string text;
  for (std::string_view line; lines.next(line);) (text += line) += '\n';
  return parse_published_fits(text, path.string());
}

std::string_view registry_name_of(std::string_view bbm_model) {
  // BBM's classes of Ngan et al.'s models (bsdfmodel/ngan.h) and the registry's restatements.
  static constexpr std::pair<std::string_view, std::string_view> kNames[] = {
      {"Lambertian", "lambert"},
      {"NganWard", "ward"},
      {"NganWardDuer", "ward-duer"},
      {"NganBlinnPhong", "blinn-phong"},
      {"NganLafortune", "lafortune"},
      {"NganCookTorrance", "cook-torrance"},
      {"NganAshikhminShirley", "ashikhmin-shirley"},
      {"NganHe", "he"},
      // Löw et al. 2012's and Bagher et al. 2012's (models/published_lobes.hpp).
      {"LowCookTorrance", "low-cook-torrance"},
      {"LowAshikhminShirley", "low-ashikhmin-shirley"},
      {"LowSmooth", "low-smooth"},
      {"LowMicrofacetFit", "low-microfacet"},
      {"Bagher", "bagher-sgd"},
  };
  for (const auto& [bbm, ours] : kNames)
    if (bbm == bbm_model) return ours;
  return {};
}

namespace {

// The registry's name of BBM's parameter `bbm` of `model` (a registry name).
std::string parameter_name(std::string_view model, std::string_view bbm) {
  // Löw's Ashikhmin–Shirley gives its index of refraction the name of Ngan's Schlick F0.
  if (bbm == "fresnelReflectance") return model == "low-ashikhmin-shirley" ? "eta" : "f0";
  if (model == "bagher-sgd" && bbm == "K") return "kscale";  // "k" is another parameter
  std::string name(bbm);
  for (char& c : name) c = char(std::tolower(static_cast<unsigned char>(c)));
  return name;
}

std::string term_spec(const PublishedLobe& lobe, const PublishedFit& fit) {
  const std::string_view model = registry_name_of(lobe.model);
  if (model.empty())
    throw std::invalid_argument(
        fmt::format("{}: halfback has no model for BBM's '{}'", fit.material, lobe.model));
  std::string spec(model);
  char separator = ':';
  const auto add = [&](const std::string& key, double value) {
    spec += fmt::format("{}{}={}", separator, key, value);  // the shortest exact decimal
    separator = ',';
  };
  for (const auto& [key, values] : lobe.params) {
    const std::string name = parameter_name(model, key);
    if (model == "bagher-sgd" && key == "eta" && values.size() == 6) {
      // Bagher et al.'s Fresnel pair [[F0 r, g, b], [F1 r, g, b]] (BBM's vec2d of spectra).
      const char* rows[] = {"f0", "f1"};
      for (int row = 0; row < 2; ++row) {
        add(std::string(rows[row]) + "_r", values[3 * row]);
        add(std::string(rows[row]) + "_g", values[3 * row + 1]);
        add(std::string(rows[row]) + "_b", values[3 * row + 2]);
      }
    } else if (values.size() == 1) {
      add(name, values[0]);
    } else if (values.size() == 3) {
      add(name + "_r", values[0]);
      add(name + "_g", values[1]);
      add(name + "_b", values[2]);
    } else {
      throw std::invalid_argument(fmt::format("{}: {}'s '{}' has {} values (one or three)",
                                              fit.material, lobe.model, key, values.size()));
    }
  }
  return spec;
}

}  // namespace

std::string spec_of(const PublishedFit& fit) {
  std::string spec;
  for (const PublishedLobe& lobe : fit.lobes) {
    if (!spec.empty()) spec += '+';
    spec += term_spec(lobe, fit);
  }
  return spec;
}

std::string model_of(const PublishedFit& fit) {
  std::string model;
  for (const PublishedLobe& lobe : fit.lobes) {
    const std::string_view name = registry_name_of(lobe.model);
    if (name.empty())
      throw std::invalid_argument(
          fmt::format("{}: halfback has no model for BBM's '{}'", fit.material, lobe.model));
    if (!model.empty()) model += '+';
    model += name;
  }
  return model;
}

}  // namespace halfback::fit
