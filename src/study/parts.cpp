#include "halfback/study/parts.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "halfback/render/image.hpp"
#include "halfback/study/metric.hpp"
#include "halfback/study/metric_tables.hpp"
#include "halfback/util/atomic_file.hpp"
#include "halfback/util/csv.hpp"
#include "material_spaces.hpp"

namespace halfback::study {

using acquire::AxisDemand;
using acquire::design_profile;
using acquire::DesignProfile;
using acquire::learn_warps;
using acquire::parse_error_space;
using acquire::parse_spacing;
using acquire::Spacing;

namespace {

void apply_quick(StudyConfig& c) {
  c.quick = true;
  c.grid = {24, 24, 32};
  c.full_grid = {8, 16, 8, 16};
  c.budgets = {1000, 10000};
  c.budgets_4d = {1000, 10000};
  c.test_pairs = 20000;
  c.image_size = 48;
  c.image_spp = 8;
  for (const Metric* m : study_metrics()) {
    const std::vector<MetricOption> own = m->options();
    for (std::size_t i = 0; i < own.size(); ++i)
      if (!c.option(own[i].key).empty()) c.options[own[i].key] = option_default(*m, i).quick;
  }
}

bool named(const std::vector<std::string>& names, std::string_view name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

// The names of --metrics and --no-NAME are metrics; std::invalid_argument otherwise.
void check_metric_names(const StudySettings& o) {
  for (const auto* list : {&o.metrics, &o.off})
    for (const std::string& name : *list)
      if (!find_metric(name))
        throw std::invalid_argument(
            fmt::format("--metrics: '{}' is not a metric ({})", name, metric_names()));
  for (const auto& [key, value] : o.options) {
    const bool known =
        std::any_of(study_metrics().begin(), study_metrics().end(), [&](const Metric* m) {
          const auto own = m->options();
          return std::any_of(own.begin(), own.end(),
                             [&](const MetricOption& x) { return x.key == key; });
        });
    if (!known) throw std::invalid_argument(fmt::format("'{}' is not an option of a metric", key));
  }
}

// Whether the settings run `m`.
bool runs(const StudySettings& o, const Metric& m) {
  if (!m.switchable()) return true;
  const bool asked = o.metrics.empty() ? m.on_by_default() : named(o.metrics, m.name());
  return asked && !named(o.off, m.name());
}

// The given options of the metrics (their kinds checked, as the CLI's flags name them), and the
// default of the first option of a metric that runs though it is not on by default.
void apply_options(const StudySettings& o, StudyConfig& c) {
  for (const Metric* m : study_metrics()) {
    const std::vector<MetricOption> own = m->options();
    for (std::size_t i = 0; i < own.size(); ++i) {
      std::string flag = "--" + own[i].key;
      std::replace(flag.begin(), flag.end(), '_', '-');
      if (const auto it = o.options.find(own[i].key);
          it != o.options.end() && !it->second.empty()) {
        check_option_text(own[i], it->second, flag);
        c.options[own[i].key] = it->second;
      } else if (const OptionDefault d = option_default(*m, i); d.when_run && runs(o, *m)) {
        c.options[own[i].key] = o.quick ? d.quick : d.value;
      }
    }
  }
}

void check_ascending(const std::vector<std::size_t>& v, const char* option) {
  for (std::size_t i = 1; i < v.size(); ++i)
    if (v[i] <= v[i - 1])
      throw std::invalid_argument(fmt::format("{}: budgets must be ascending", option));
}

template <class T>
std::vector<std::string_view> names_of(const std::vector<T>& items) {
  std::vector<std::string_view> names;
  for (const T& item : items) names.push_back(name_of(item));
  return names;
}

// The parameterizations of --params (std::invalid_argument) or of a description
// (std::runtime_error), by name.
template <class Error>
std::vector<Space> params_named(const std::vector<std::string>& names, const std::string& where) {
  std::vector<Space> params;
  for (const std::string& name : names) {
    const auto space = space_from_name(name);
    if (!space || space->is_dirs())
      throw Error(fmt::format("{}: '{}' is not a parameterization ({})", where, name,
                              parameterization_names()));
    if (std::find(params.begin(), params.end(), *space) != params.end())
      throw Error(fmt::format("{}: '{}' is given twice", where, name));
    params.push_back(*space);
  }
  if (params.empty()) throw Error(where + ": no parameterization given");
  return params;
}

template <class T>
std::string joined(const std::vector<T>& v) {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) s += fmt::format("{}{}", i ? "," : "", v[i]);
  return s;
}

}  // namespace

StudyConfig quick_config() {
  StudyConfig c;
  apply_quick(c);
  return c;
}

StudyConfig make_config(const StudySettings& o) {
  StudyConfig c;
  if (!o.params.empty()) c.params = params_named<std::invalid_argument>(o.params, "--params");
  const auto space = parse_error_space(o.space);
  if (!space)
    throw std::invalid_argument(fmt::format(
        "--error-space '{}': expected linear, log, cbrt, nielsen or low (docs/study.md)", o.space));
  c.space = *space;
  c.spacings.clear();
  for (const std::string& name : o.designs) {
    const auto spacing = parse_spacing(name);
    if (!spacing)
      throw std::invalid_argument(
          fmt::format("--spacings: '{}' is not a spacing (own, angle, merl or learned)", name));
    if (std::find(c.spacings.begin(), c.spacings.end(), *spacing) != c.spacings.end())
      throw std::invalid_argument(fmt::format("--spacings: '{}' is given twice", name));
    c.spacings.push_back(*spacing);
  }
  if (c.spacings.empty()) throw std::invalid_argument("--spacings: no spacing given");
  if (o.quick) apply_quick(c);
  check_ascending(o.budgets, "--budgets");
  check_ascending(o.budgets_4d, "--budgets-4d");
  if (!o.budgets.empty()) c.budgets = o.budgets;
  if (!o.budgets_4d.empty()) c.budgets_4d = o.budgets_4d;
  if (o.test_pairs) c.test_pairs = o.test_pairs;
  if (o.image_size) c.image_size = o.image_size;
  if (o.image_spp) c.image_spp = o.image_spp;
  check_metric_names(o);
  apply_options(o, c);
  check_ascending(o.nielsen_counts, "--nielsen-budgets");
  if (!o.nielsen_counts.empty()) c.nielsen_counts = o.nielsen_counts;
  c.seed = o.seed;
  c.max_theta_deg = o.max_theta;
  // The image budget: as asked, else 10^4 if it is a budget, else the middle budget.
  if (o.image_budget)
    c.image_budget = o.image_budget;
  else if (!c.budgets.empty() &&
           std::find(c.budgets.begin(), c.budgets.end(), c.image_budget) == c.budgets.end())
    c.image_budget = c.budgets[c.budgets.size() / 2];
  const bool gonio = runs(o, *find_metric("gonio"));
  if (gonio && runs(o, *find_metric("images"))) {  // the environments are loaded only for these
    if (o.environments.empty())
      c.environments = render::default_environments();
    else
      for (const std::string& spec : o.environments)
        c.environments.push_back(render::load_environment(spec));
  }
  for (const Metric* m : study_metrics())
    if (!runs(o, *m)) m->switch_off(c);
  c.validate();
  return c;
}

std::string describe_config(const StudyConfig& c) {
  std::string envs;
  for (const render::Environment& e : c.environments) {
    if (!envs.empty()) envs += ',';
    envs += csv_text_field(e.label);
  }
  // The metrics' options, in the order of the list.
  std::string metric_lines;
  for (const Metric* m : study_metrics())
    for (const MetricOption& o : m->options())
      metric_lines += fmt::format("{} = {}\n", o.key, c.option(o.key));
  // Nielsen's lines only with a database: the settings of runs without one read as before.
  const std::string nielsen = c.nielsen_from.empty()
                                  ? std::string()
                                  : fmt::format("nielsen_from = {}\nnielsen_counts = {}\n",
                                                c.nielsen_from, joined(c.nielsen_counts));
  // A quick run says so (its report warns that its headline is not the study's), in a line of its
  // own: the settings of a full run read as before.
  const std::string quick = c.quick ? "quick = 1\n" : "";
  return fmt::format(
      "parameterizations = {}\nspace = {}\ngrid = {},{},{}\nfull_grid = {}\nranks = {}\nbudgets = "
      "{}\nbudgets_4d = {}\n"
      "test_pairs = {}\nmax_theta_deg = {}\nseed = {}\nenvironments = {}\nimage_budget = {}\n"
      "image_size = {}\nimage_spp = {}\ndesigns = {}\nprofile_grid = {},{},{}\n"
      "learned_from = {}\n{}{}{}",
      joined(names_of(c.params)), name_of(c.space), c.grid.a, c.grid.b, c.grid.phi,
      joined(std::vector<std::size_t>(c.full_grid.begin(), c.full_grid.end())), joined(c.ranks),
      joined(c.budgets), joined(c.budgets_4d), c.test_pairs, format_csv_number(c.max_theta_deg),
      c.seed, envs, c.image_budget, c.image_size, c.image_spp, joined(names_of(c.spacings)),
      c.profile_grid.a, c.profile_grid.b, c.profile_grid.phi, c.learned_from, metric_lines, nielsen,
      quick);
}

namespace {

template <class T>
T number_of(std::string_view text, const std::string& where) {
  T v{};
  if constexpr (std::is_floating_point_v<T>) {
    if (parse_csv_number(text, v, false).empty()) return v;
  } else {
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec == std::errc() && end == text.data() + text.size()) return v;
  }
  throw std::runtime_error(fmt::format("{}: '{}' is not a number", where, text));
}

template <class T>
std::vector<T> numbers_of(std::string_view text, const std::string& where) {
  std::vector<T> v;
  if (text.empty()) return v;
  for (const std::string& f : split_csv_line(text)) v.push_back(number_of<T>(f, where));
  return v;
}

}  // namespace

StudyConfig config_from_description(std::string_view text, const std::string& source) {
  std::map<std::string, std::string> kv;
  std::istringstream in{std::string(text)};
  std::size_t line_no = 0;
  for (std::string line; std::getline(in, line);) {
    ++line_no;
    const std::size_t eq = line.find(" = ");
    if (line.empty()) continue;
    if (eq == std::string::npos)
      throw std::runtime_error(fmt::format("{}:{}: expected 'key = value'", source, line_no));
    kv[line.substr(0, eq)] = line.substr(eq + 3);
  }
  auto get = [&](const char* key) -> std::string {
    const auto it = kv.find(key);
    if (it == kv.end()) throw std::runtime_error(fmt::format("{}: no '{}' line", source, key));
    return it->second;
  };
  const std::string where = source;
  StudyConfig c;
  c.params = params_named<std::runtime_error>(split_csv_line(get("parameterizations")),
                                              source + ": parameterizations");
  const auto space = parse_error_space(get("space"));
  if (!space) throw std::runtime_error(fmt::format("{}: unknown error space", source));
  c.space = *space;
  const auto grid = numbers_of<std::size_t>(get("grid"), where);
  const auto full = numbers_of<std::size_t>(get("full_grid"), where);
  if (grid.size() != 3 || full.size() != 4)
    throw std::runtime_error(fmt::format("{}: a grid has the wrong number of axes", source));
  c.grid = {grid[0], grid[1], grid[2]};
  std::copy(full.begin(), full.end(), c.full_grid.begin());
  c.ranks = numbers_of<int>(get("ranks"), where);
  c.budgets = numbers_of<std::size_t>(get("budgets"), where);
  c.budgets_4d = numbers_of<std::size_t>(get("budgets_4d"), where);
  c.test_pairs = number_of<std::size_t>(get("test_pairs"), where);
  c.max_theta_deg = number_of<double>(get("max_theta_deg"), where);
  c.seed = number_of<std::uint64_t>(get("seed"), where);
  const std::string envs = get("environments");
  if (!envs.empty())
    for (const std::string& label : split_csv_line(envs)) c.environments.push_back({label, {}});
  c.image_budget = number_of<std::size_t>(get("image_budget"), where);
  c.image_size = number_of<int>(get("image_size"), where);
  c.image_spp = number_of<int>(get("image_spp"), where);
  c.spacings.clear();
  for (const std::string& name : split_csv_line(get("designs"))) {
    const auto spacing = parse_spacing(name);
    if (!spacing) throw std::runtime_error(fmt::format("{}: unknown design '{}'", source, name));
    c.spacings.push_back(*spacing);
  }
  const auto profile_grid = numbers_of<std::size_t>(get("profile_grid"), where);
  if (profile_grid.size() != 3)
    throw std::runtime_error(fmt::format("{}: a grid has the wrong number of axes", source));
  c.profile_grid = {profile_grid[0], profile_grid[1], profile_grid[2]};
  c.learned_from = get("learned_from");
  if (const auto it = kv.find("quick"); it != kv.end()) {
    if (it->second != "1")
      throw std::runtime_error(fmt::format("{}: quick = '{}': expected 1", source, it->second));
    c.quick = true;
  }
  // The metrics' options. A run's settings without a metric's lines (written before it was
  // added): the metric off, its other options at their defaults.
  for (const Metric* m : study_metrics()) {
    const std::vector<MetricOption> own = m->options();
    for (std::size_t i = 0; i < own.size(); ++i) {
      const auto it = kv.find(own[i].key);
      if (it == kv.end()) {
        if (i == 0) c.options[own[i].key].clear();
        continue;
      }
      try {
        if (!it->second.empty()) check_option_text(own[i], it->second, own[i].key);
      } catch (const std::invalid_argument& e) {
        throw std::runtime_error(fmt::format("{}: {}", source, e.what()));
      }
      c.options[own[i].key] = it->second;
    }
  }
  // Runs without Nielsen's database have neither line.
  if (kv.count("nielsen_from")) c.nielsen_from = get("nielsen_from");
  if (kv.count("nielsen_counts"))
    c.nielsen_counts = numbers_of<std::size_t>(get("nielsen_counts"), where);
  return c;
}

std::string study_label(std::string_view spec, const Brdf& brdf) {
  std::error_code ec;
  return std::filesystem::exists(spec, ec) ? brdf.name() : std::string(spec);
}

// ---------------------------------------------------------------------------------------------
// Profiles (the learned design)
// ---------------------------------------------------------------------------------------------

namespace {

constexpr std::string_view kProfileMagic = "# halfback study profile 1\n";

std::uint64_t fnv1a(std::string_view s, std::uint64_t h = 1469598103934665603ull) {
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  return h;
}

}  // namespace

bool wants_learned(const StudyConfig& c) {
  return !c.budgets.empty() &&
         std::find(c.spacings.begin(), c.spacings.end(), Spacing::learned) != c.spacings.end();
}

LabeledProfile study_profile(const Brdf& brdf, const std::string& label, const StudyConfig& c) {
  // Computed in the BRDF's spaces, named by the parameterizations (a per-material warp's profile
  // is kept under its placeholder, as its rows are).
  DesignProfile p =
      design_profile(brdf, material_spaces(brdf, label, c.params), c.profile_grid, c.space);
  for (std::size_t k = 0; k < p.spaces.size(); ++k) p.spaces[k].space = c.params[k];
  return {label, std::move(p)};
}

// The label, then per space its name and one line of numbers per axis.
std::string profile_text(const LabeledProfile& p) {
  std::string text(kProfileMagic);
  text += "label = " + csv_text_field(p.label) + "\n";
  for (const AxisDemand& d : p.profile.spaces) {
    text += fmt::format("space = {}\n", name_of(d.space));
    for (const std::vector<double>& axis : d.demand) {
      for (std::size_t i = 0; i < axis.size(); ++i) {
        if (i) text += ',';
        text += format_csv_number(axis[i]);
      }
      text += '\n';
    }
  }
  return text;
}

LabeledProfile profile_from_text(std::string_view text, const std::string& source) {
  if (text.substr(0, kProfileMagic.size()) != kProfileMagic)
    throw std::runtime_error(source + ": not a profile of a halfback study");
  std::istringstream in{std::string(text.substr(kProfileMagic.size()))};
  std::string line;
  LabeledProfile p;
  if (!std::getline(in, line) || line.rfind("label = ", 0) != 0)
    throw std::runtime_error(source + ": no 'label' line");
  const auto label = split_csv_line(line.substr(8));
  if (label.size() != 1) throw std::runtime_error(source + ": a malformed label");
  p.label = label[0];
  while (std::getline(in, line)) {
    if (line.rfind("space = ", 0) != 0)
      throw std::runtime_error(fmt::format("{}: expected 'space = NAME', got '{}'", source, line));
    AxisDemand d;
    const auto space = space_from_name(line.substr(8));
    if (!space || space->is_dirs())
      throw std::runtime_error(fmt::format("{}: unknown space '{}'", source, line.substr(8)));
    d.space = *space;
    for (std::vector<double>& axis : d.demand) {
      if (!std::getline(in, line))
        throw std::runtime_error(source + ": the profile ends inside a space");
      axis = numbers_of<double>(line, source);
    }
    p.profile.spaces.push_back(std::move(d));
  }
  return p;
}

std::string learned_fingerprint(std::span<const LabeledProfile> profiles) {
  std::uint64_t h = fnv1a(std::to_string(profiles.size()));
  for (const LabeledProfile& p : profiles) h = fnv1a(profile_text(p), h);
  return fmt::format("{} profiles, {:016x}", profiles.size(), h);
}

void set_learned(StudyConfig& c, std::span<const LabeledProfile> profiles,
                 const std::string& label) {
  const auto it = std::find_if(profiles.begin(), profiles.end(),
                               [&](const LabeledProfile& p) { return p.label == label; });
  if (it == profiles.end())
    throw std::invalid_argument(fmt::format(
        "the learned design: no profile of '{}' among the profiles given (they must be those of "
        "every BRDF of the study, this one's included, so that it is left out)",
        label));
  std::vector<DesignProfile> plain;
  for (const LabeledProfile& p : profiles) plain.push_back(p.profile);
  c.learned.clear();
  if (profiles.size() > 1)
    c.learned = learn_warps(plain, std::size_t(std::distance(profiles.begin(), it)));
  c.learned_from = learned_fingerprint(profiles);
}

// ---------------------------------------------------------------------------------------------
// Tables
// ---------------------------------------------------------------------------------------------

namespace {

// The "brdf" table: what a result holds besides its metric tables.
constexpr std::string_view kBrdfHeader = "brdf,isotropic,seconds";

}  // namespace

StudyTables to_tables(const BrdfResult& b) {
  StudyTables t;
  t["brdf"] = fmt::format("{}\n{},{},{}\n", kBrdfHeader, csv_text_field(b.label), int(b.isotropic),
                          format_csv_number(b.seconds));
  for (const MetricTable& table : b.tables)
    t[table.name] = csv_header(table) + csv_rows(table, b.label, NumberText::exact);
  return t;
}

namespace {

// The label, isotropy and seconds of the "brdf" table.
void read_brdf_table(const StudyTables& t, const std::string& source, BrdfResult& b) {
  const auto it = t.find("brdf");
  if (it == t.end()) throw std::runtime_error(fmt::format("{}: no table 'brdf'", source));
  std::istringstream in(it->second);
  std::string header, line;
  std::getline(in, header);
  if (header != kBrdfHeader)
    throw std::runtime_error(
        fmt::format("{}: table brdf: the header is not '{}'", source, kBrdfHeader));
  std::vector<std::vector<std::string>> rows;
  while (std::getline(in, line))
    if (!line.empty()) rows.push_back(split_csv_line(line));
  if (rows.size() != 1 || rows[0].size() != 3)
    throw std::runtime_error(fmt::format("{}: table brdf: expected one row of 3 fields", source));
  b.label = rows[0][0];
  b.isotropic = rows[0][1] == "1";
  b.seconds = number_of<double>(rows[0][2], source + ": table brdf, line 2");
}

// Every row of `table` is of one of `params` and of the BRDF `label` (read_csv_rows' `brdf`).
void check_rows(const MetricTable& table, std::string_view brdf, const BrdfResult& b,
                const std::string& source) {
  if (!table.rows.empty() && brdf != b.label)
    throw std::runtime_error(fmt::format("{}: table {}: rows of '{}' in the tables of '{}'", source,
                                         table.name, brdf, b.label));
  for (const Row& row : table.rows) {
    const std::string& name = table.text(row, "parameterization");
    if (std::none_of(b.params.begin(), b.params.end(), [&](Space s) { return name_of(s) == name; }))
      throw std::runtime_error(
          fmt::format("{}: table {}: the parameterization '{}' is not one of the run's ({})",
                      source, table.name, name, joined(names_of(b.params))));
  }
}

}  // namespace

BrdfResult from_tables(const StudyTables& t, std::span<const Space> params,
                       const std::string& source) {
  BrdfResult b;
  read_brdf_table(t, source, b);
  b.params.assign(params.begin(), params.end());
  b.tables = stored_tables();
  for (MetricTable& table : b.tables) {
    const auto it = t.find(table.name);
    if (it == t.end())
      throw std::runtime_error(fmt::format("{}: no table '{}'", source, table.name));
    const std::string brdf = read_csv_rows(table, it->second, source);
    check_rows(table, brdf, b, source);
  }
  return b;
}

// ---------------------------------------------------------------------------------------------
// Part files
// ---------------------------------------------------------------------------------------------

namespace {

// Version 3: the parameterizations of the run in its settings, a rank column in the separability
// table (version 2 had the rank's index).
constexpr std::string_view kPartMagic = "# halfback study part 3\n";

// The example renderings side by side in one image (they share their size).
render::Image strip_of(const std::vector<render::Image>& images) {
  render::Image s;
  s.width = images.front().width * int(images.size());
  s.height = images.front().height;
  s.rgb.resize(std::size_t(s.width) * std::size_t(s.height) * 3);
  for (std::size_t k = 0; k < images.size(); ++k)
    for (int y = 0; y < s.height; ++y)
      std::copy_n(
          images[k].pixel(0, y), std::size_t(images[k].width) * 3,
          &s.rgb[3 * (std::size_t(y) * std::size_t(s.width) + k * std::size_t(images[k].width))]);
  return s;
}

std::vector<render::Image> images_of(const render::Image& strip, int size) {
  std::vector<render::Image> out;
  for (int x0 = 0; size > 0 && x0 + size <= strip.width; x0 += size) {
    render::Image im{size, strip.height, {}};
    for (int y = 0; y < strip.height; ++y)
      im.rgb.insert(im.rgb.end(), strip.pixel(x0, y), strip.pixel(x0, y) + std::size_t(size) * 3);
    out.push_back(std::move(im));
  }
  return out;
}

}  // namespace

std::filesystem::path parts_dir(const std::filesystem::path& out) {
  return out / "parts";
}

std::filesystem::path profiles_dir(const std::filesystem::path& out) {
  return out / "profiles";
}

std::string part_key(std::string_view spec) {
  std::string name(std::filesystem::path(spec).filename().string());
  if (name.empty()) name = std::string(spec);
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.') c = '_';
  if (name.size() > 60) name.resize(60);
  return fmt::format("{}-{:016x}", name, fnv1a(spec));
}

void write_part(const std::filesystem::path& parts, const std::string& key,
                const BrdfResult& result, std::size_t order) {
  if (!result.example_images.empty())
    render::write_exr(parts / (key + ".exr"), strip_of(result.example_images));
  std::string text(kPartMagic);
  text += fmt::format("order = {}\n", order);
  for (const auto& [name, table] : to_tables(result)) text += "[" + name + "]\n" + table;
  write_file_atomically(parts / (key + ".part"), text);
}

BrdfResult read_part(const std::filesystem::path& parts, const std::string& key,
                     std::span<const Space> params, std::size_t* order) {
  const std::filesystem::path file = parts / (key + ".part");
  const std::string text = read_text_file(file);
  const std::string source = file.string();
  if (text.rfind(kPartMagic, 0) != 0)
    throw std::runtime_error(source + ": not a part of a study by this version of halfback");
  std::istringstream in(text.substr(kPartMagic.size()));
  std::string line;
  std::getline(in, line);
  if (line.rfind("order = ", 0) != 0) throw std::runtime_error(source + ": no 'order' line");
  const auto at = number_of<std::size_t>(line.substr(8), source);
  if (order) *order = at;
  StudyTables tables;
  std::string* current = nullptr;
  while (std::getline(in, line)) {
    if (line.size() > 2 && line.front() == '[' && line.back() == ']')
      current = &tables[line.substr(1, line.size() - 2)];
    else if (current)
      *current += line + "\n";
    else
      throw std::runtime_error(source + ": a row before the first table");
  }
  BrdfResult b = from_tables(tables, params, source);
  const std::filesystem::path exr = parts / (key + ".exr");
  std::error_code ec;
  if (std::filesystem::exists(exr, ec)) {
    const render::Image strip = render::read_exr(exr);
    b.example_images = images_of(strip, strip.height);  // square renderings
  }
  return b;
}

void merge_into(MergedParts& into, const std::string& settings, const std::string& source,
                std::vector<BrdfResult> results) {
  if (into.settings.empty()) {
    into.config = config_from_description(settings, source);
    into.settings = settings;
  } else if (settings != into.settings) {
    const StudyConfig other = config_from_description(settings, source);
    const bool learned_only = [&] {
      StudyConfig a = into.config;
      a.learned_from = other.learned_from;
      return describe_config(a) == settings;
    }();
    throw std::runtime_error(fmt::format(
        "'{}' and '{}' were run with different settings{}", into.source_of.begin()->second, source,
        learned_only ? " (their learned designs come from different sets of BRDFs: run the "
                       "study over all of them, or pass every profile to study_brdf, or leave "
                       "out the learned spacing with --spacings own,angle,merl)"
                     : ""));
  }
  for (BrdfResult& b : results) {
    if (const auto [it, fresh] = into.source_of.emplace(b.label, source); !fresh)
      throw std::runtime_error(
          fmt::format("'{}' is in both '{}' and '{}'", b.label, it->second, source));
    into.results.push_back(std::move(b));
  }
}

MergedParts read_parts(const std::vector<std::filesystem::path>& dirs) {
  MergedParts merged;
  for (const std::filesystem::path& dir : dirs) {
    std::error_code ec;
    const std::filesystem::path parts =
        std::filesystem::exists(dir / "settings.txt", ec) ? dir : parts_dir(dir);
    const std::filesystem::path settings_file = parts / "settings.txt";
    if (!std::filesystem::exists(settings_file, ec))
      throw std::runtime_error(
          fmt::format("'{}': not the output of a study (no parts/settings.txt)", dir.string()));
    const std::string settings = read_text_file(settings_file);
    const StudyConfig config = config_from_description(settings, settings_file.string());
    std::vector<std::pair<std::size_t, BrdfResult>> in_dir;
    for (const auto& entry : std::filesystem::directory_iterator(parts)) {
      if (entry.path().extension() != ".part") continue;
      std::size_t order = 0;
      BrdfResult b = read_part(parts, entry.path().stem().string(), config.params, &order);
      in_dir.emplace_back(order, std::move(b));
    }
    if (in_dir.empty())
      throw std::runtime_error(fmt::format("'{}': no finished BRDF in it", dir.string()));
    std::stable_sort(in_dir.begin(), in_dir.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<BrdfResult> results;
    for (auto& [order, b] : in_dir) results.push_back(std::move(b));
    merge_into(merged, settings, dir.string(), std::move(results));
  }
  return merged;
}

}  // namespace halfback::study
