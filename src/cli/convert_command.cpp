// `halfback convert`: CSV in, CSV out, through the library's batch convert<double>().
//
// Steps: open the output (an AtomicFile: an unwritable destination fails before any work), read
// the whole input, check the header against the columns of --from, read every row (CsvReader),
// check direction pairs with check_pair(), convert all rows at once, then write. Every data
// problem is found before the first byte is written, so a bad input leaves stdout empty and an
// existing output file untouched. With --skip-invalid, rows with a problem are kept as valid = 0
// rows (nan coordinates) and one warning on stderr counts them.
#include <fmt/format.h>

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "command.hpp"
#include "halfback/core/batch.hpp"
#include "halfback/core/space.hpp"

namespace halfback::cli {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct ConvertOptions {
  std::string from, to;
  bool isotropic = false;
  bool jacobian = false;
  bool skip_invalid = false;
  std::string input = "-";
  std::string output = "-";
};

std::string join(std::span<const std::string_view> names) {
  std::string s;
  for (auto n : names) {
    if (!s.empty()) s += ',';
    s += n;
  }
  return s;
}

std::string form_option(Form form) {
  std::string s = fmt::format("--from {}", name_of(form.space));
  if (form.isotropic) s += " --isotropic";
  return s;
}

// A hint for a header that is not the expected one: the form it belongs to, or that it looks like
// data.
std::string header_hint(const std::vector<std::string>& found, Form expected) {
  auto matches = [&](Form f) {
    const auto names = column_names(f);
    if (names.size() != found.size()) return false;
    for (std::size_t i = 0; i < names.size(); ++i)
      if (names[i] != found[i]) return false;
    return true;
  };
  for (Space s : {Space::dirs, Space::spherical, Space::halfdiff, Space::ortho, Space::hybrid}) {
    for (bool iso : {false, true}) {
      if (iso && s == Space::dirs) continue;
      const Form f{s, iso};
      if (f == expected || !matches(f)) continue;
      std::string hint = fmt::format("these are the columns of '{}'", form_option(f));
      if (!iso && expected.isotropic && s != Space::dirs) hint += " (without --isotropic)";
      return hint;
    }
  }
  bool numbers = !found.empty();
  for (const auto& field : found) {
    double v;
    if (!parse_csv_number(field, v, true).empty()) numbers = false;
  }
  if (numbers) return "the first line looks like data: the input needs a header row";
  return {};
}

// The message for a direction pair that check_pair() rejects, with the offending quantity.
std::string pair_problem(PairStatus status, const DirPair<double>& p) {
  const auto norm_error = [](const Vec3<double>& w) {
    return w.x * w.x + w.y * w.y + w.z * w.z - 1;
  };
  switch (status) {
    case PairStatus::wi_not_unit:
      return fmt::format("{} (|wi|^2 - 1 = {:.1e})", describe(status), norm_error(p.wi));
    case PairStatus::wo_not_unit:
      return fmt::format("{} (|wo|^2 - 1 = {:.1e})", describe(status), norm_error(p.wo));
    case PairStatus::wi_below_horizon:
      return fmt::format("{}: wi_z = {:.3g}", describe(status), p.wi.z);
    case PairStatus::wo_below_horizon:
      return fmt::format("{}: wo_z = {:.3g}", describe(status), p.wo.z);
    default:
      return std::string(describe(status));
  }
}

int run_convert(const ConvertOptions& o) {
  const Space from_space = *space_from_name(o.from);  // (checked by the validator)
  const Space to_space = *space_from_name(o.to);
  if (from_space == Space::dirs && to_space == Space::dirs) {
    if (o.isotropic)
      throw UsageError("--isotropic needs a parameterization on one side (--from or --to)");
    if (o.jacobian)
      throw UsageError("--jacobian needs a parameterization on one side (--from or --to)");
  }
  const Form from{from_space, o.isotropic && from_space != Space::dirs};
  const Form to{to_space, o.isotropic && to_space != Space::dirs};

  Output out(o.output);
  const InputText input = read_input(o.input);
  CsvReader reader(input.text, input.name);
  reader.require_header(column_names(from), header_hint(reader.header(), from));
  CsvReadOptions read_options;
  read_options.keep_bad_rows = o.skip_invalid;
  const CsvTable table = reader.read_rows(read_options);
  const std::size_t n = table.rows();

  // Rows to force to valid = 0, and the first message about them.
  std::vector<std::uint8_t> bad(n, 0);
  std::size_t bad_count = table.problems.size();
  std::string first_problem = bad_count ? table.problems.front().message : std::string();
  std::size_t first_problem_row = bad_count ? table.problems.front().row : n;
  for (const CsvRowProblem& p : table.problems) bad[p.row] = 1;

  if (from.space == Space::dirs) {
    const auto& c = table.columns;
    for (std::size_t r = 0; r < n; ++r) {
      if (bad[r]) continue;
      const DirPair<double> pair{{c[0][r], c[1][r], c[2][r]}, {c[3][r], c[4][r], c[5][r]}};
      const PairStatus status = check_pair(pair);
      if (status == PairStatus::ok) continue;
      std::string message =
          CsvError::location(input.name, table.lines[r], "") + pair_problem(status, pair);
      if (!o.skip_invalid) throw std::runtime_error(message);
      bad[r] = 1;
      ++bad_count;
      if (r < first_problem_row) {
        first_problem_row = r;
        first_problem = std::move(message);
      }
    }
  }

  // Convert every row at once.
  const std::size_t dim_in = dimension(from), dim_out = dimension(to);
  std::vector<ConstColumn<double>> in_cols(dim_in);
  for (std::size_t c = 0; c < dim_in; ++c) in_cols[c] = {table.columns[c].data(), 1};
  std::vector<std::vector<double>> values(dim_out, std::vector<double>(n));
  std::vector<Column<double>> out_cols(dim_out);
  for (std::size_t c = 0; c < dim_out; ++c) out_cols[c] = {values[c].data(), 1};
  std::vector<double> jacobian(o.jacobian ? n : 0);
  std::vector<std::uint8_t> valid(n, 0);
  ConvertOutput<double> conv;
  conv.columns = out_cols;
  if (o.jacobian) conv.jacobian = {jacobian.data(), 1};
  conv.valid = valid.data();
  convert<double>(from, to, in_cols, n, conv);

  for (std::size_t r = 0; r < n; ++r) {
    if (!bad[r]) {
      // A pair that check_pair() accepts is valid for the conversion too (same tolerances).
      if (from.space == Space::dirs && !valid[r] && !o.skip_invalid)
        throw std::runtime_error(CsvError::location(input.name, table.lines[r], "") +
                                 "the direction pair was rejected by the conversion");
      continue;
    }
    valid[r] = 0;
    for (auto& v : values) v[r] = kNaN;
    if (o.jacobian) jacobian[r] = kNaN;
  }

  // The output table.
  std::vector<std::string> header;
  std::vector<std::span<const double>> columns;
  for (std::size_t c = 0; c < dim_out; ++c) {
    header.emplace_back(column_names(to)[c]);
    columns.emplace_back(values[c]);
  }
  std::vector<double> valid_column;
  if (from.space != Space::dirs || o.skip_invalid) {
    valid_column.assign(valid.begin(), valid.end());
    header.emplace_back("valid");
    columns.emplace_back(valid_column);
  }
  if (o.jacobian) {
    header.emplace_back("jacobian");
    columns.emplace_back(jacobian);
  }
  write_csv(header, columns, out.sink());
  out.commit();

  if (bad_count > 0)
    warn("convert", fmt::format("{} invalid input row{} written with valid = 0; the first: {}",
                                bad_count, bad_count == 1 ? "" : "s", first_problem));
  return kExitOk;
}

std::string columns_help() {
  std::string s =
      "Columns of each form (the input header must list exactly these, in this order):\n";
  for (Space space :
       {Space::dirs, Space::spherical, Space::halfdiff, Space::ortho, Space::hybrid}) {
    s += fmt::format("  {:<10} {}", name_of(space), join(column_names({space, false})));
    if (space != Space::dirs)
      s += fmt::format("{:<{}}isotropic: {}", "", 31 - join(column_names({space, false})).size(),
                       join(column_names({space, true})));
    s += '\n';
  }
  return s;
}

}  // namespace

Command register_convert(CLI::App& parent) {
  auto options = std::make_shared<ConvertOptions>();
  CLI::App* app = parent.add_subcommand(
      "convert", "Convert direction pairs or coordinate tuples between forms (CSV in and out)");
  app->add_option("--from", options->from, "Input form: " + space_names())
      ->required()
      ->type_name("NAME")
      ->check(space_name_validator());
  app->add_option("--to", options->to, "Output form: " + space_names())
      ->required()
      ->type_name("NAME")
      ->check(space_name_validator());
  app->add_flag("--isotropic", options->isotropic,
                "Isotropic (3-column) form for the side(s) that are not dirs");
  app->add_flag("--jacobian", options->jacobian, "Append a jacobian column");
  app->add_flag("--skip-invalid", options->skip_invalid,
                "Write bad input rows as valid = 0 rows instead of failing");
  app->add_option("-i,--input", options->input, "Input CSV file; - for stdin (the default)")
      ->type_name("FILE");
  app->add_option("-o,--output", options->output,
                  "Output CSV file, replaced only on success; - for stdout (the default)")
      ->type_name("FILE");
  app->footer(
      "Reads CSV (a header row, then one tuple per row) and writes CSV with full double\n"
      "precision (%.17g, nan where there is no value).\n"
      "\n" +
      columns_help() +
      "With --isotropic, phi_h is dropped and the second azimuth is relative (dphi = phi_o -\n"
      "phi_i, phi_d, or dphi = phi_k - phi_h): the coordinates of the pair rotated to phi_h = 0.\n"
      "\n"
      "Output: the columns of --to, then\n"
      "  valid     when --from is not dirs (or with --skip-invalid): 1, or 0 for a tuple\n"
      "            outside the domain (or a bad row), whose output values are nan\n"
      "  jacobian  with --jacobian: J with dwi dwo = J dq, q the --to coordinates (the\n"
      "            --from ones when --to is dirs); for isotropic forms, the measure of q\n"
      "\n"
      "Input directions must be unit vectors (| |w|^2 - 1 | <= 1e-6) above the horizon\n"
      "(w_z >= 0, to within rounding). A malformed row, a field that is not a finite number or a\n"
      "bad direction is an error naming the line; with --skip-invalid, a valid = 0 row.\n"
      "\n"
      "Examples:\n"
      "  halfback convert --from dirs --to hybrid -i pairs.csv -o hybrid.csv\n"
      "  halfback convert --from hybrid --to dirs --jacobian < hybrid.csv\n"
      "  halfback convert --from dirs --to halfdiff --isotropic --skip-invalid -i pairs.csv");
  return {app, [options] { return run_convert(*options); }};
}

}  // namespace halfback::cli
