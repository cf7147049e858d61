// The factored BRDF and its JSON file (formats/factored.hpp).
#include "halfback/formats/factored.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "halfback/brdf/rho_bound.hpp"
#include "halfback/core/batch.hpp"
#include "halfback/util/atomic_file.hpp"
#include "halfback/util/format_error.hpp"

namespace halfback {

namespace {

constexpr std::string_view kFormat = "halfback-factored-brdf";
constexpr std::size_t kMaxCells = 4096, kMaxRank = 64;
constexpr std::uintmax_t kMaxFileBytes = std::uintmax_t(64) << 20;
constexpr const char* kChannels[3] = {"r", "g", "b"};

// The largest M_c: ρ_c ≤ exp(M_c) − 1, so a file whose M_c is above log(1 + kMaxRho) can hold
// values above the bound on a BRDF's value (brdf/rho_bound.hpp).
const double kMaxLog = std::log1p(kMaxRho);

// The bound's message for a channel's M_c above kMaxLog ("" when within).
std::string max_log_problem(double max_log) {
  if (!(max_log > kMaxLog)) return {};
  return rho_above_bound(std::expm1(max_log), "its largest, exp(max_log) − 1");
}

void check_model(const FactoredModel& m) {
  if (m.space.is_dirs()) throw std::invalid_argument("factored BRDF: dirs is no parameterization");
  for (std::size_t n : m.counts)
    if (n < 1 || n > kMaxCells)
      throw std::invalid_argument(
          fmt::format("factored BRDF: {} cells on an axis: expected 1 to {}", n, kMaxCells));
  for (double x : m.max_log) {
    if (!(std::isfinite(x) && x >= 0))
      throw std::invalid_argument(
          "factored BRDF: a channel's largest log value is not finite and >= 0");
    if (const std::string problem = max_log_problem(x); !problem.empty())
      throw std::invalid_argument("factored BRDF: max_log: " + problem);
  }
  if (m.rank() < 1 || m.rank() > kMaxRank)
    throw std::invalid_argument(
        fmt::format("factored BRDF: rank {}: expected 1 to {}", m.rank(), kMaxRank));
  for (const auto& terms : m.channels) {
    if (terms.size() != m.rank())
      throw std::invalid_argument("factored BRDF: the channels have different ranks");
    for (const FactoredTerm& t : terms) {
      const std::vector<double>* f[3] = {&t.a, &t.b, &t.phi};
      for (std::size_t axis = 0; axis < 3; ++axis) {
        if (f[axis]->size() != m.counts[axis])
          throw std::invalid_argument(
              fmt::format("factored BRDF: a factor of axis {} has {} values, not {}", axis,
                          f[axis]->size(), m.counts[axis]));
        if (!std::all_of(f[axis]->begin(), f[axis]->end(),
                         [](double x) { return std::isfinite(x); }))
          throw std::invalid_argument("factored BRDF: a factor is not finite");
      }
    }
  }
}

}  // namespace

GridSpec FactoredModel::grid() const {
  return default_grid(space, GridKind::isotropic, {counts[0], counts[1], counts[2]});
}

FactoredBrdf::FactoredBrdf(FactoredModel model) : model_(std::move(model)) {
  check_model(model_);
  // Only the axes' ranges and counts are used (no grid point is made): a grid of one point
  // given the file's counts, which may make more points than a resampled grid may hold.
  grid_ = default_grid(model_.space, GridKind::isotropic, {1, 1, 1});
  for (std::size_t axis = 0; axis < 3; ++axis) grid_.axes[axis].count = model_.counts[axis];
}

std::string FactoredBrdf::description() const {
  return fmt::format("factored BRDF in {}: rank {}, {}x{}x{} cells, {} numbers",
                     name_of(model_.space), model_.rank(), model_.counts[0], model_.counts[1],
                     model_.counts[2], model_.numbers());
}

// Linear interpolation between the cell centres of `axis`, constant beyond the outermost.
double FactoredBrdf::factor_at(const std::vector<double>& f, std::size_t axis, double x) const {
  const GridAxis& g = grid_.axes[axis];
  const double u = (x - g.lo) / (g.hi - g.lo) * double(g.count) - 0.5;
  if (!(u > 0)) return f.front();
  if (u >= double(g.count - 1)) return f.back();
  const auto i = std::size_t(u);
  const double t = u - double(i);
  return f[i] + t * (f[i + 1] - f[i]);
}

Rgb FactoredBrdf::eval(const DirPair<double>& pair) const {
  if (!(pair.wi.z > 0 && pair.wo.z > 0)) return {};
  const double d[6] = {pair.wi.x, pair.wi.y, pair.wi.z, pair.wo.x, pair.wo.y, pair.wo.z};
  double q[3];
  if (!convert_one<double>({Space::dirs, false}, {model_.space, true}, d, q)) return {};
  double out[3];
  for (std::size_t c = 0; c < 3; ++c) {
    double log_value = 0;
    for (const FactoredTerm& t : model_.channels[c])
      log_value += factor_at(t.a, 0, q[0]) * factor_at(t.b, 1, q[1]) * factor_at(t.phi, 2, q[2]);
    out[c] = std::expm1(std::clamp(log_value, 0.0, model_.max_log[c]));
  }
  return {out[0], out[1], out[2]};
}

void write_factored(const std::filesystem::path& path, const FactoredModel& m) {
  write_file_atomically(path, factored_text(m));
}

std::string factored_text(const FactoredModel& m) {
  check_model(m);
  nlohmann::ordered_json j;
  j["format"] = kFormat;
  j["version"] = 1;
  j["name"] = m.name;
  j["parameterization"] = std::string(name_of(m.space));
  j["rank"] = m.rank();
  j["counts"] = m.counts;
  j["max_log"] = m.max_log;
  for (std::size_t c = 0; c < 3; ++c) {
    nlohmann::ordered_json terms = nlohmann::ordered_json::array();
    for (const FactoredTerm& t : m.channels[c])
      terms.push_back({{"a", t.a}, {"b", t.b}, {"phi", t.phi}});
    j["factors"][kChannels[c]] = terms;
  }
  return j.dump(1) + "\n";
}

bool looks_like_factored(std::string_view head) {
  const std::size_t open = head.find_first_not_of(" \t\r\n");
  return open != std::string_view::npos && head[open] == '{' &&
         head.substr(0, 256).find("\"halfback-factored-brdf\"") != std::string_view::npos;
}

namespace {

const nlohmann::json& field(const nlohmann::json& j, const char* key, const std::string& source) {
  if (!j.is_object() || !j.contains(key)) throw FormatError(source, key, "missing");
  return j.at(key);
}

std::vector<double> factor_values(const nlohmann::json& j, const char* key, std::size_t count,
                                  const std::string& source, const std::string& where) {
  const nlohmann::json& v = field(j, key, source);
  const std::string name = where.empty() ? std::string(key) : where + "." + key;
  if (!v.is_array() || v.size() != count)
    throw FormatError(source, name, fmt::format("expected {} numbers", count));
  std::vector<double> out;
  for (const auto& x : v) {
    if (!x.is_number() || !std::isfinite(x.get<double>()))
      throw FormatError(source, name, "not a finite number");
    out.push_back(x.get<double>());
  }
  return out;
}

}  // namespace

FactoredModel parse_factored(std::string_view text, const std::string& source) {
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_discarded()) throw FormatError(source, "file", "not JSON");
  if (field(j, "format", source) != kFormat)
    throw FormatError(source, "format", "not \"halfback-factored-brdf\"");
  if (field(j, "version", source) != 1) throw FormatError(source, "version", "expected 1");
  FactoredModel m;
  const nlohmann::json& name = field(j, "name", source);
  if (!name.is_string()) throw FormatError(source, "name", "not a string");
  m.name = name.get<std::string>();
  // Only a parameterization already known: a family's member ("dupuy-jakob:FILE") would make
  // reading this file load another BRDF (or this one again).
  const nlohmann::json& param = field(j, "parameterization", source);
  const std::vector<Space> known = parameterizations();
  const auto it = std::find_if(known.begin(), known.end(), [&](Space s) {
    return param.is_string() && name_of(s) == param.get<std::string>();
  });
  if (it == known.end())
    throw FormatError(
        source, "parameterization",
        "not the name of a registered parameterization (" + parameterization_names() + ")");
  m.space = *it;
  const nlohmann::json& rank = field(j, "rank", source);
  if (!rank.is_number_unsigned() || rank.get<std::size_t>() < 1 ||
      rank.get<std::size_t>() > kMaxRank)
    throw FormatError(source, "rank", fmt::format("expected 1 to {}", kMaxRank));
  const nlohmann::json& counts = field(j, "counts", source);
  if (!counts.is_array() || counts.size() != 3)
    throw FormatError(source, "counts", "expected three cell counts");
  for (std::size_t axis = 0; axis < 3; ++axis) {
    if (!counts[axis].is_number_unsigned() || counts[axis].get<std::size_t>() < 1 ||
        counts[axis].get<std::size_t>() > kMaxCells)
      throw FormatError(source, "counts", fmt::format("expected 1 to {} cells an axis", kMaxCells));
    m.counts[axis] = counts[axis].get<std::size_t>();
  }
  const std::vector<double> max_log = factor_values(j, "max_log", 3, source, "");
  for (std::size_t c = 0; c < 3; ++c) {
    if (max_log[c] < 0) throw FormatError(source, "max_log", "negative");
    if (const std::string problem = max_log_problem(max_log[c]); !problem.empty())
      throw FormatError(source, fmt::format("max_log[{}]", c), problem);
    m.max_log[c] = max_log[c];
  }
  const nlohmann::json& factors = field(j, "factors", source);
  for (std::size_t c = 0; c < 3; ++c) {
    const nlohmann::json& terms = field(factors, kChannels[c], source);
    if (!terms.is_array() || terms.size() != rank.get<std::size_t>())
      throw FormatError(source, std::string("factors.") + kChannels[c],
                        fmt::format("expected {} terms", rank.get<std::size_t>()));
    for (std::size_t r = 0; r < terms.size(); ++r) {
      const std::string where = fmt::format("factors.{}[{}]", kChannels[c], r);
      m.channels[c].push_back({factor_values(terms[r], "a", m.counts[0], source, where),
                               factor_values(terms[r], "b", m.counts[1], source, where),
                               factor_values(terms[r], "phi", m.counts[2], source, where)});
    }
  }
  return m;
}

FactoredModel read_factored(const std::filesystem::path& path) {
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) throw FormatError(path.string(), "file", "cannot get its size: " + ec.message());
  if (size > kMaxFileBytes)
    throw FormatError(
        path.string(), "file",
        fmt::format("{} bytes, above the {} of a factored BRDF", size, kMaxFileBytes));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FormatError(path.string(), "file", "cannot open for reading");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_factored(text.str(), path.string());
}

}  // namespace halfback
