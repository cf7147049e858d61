#include "halfback/formats/alta.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "binary_io.hpp"
#include "halfback/brdf/rho_bound.hpp"
#include "halfback/util/bounded_read.hpp"
#include "halfback/util/format_error.hpp"
#include "kdtree.hpp"

namespace halfback {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr std::uintmax_t kMaxFileBytes = std::uintmax_t(1) << 31;  // 2 GiB of text

struct ParamInfo {
  std::string_view name;
  std::size_t dim;
};
// The input parameterizations of ALTA (params.h of the ALTA library) and their dimensions.
constexpr ParamInfo kParams[] = {
    {"COS_TH", 1},
    {"COS_TK", 1},
    {"COS_TLV", 1},
    {"COS_TLR", 1},
    {"RUSIN_TH_TD", 2},
    {"COS_TH_TD", 2},
    {"ISOTROPIC_TV_PROJ_DPHI", 2},
    {"STARK_2D", 2},
    {"NEUMANN_2D", 2},
    {"RUSIN_TH_TD_PD", 3},
    {"RUSIN_TH_PH_TD", 3},
    {"ISOTROPIC_TV_TL_DPHI", 3},
    {"RUSIN_VH", 3},
    {"SCHLICK_VK", 3},
    {"ISOTROPIC_TL_TV_PROJ_DPHI", 3},
    {"SCHLICK_TL_TK_PROJ_DPHI", 3},
    {"RETRO_TL_TVL_PROJ_DPHI", 3},
    {"STARK_3D", 3},
    {"NEUMANN_3D", 3},
    {"RUSIN_TH_PH_TD_PD", 4},
    {"SPHERICAL_TL_PL_TV_PV", 4},
    {"STEREOGRAPHIC", 4},
    {"CARTESIAN", 6},
};
constexpr std::string_view kOutputs[] = {"INV_STERADIAN", "INV_STERADIAN_COSINE_FACTOR", "ENERGY",
                                         "RGB_COLOR", "XYZ_COLOR"};

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

std::string_view next_token(std::string_view& s) {
  s = trim(s);
  std::size_t n = 0;
  while (n < s.size() && s[n] != ' ' && s[n] != '\t') ++n;
  const std::string_view t = s.substr(0, n);
  s.remove_prefix(n);
  return t;
}

std::string printable(std::string_view t) {
  std::string r;
  for (char c : t.substr(0, 40)) r += (c >= 32 && c < 127) ? c : '?';
  if (t.size() > 40) r += "...";
  return r;
}

bool parse_size(std::string_view t, std::size_t& v) {
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  return r.ec == std::errc() && r.ptr == t.data() + t.size();
}

}  // namespace

std::size_t alta_param_dimension(std::string_view name) {
  for (const auto& p : kParams)
    if (p.name == name) return p.dim;
  return 0;
}

namespace {

// The parser of an ALTA file, fed one line at a time (from memory or from a file read line by
// line), so that a file is never held whole.
class AltaParser {
 public:
  explicit AltaParser(std::string name) : name_(std::move(name)) {}

  void line(std::string_view line) {
    ++line_no_;
    require_text_line(name_, line_no_, line);
    // Editors on Windows start UTF-8 text with a byte-order mark; it is not part of the header.
    constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";
    if (line_no_ == 1 && line.substr(0, kUtf8Bom.size()) == kUtf8Bom)
      line.remove_prefix(kUtf8Bom.size());
    line = trim(line);
    if (line.empty()) return;
    if (line.front() == '#')
      header_line(line);
    else
      data_line(line);
  }

  AltaData finish() {
    if (!have_dim_) throw FormatError(name_, "header", "no #DIM line (not an ALTA data file)");
    if (d_.rows() == 0) throw FormatError(name_, "data", "no data lines");
    return std::move(d_);
  }

 private:
  [[noreturn]] void fail(const std::string& problem) const {
    throw FormatError(name_, "line " + std::to_string(line_no_), problem);
  }

  void header_line(std::string_view line) {
    std::string_view rest = line.substr(1);
    const std::string_view key = next_token(rest);
    const std::string_view value = trim(rest);
    if (key == "FUNC" || (key == "ALTA" && value.rfind("FUNC", 0) == 0))
      fail("an ALTA function file (a fitted model, '#" + printable(trim(line.substr(1))) +
           "'), not ALTA data: halfback reads ALTA data files (#DIM, #PARAM_IN, #PARAM_OUT, "
           "then one sample per line)");
    if (key == "DIM" || key == "PARAM_IN" || key == "PARAM_OUT" || key == "VS" || key == "FORMAT") {
      if (d_.rows() > 0) fail("header entry #" + std::string(key) + " after the first data line");
      if (d_.header.count(std::string(key))) fail("#" + std::string(key) + " given twice");
    }
    if (key == "DIM") {
      std::string_view r = value;
      const std::string_view a = next_token(r), b = next_token(r);
      if (!parse_size(a, d_.dim_in) || !parse_size(b, d_.dim_out) || !trim(r).empty())
        fail("#DIM expects two integers, got '" + printable(value) + "'");
      if (d_.dim_in < 1 || d_.dim_in > 6) fail("#DIM: input dimension must be 1 to 6");
      if (d_.dim_out < 1 || d_.dim_out > 3) fail("#DIM: output dimension must be 1 to 3");
      have_dim_ = true;
    } else if (key == "PARAM_IN") {
      if (alta_param_dimension(value) == 0)
        fail("#PARAM_IN: unknown input parameterization '" + printable(value) + "'");
      d_.param_in = std::string(value);
    } else if (key == "PARAM_OUT") {
      if (std::find(std::begin(kOutputs), std::end(kOutputs), value) == std::end(kOutputs))
        fail("#PARAM_OUT: unknown output parameterization '" + printable(value) + "'");
      d_.param_out = std::string(value);
    } else if (key == "VS") {
      std::size_t vs;
      if (!parse_size(value, vs) || vs > 2)
        fail("#VS expects 0, 1 or 2, got '" + printable(value) + "'");
      d_.vs = static_cast<int>(vs);
    } else if (key == "FORMAT") {
      if (value != "text")
        fail("#FORMAT " + printable(value) + ": only text ALTA files are supported");
    }
    if (!key.empty() && d_.rows() == 0) d_.header[std::string(key)] = std::string(value);
  }

  std::string counts() const {
    return std::to_string(d_.dim_in) + " inputs, " + std::to_string(d_.dim_out) + " outputs" +
           (d_.vs ? ", " + std::to_string(d_.vs) + " for #VS" : std::string());
  }

  void data_line(std::string_view line) {
    if (d_.rows() == 0) {
      if (!have_dim_) fail("data before #DIM (an ALTA file starts with a #DIM line)");
      if (!d_.param_in.empty() && alta_param_dimension(d_.param_in) != d_.dim_in)
        fail("#PARAM_IN " + d_.param_in + " has dimension " +
             std::to_string(alta_param_dimension(d_.param_in)) + " but #DIM says " +
             std::to_string(d_.dim_in));
      expected_ = d_.dim_in + d_.dim_out + static_cast<std::size_t>(d_.vs);
    }
    double values[6 + 3 + 2];
    std::size_t n = 0;
    std::string_view rest = line;
    while (true) {
      const std::string_view tok = next_token(rest);
      if (tok.empty()) break;
      if (n == expected_)
        fail("more than the " + std::to_string(expected_) + " numbers expected (" + counts() + ")");
      double v;
      const auto r = std::from_chars(tok.data(), tok.data() + tok.size(), v);
      if (r.ec != std::errc() || r.ptr != tok.data() + tok.size())
        fail("column " + std::to_string(n + 1) + ": '" + printable(tok) + "' is not a number");
      if (!std::isfinite(v))
        fail("column " + std::to_string(n + 1) + ": '" + printable(tok) + "' is not finite");
      values[n++] = v;
    }
    if (n != expected_)
      fail(std::to_string(n) + " numbers, expected " + std::to_string(expected_) + " (" + counts() +
           ")");
    d_.x.insert(d_.x.end(), values, values + d_.dim_in);
    d_.y.insert(d_.y.end(), values + d_.dim_in, values + d_.dim_in + d_.dim_out);
    if (d_.vs == 1) {
      const double v0 = values[d_.dim_in], dt = values[d_.dim_in + d_.dim_out];
      d_.interval.push_back(v0 - dt);
      d_.interval.push_back(v0 + dt);
    } else if (d_.vs == 2) {
      d_.interval.push_back(values[d_.dim_in + d_.dim_out]);
      d_.interval.push_back(values[d_.dim_in + d_.dim_out + 1]);
    }
    d_.line.push_back(line_no_);
  }

  std::string name_;
  AltaData d_;
  bool have_dim_ = false;
  std::size_t line_no_ = 0, expected_ = 0;
};

}  // namespace

AltaData parse_alta(std::string_view text, std::string_view name) {
  AltaParser parser{std::string(name)};
  while (!text.empty()) {
    const std::size_t eol = text.find('\n');
    parser.line(text.substr(0, eol));
    text.remove_prefix(eol == std::string_view::npos ? text.size() : eol + 1);
  }
  return parser.finish();
}

AltaData read_alta(const std::filesystem::path& path) {
  TextLines lines(path, kMaxFileBytes);
  AltaParser parser(lines.name());
  std::string_view line;
  while (lines.next(line)) parser.line(line);
  return parser.finish();
}

// ---------------------------------------------------------------------------------------------
// Evaluation
// ---------------------------------------------------------------------------------------------

namespace {

using Tree = io_detail::KdTree<2>;

struct Slice {
  double theta_l;
  Tree tree;
  std::vector<std::array<double, 3>> value;  // ρ per sample, in the tree's point order
  double support = 0;                        // no data farther than this from every sample
};

// Below this cosine of the view elevation a cosine-weighted value cannot be turned into ρ (0/0).
constexpr double kMinCosView = 1e-3;

}  // namespace

struct AltaBrdf::Impl {
  std::vector<Slice> slices;  // by increasing θl
  std::string param_out, sample;
  std::size_t samples = 0, dropped = 0, dim_out = 1;
  std::size_t negative = 0;  // samples with a negative value, clamped to 0
};

AltaBrdf::AltaBrdf(const AltaData& data, std::string file, std::string label, AltaOptions options)
    : impl_(std::make_unique<Impl>()), label_(std::move(label)), options_(options) {
  Impl& m = *impl_;
  if (data.param_in.empty())
    throw FormatError(file, "header",
                      "no #PARAM_IN line, so the coordinates of the samples are unknown: "
                      "evaluation supports '#PARAM_IN ISOTROPIC_TL_TV_PROJ_DPHI' (θl, θv·cos Δφ, "
                      "θv·sin Δφ)");
  if (data.param_in != "ISOTROPIC_TL_TV_PROJ_DPHI")
    throw FormatError(
        file, "#PARAM_IN",
        "'" + data.param_in +
            "': evaluation supports ISOTROPIC_TL_TV_PROJ_DPHI (θl, θv·cos Δφ, θv·sin Δφ)");
  if (data.param_out.empty())
    throw FormatError(file, "header",
                      "no #PARAM_OUT line, so the unit of the values is unknown: add "
                      "'#PARAM_OUT INV_STERADIAN' (values are ρ) or '#PARAM_OUT "
                      "INV_STERADIAN_COSINE_FACTOR' (values are ρ·cos θv)");
  const bool cosine = data.param_out == "INV_STERADIAN_COSINE_FACTOR";
  if (!cosine && data.param_out != "INV_STERADIAN")
    throw FormatError(file, "#PARAM_OUT",
                      "'" + data.param_out +
                          "': evaluation supports INV_STERADIAN and INV_STERADIAN_COSINE_FACTOR");
  if (data.dim_out != 1 && data.dim_out != 3)
    throw FormatError(file, "#DIM", "evaluation needs 1 (gray) or 3 (RGB) values per sample");
  if (options_.neighbours < 1 || options_.neighbours > 64)
    throw std::invalid_argument("AltaOptions::neighbours must be 1 to 64");
  m.param_out = data.param_out;
  m.dim_out = data.dim_out;
  if (auto it = data.header.find("SAMPLE"); it != data.header.end()) m.sample = it->second;

  // Group the samples by incidence angle θl.
  struct Row {
    double theta_l, px, py;
    std::array<double, 3> rho;
  };
  std::vector<Row> rows;
  rows.reserve(data.rows());
  const double tol = 1e-9;
  for (std::size_t r = 0; r < data.rows(); ++r) {
    const double* x = &data.x[3 * r];
    const double* y = &data.y[data.dim_out * r];
    const std::string field = "line " + std::to_string(data.line[r]);
    if (x[0] < -tol || x[0] > kPi / 2 + tol)
      throw FormatError(file, field, fmt::format("θl = {:g} rad is outside [0, π/2]", x[0]));
    const double theta_v = std::hypot(x[1], x[2]);
    if (theta_v > kPi / 2 + tol)
      throw FormatError(file, field,
                        fmt::format("θv = √(x2² + x3²) = {:g} rad exceeds π/2", theta_v));
    std::array<double, 3> rho{y[0], y[data.dim_out == 3 ? 1 : 0], y[data.dim_out == 3 ? 2 : 0]};
    // A negative measurement of ρ (noise around 0) counts as 0 (docs/formats.md, "Missing and
    // negative measurements").
    if (std::any_of(rho.begin(), rho.end(), [](double v) { return v < 0; })) {
      ++m.negative;
      for (double& v : rho) v = std::max(v, 0.0);
    }
    if (cosine) {
      const double c = std::cos(std::min(theta_v, kPi / 2));
      if (c < kMinCosView) {
        ++m.dropped;
        continue;
      }
      for (double& v : rho) v /= c;
    }
    // The bound on ρ (brdf/rho_bound.hpp), on the value as read, after the division by cos θv.
    for (double v : rho)
      if (!rho_within_bound(v))
        throw FormatError(file, field, "the sample's value gives " + rho_above_bound(v));
    rows.push_back({std::clamp(x[0], 0.0, kPi / 2), x[1], x[2], rho});
  }
  std::sort(rows.begin(), rows.end(),
            [](const Row& a, const Row& b) { return a.theta_l < b.theta_l; });
  for (std::size_t b = 0; b < rows.size();) {
    std::size_t e = b;
    while (e < rows.size() && rows[e].theta_l == rows[b].theta_l) ++e;
    if (e - b < 3)
      throw FormatError(file, "data",
                        fmt::format("incidence θl = {:g} has {} samples: evaluation needs the "
                                    "samples grouped by incidence angle, at least 3 per angle",
                                    rows[b].theta_l, e - b));
    Slice s;
    s.theta_l = rows[b].theta_l;
    std::vector<Tree::Point> pts;
    for (std::size_t i = b; i < e; ++i) pts.push_back({rows[i].px, rows[i].py});
    s.tree = Tree(std::move(pts));
    for (std::size_t i = b; i < e; ++i) s.value.push_back(rows[i].rho);
    // Support radius: 1.5 × the largest distance from a sample to its nearest other sample.
    std::vector<Tree::Neighbour> nb;
    double widest = 0;
    for (std::size_t i = 0; i < s.tree.size(); ++i) {
      s.tree.nearest(s.tree.point(i), 2, nb);
      widest = std::max(widest, std::sqrt(nb.back().dist2));
    }
    s.support = 1.5 * widest;
    m.samples += e - b;
    m.slices.push_back(std::move(s));
    b = e;
  }
  if (m.slices.empty())
    throw FormatError(file, "data", "no usable samples (all at grazing view with a cosine factor)");
}

AltaBrdf::~AltaBrdf() = default;

std::string AltaBrdf::name() const {
  return "alta:" + label_;
}

std::string AltaBrdf::description() const {
  std::string d = "ALTA measured BRDF";
  if (!impl_->sample.empty()) d += " " + impl_->sample;
  d += " (" + std::to_string(impl_->samples) + " samples at " +
       std::to_string(impl_->slices.size()) + " incidence angles, " + impl_->param_out + ")";
  return d;
}

std::vector<Brdf::Fact> AltaBrdf::facts() const {
  const Impl& m = *impl_;
  std::vector<Fact> f;
  f.push_back(
      {"format", "ALTA text data, #PARAM_IN ISOTROPIC_TL_TV_PROJ_DPHI, #PARAM_OUT " + m.param_out});
  if (!m.sample.empty()) f.push_back({"sample", m.sample});
  f.push_back({"samples", fmt::format("{} used, {} dropped at grazing view (see docs/formats.md)",
                                      m.samples, m.dropped)});
  f.push_back({"negative samples", fmt::format("{} (clamped to 0)", m.negative)});
  f.push_back({"missing", "ρ is NaN where no sample is near (outside the measured support)"});
  std::string angles;
  for (const double a : incidence_angles())
    angles += fmt::format("{}{:.4g}°", angles.empty() ? "" : ", ", a * 180 / std::numbers::pi);
  f.push_back({"incidence angles θl", angles});
  f.push_back({"channels", m.dim_out == 3 ? "RGB" : "one (gray, copied to R, G, B)"});
  return f;
}

std::size_t AltaBrdf::samples() const {
  return impl_->samples;
}
std::size_t AltaBrdf::dropped_grazing() const {
  return impl_->dropped;
}
std::size_t AltaBrdf::negative_samples() const {
  return impl_->negative;
}
std::vector<double> AltaBrdf::incidence_angles() const {
  std::vector<double> r;
  for (const auto& s : impl_->slices) r.push_back(s.theta_l);
  return r;
}
double AltaBrdf::support_radius(std::size_t slice) const {
  return impl_->slices.at(slice).support;
}

Rgb AltaBrdf::eval_coords(double theta_l, double px, double py) const {
  const Impl& m = *impl_;
  const double outside = options_.zero_outside ? 0.0 : kNaN;
  const Rgb none{outside, outside, outside};
  if (std::isnan(theta_l) || std::isnan(px) || std::isnan(py)) return {kNaN, kNaN, kNaN};

  // Modified Shepard interpolation in one slice; false where the slice has no data.
  auto in_slice = [&](const Slice& s, std::array<double, 3>& out) {
    const auto k = static_cast<std::size_t>(options_.neighbours);
    thread_local std::vector<Tree::Neighbour> nb;
    s.tree.nearest({px, py}, k + 1, nb);
    if (std::sqrt(nb.front().dist2) > s.support) return false;
    out = {0, 0, 0};
    if (nb.front().dist2 == 0) {  // on a sample (average coincident ones)
      std::size_t n = 0;
      for (const auto& x : nb) {
        if (x.dist2 != 0) break;
        for (int c = 0; c < 3; ++c) out[c] += s.value[x.index][c];
        ++n;
      }
      for (double& v : out) v /= double(n);
      return true;
    }
    // Weights ((R - d)/(R d))², R the distance of the (k+1)-th neighbour, which has weight 0: the
    // interpolant stays continuous when the set of neighbours changes.
    const std::size_t used = std::min(k, nb.size());
    const double radius =
        nb.size() > k ? std::sqrt(nb.back().dist2) : 1.5 * std::sqrt(nb.back().dist2);
    double wsum = 0;
    for (std::size_t i = 0; i < used; ++i) {
      const double d = std::sqrt(nb[i].dist2);
      const double w = std::pow(std::max(radius - d, 0.0) / (radius * d), 2);
      wsum += w;
      for (int c = 0; c < 3; ++c) out[c] += w * s.value[nb[i].index][c];
    }
    if (!(wsum > 0)) {  // all neighbours equidistant at R: plain inverse-distance weights
      out = {0, 0, 0};
      for (std::size_t i = 0; i < used; ++i) {
        const double w = 1 / nb[i].dist2;
        wsum += w;
        for (int c = 0; c < 3; ++c) out[c] += w * s.value[nb[i].index][c];
      }
    }
    for (double& v : out) v /= wsum;
    return true;
  };

  // Linear in θl between the two measured incidences around it; no extrapolation. The tolerance
  // covers angles written with 8 decimals (0.26179939 for 15°).
  const auto& sl = m.slices;
  const double tol = 1e-6;
  if (theta_l < sl.front().theta_l - tol || theta_l > sl.back().theta_l + tol) return none;
  std::size_t j = 0;
  while (j + 1 < sl.size() && sl[j + 1].theta_l <= theta_l) ++j;
  std::array<double, 3> a{}, b{};
  // On a measured incidence (within the tolerance): that slice alone.
  for (std::size_t k : {j, j + 1}) {
    if (k < sl.size() && std::abs(theta_l - sl[k].theta_l) <= tol) {
      if (!in_slice(sl[k], a)) return none;
      return {a[0], a[1], a[2]};
    }
  }
  if (j + 1 == sl.size()) return none;  // unreachable: θl beyond the last slice was rejected
  const double t = (theta_l - sl[j].theta_l) / (sl[j + 1].theta_l - sl[j].theta_l);
  if (!in_slice(sl[j], a) || !in_slice(sl[j + 1], b)) return none;
  return {(1 - t) * a[0] + t * b[0], (1 - t) * a[1] + t * b[1], (1 - t) * a[2] + t * b[2]};
}

Rgb AltaBrdf::eval(const DirPair<double>& pair) const {
  const double v[6] = {pair.wi.x, pair.wi.y, pair.wi.z, pair.wo.x, pair.wo.y, pair.wo.z};
  for (double x : v)
    if (std::isnan(x)) return {kNaN, kNaN, kNaN};
  if (pair.wi.z < 0 || pair.wo.z < 0) return {};
  // The canonical pose of the file's parameterization: the light at azimuth 0, the view at Δφ.
  const double theta_l = std::atan2(std::hypot(pair.wi.x, pair.wi.y), pair.wi.z);
  const double theta_v = std::atan2(std::hypot(pair.wo.x, pair.wo.y), pair.wo.z);
  const double dphi = std::atan2(pair.wo.y, pair.wo.x) - std::atan2(pair.wi.y, pair.wi.x);
  return eval_coords(theta_l, theta_v * std::cos(dphi), theta_v * std::sin(dphi));
}

std::shared_ptr<const AltaBrdf> load_alta(const std::filesystem::path& path, AltaOptions options) {
  return std::make_shared<const AltaBrdf>(read_alta(path), path.string(), path.stem().string(),
                                          options);
}

}  // namespace halfback
