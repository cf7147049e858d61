// `halfback convert`: CSV in, CSV out, through the library's batch convert<double>().
//
// Steps: open the output (an AtomicFile: an unwritable destination fails before any work), read
// the header and check it against the columns of --from, then, a block of rows at a time
// (CsvStreamReader): read the rows, check direction pairs with check_pair(), convert, write. Memory
// is bounded by the block, whatever the input's length. A bad row fails the command: an output
// file is then left untouched (AtomicFile); standard output holds the blocks before the bad one
// (nothing when the input is a single block, up to 65536 rows). With --skip-invalid, rows with a
// problem are kept as valid = 0 rows (nan coordinates) and one warning on stderr counts them.
#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <memory>
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
  std::vector<Space> spaces{Space::dirs};
  for (Space s : parameterizations()) spaces.push_back(s);
  for (Space s : spaces) {
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

// The bad rows of the input so far: how many, and the message of the first.
struct BadRows {
  std::size_t count = 0;
  std::string first;
};

// Marks the rows of `block` to write as valid = 0: rows the reader kept as bad, and direction
// pairs that check_pair() rejects (an error without --skip-invalid).
std::vector<std::uint8_t> find_bad_rows(const CsvTable& block, Form from, bool skip_invalid,
                                        const std::string& source, BadRows& bad_rows) {
  const std::size_t n = block.rows();
  std::vector<std::uint8_t> bad(n, 0);
  std::size_t first_row = n;
  std::string first;
  if (!block.problems.empty()) {
    first_row = block.problems.front().row;
    first = block.problems.front().message;
  }
  for (const CsvRowProblem& p : block.problems) bad[p.row] = 1;
  bad_rows.count += block.problems.size();
  if (from.space == Space::dirs) {
    const auto& c = block.columns;
    for (std::size_t r = 0; r < n; ++r) {
      if (bad[r]) continue;
      const DirPair<double> pair{{c[0][r], c[1][r], c[2][r]}, {c[3][r], c[4][r], c[5][r]}};
      const PairStatus status = check_pair(pair);
      if (status == PairStatus::ok) continue;
      std::string message =
          CsvError::location(source, block.lines[r], "") + pair_problem(status, pair);
      if (!skip_invalid) throw std::runtime_error(message);
      bad[r] = 1;
      ++bad_rows.count;
      if (r < first_row) {
        first_row = r;
        first = std::move(message);
      }
    }
  }
  if (bad_rows.first.empty()) bad_rows.first = std::move(first);
  return bad;
}

// Converts one block and writes its rows: the columns of `to`, then valid and jacobian when asked.
void convert_block(const CsvTable& block, Form from, Form to, const ConvertOptions& o,
                   const std::string& source, const std::vector<std::uint8_t>& bad,
                   const CsvSink& sink) {
  const std::size_t n = block.rows();
  const std::size_t dim_in = dimension(from), dim_out = dimension(to);
  std::vector<ConstColumn<double>> in_cols(dim_in);
  for (std::size_t c = 0; c < dim_in; ++c) in_cols[c] = {block.columns[c].data(), 1};
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
        throw std::runtime_error(CsvError::location(source, block.lines[r], "") +
                                 "the direction pair was rejected by the conversion");
      continue;
    }
    valid[r] = 0;
    for (auto& v : values) v[r] = kNaN;
    if (o.jacobian) jacobian[r] = kNaN;
  }

  std::vector<std::span<const double>> columns(values.begin(), values.end());
  std::vector<double> valid_column;
  if (from.space != Space::dirs || o.skip_invalid) {
    valid_column.assign(valid.begin(), valid.end());
    columns.emplace_back(valid_column);
  }
  if (o.jacobian) columns.emplace_back(jacobian);
  write_csv_rows(columns, sink);
}

std::vector<std::string> output_header(Form from, Form to, const ConvertOptions& o) {
  std::vector<std::string> header;
  for (std::string_view name : column_names(to)) header.emplace_back(name);
  if (from.space != Space::dirs || o.skip_invalid) header.emplace_back("valid");
  if (o.jacobian) header.emplace_back("jacobian");
  return header;
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
  const std::unique_ptr<CsvStreamReader> reader = open_csv_input(o.input);
  reader->require_header(column_names(from), header_hint(reader->header(), from));
  CsvReadOptions read_options;
  read_options.keep_bad_rows = o.skip_invalid;

  // The header goes out with the first block, so that an input of one block with a bad row
  // leaves standard output empty, as it did when the whole input was read first.
  std::string header = csv_header_line(output_header(from, to, o));
  const CsvSink sink = [&](std::string_view text) {
    if (!header.empty()) {
      out.write(header);
      header.clear();
    }
    out.write(text);
  };
  BadRows bad_rows;
  CsvTable block;
  while (reader->read_block(block, kBlockRows, read_options)) {
    const auto bad = find_bad_rows(block, from, o.skip_invalid, reader->source(), bad_rows);
    convert_block(block, from, to, o, reader->source(), bad, sink);
  }
  if (!header.empty()) out.write(header);
  out.commit();

  if (bad_rows.count > 0)
    warn("convert", fmt::format("{} invalid input row{} written with valid = 0; the first: {}",
                                bad_rows.count, bad_rows.count == 1 ? "" : "s", bad_rows.first));
  return kExitOk;
}

// The columns of every form, from the registry (built-in and registered parameterizations), in
// columns as wide as the longest name and column list.
std::string columns_help() {
  std::vector<Space> spaces{Space::dirs};
  for (Space p : parameterizations()) spaces.push_back(p);
  std::size_t name_width = 0, columns_width = 0;
  for (Space space : spaces) {
    name_width = std::max(name_width, name_of(space).size());
    columns_width = std::max(columns_width, join(column_names({space, false})).size());
  }
  std::string s =
      "Columns of each form (the input header must list exactly these, in this order):\n";
  s += fmt::format("  {:<{}}  {:<{}}  {}\n", "form", name_width, "columns", columns_width,
                   "with --isotropic");
  for (Space space : spaces) {
    s += fmt::format("  {:<{}}  {:<{}}  {}\n", name_of(space), name_width,
                     join(column_names({space, false})), columns_width,
                     space == Space::dirs ? "(none)" : join(column_names({space, true})));
  }
  return s + "\n";
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
                "Isotropic (3-column) form for the side(s) that are not dirs: phi_h dropped and "
                "the second azimuth relative, the coordinates of the pair turned about the normal "
                "to phi_h = 0 (its canonical pose; isotropic to dirs gives that pose); an error "
                "with --from dirs --to dirs");
  app->add_flag("--jacobian", options->jacobian,
                "Append a jacobian column: J with dwi dwo = J dq, q the --to coordinates (the "
                "--from ones when --to is dirs; for an isotropic form, the measure of its 3 "
                "coordinates); nan on invalid rows; an error with --from dirs --to dirs");
  app->add_flag("--skip-invalid", options->skip_invalid,
                "Write bad input rows as valid = 0 rows of nan instead of failing, and count them "
                "in one warning");
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
      "(w_z >= 0, to within rounding); accepted directions are normalized (and put on the\n"
      "horizon if just below it) before conversion. A malformed row, a field that is not a\n"
      "finite number or a bad direction is an error naming the line; with --skip-invalid, a\n"
      "valid = 0 row.\n"
      "\n"
      "Examples:\n"
      "  halfback convert --from dirs --to hybrid -i pairs.csv -o hybrid.csv\n"
      "  halfback convert --from hybrid --to dirs --jacobian < hybrid.csv\n"
      "  halfback convert --from dirs --to halfdiff --isotropic --skip-invalid -i pairs.csv");
  return {app, [options] { return run_convert(*options); }};
}

}  // namespace halfback::cli
