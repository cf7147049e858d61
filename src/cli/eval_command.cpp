// `halfback eval`: ρ(ωi, ωo) of any BRDF at the direction pairs of a CSV file.
//
// Input: the columns of `dirs` (wi_x,wi_y,wi_z,wo_x,wo_y,wo_z), as for `convert`. A direction that
// is not a unit vector or a field that is not a finite number is an error naming the line; a pair
// with a direction below the horizon is a legitimate query whose answer is 0. Output: r,g,b in
// sr⁻¹ (no cosine factor), one row per input row, %.17g.
#include <fmt/format.h>

#include <memory>
#include <string>
#include <vector>

#include "command.hpp"
#include "halfback/core/space.hpp"
#include "halfback/loader/load.hpp"

namespace halfback::cli {

namespace {

struct EvalOptions {
  std::string brdf, input = "-", output = "-";
};

// ρ at the pairs of one block, written as r,g,b rows.
void eval_block(const Brdf& brdf, const CsvTable& block, const std::string& source,
                const CsvSink& sink) {
  const std::size_t n = block.rows();
  const auto& c = block.columns;
  std::vector<DirPair<double>> pairs(n);
  for (std::size_t r = 0; r < n; ++r) {
    pairs[r] = {{c[0][r], c[1][r], c[2][r]}, {c[3][r], c[4][r], c[5][r]}};
    const PairStatus status = accept_pair(pairs[r]);  // near-unit directions normalized
    if (status == PairStatus::ok || status == PairStatus::wi_below_horizon ||
        status == PairStatus::wo_below_horizon)
      continue;
    throw std::runtime_error(CsvError::location(source, block.lines[r], "") +
                             std::string(describe(status)));
  }
  std::vector<Rgb> rho(n);
  brdf.eval_batch(pairs, rho);
  std::vector<std::vector<double>> rgb(3, std::vector<double>(n));
  for (std::size_t r = 0; r < n; ++r) {
    rgb[0][r] = rho[r].r;
    rgb[1][r] = rho[r].g;
    rgb[2][r] = rho[r].b;
  }
  const std::vector<std::span<const double>> columns{rgb[0], rgb[1], rgb[2]};
  write_csv_rows(columns, sink);
}

int run_eval(const EvalOptions& o) {
  Output out(o.output);
  const BrdfPtr brdf = brdf_argument(o.brdf, "--brdf");
  const std::unique_ptr<CsvStreamReader> reader = open_csv_input(o.input);
  reader->require_header(column_names(Form{Space::dirs, false}));
  // The header goes out with the first block (a bad row in a one-block input writes nothing).
  std::string header = csv_header_line(std::vector<std::string>{"r", "g", "b"});
  const CsvSink sink = [&](std::string_view text) {
    if (!header.empty()) {
      out.write(header);
      header.clear();
    }
    out.write(text);
  };
  CsvTable block;
  while (reader->read_block(block, kBlockRows)) eval_block(*brdf, block, reader->source(), sink);
  if (!header.empty()) out.write(header);
  out.commit();
  return kExitOk;
}

}  // namespace

Command register_eval(CLI::App& parent) {
  auto o = std::make_shared<EvalOptions>();
  CLI::App* app = parent.add_subcommand(
      "eval", "Evaluate a BRDF at direction pairs (CSV in: wi_x..wo_z; CSV out: r,g,b)");
  app->add_option("--brdf", o->brdf,
                  "BRDF SPEC: a MERL, RGL or ALTA file, or a model such as ggx:alpha=0.2 "
                  "('halfback models' lists them)")
      ->required();
  app->add_option("-i,--input", o->input, "Input CSV file; - for stdin (the default)")
      ->type_name("FILE");
  app->add_option("-o,--output", o->output,
                  "Output CSV file, replaced only on success; - for stdout (the default)")
      ->type_name("FILE");
  app->footer(
      "Input: a header row wi_x,wi_y,wi_z,wo_x,wo_y,wo_z, then one pair per row (wi: light,\n"
      "wo: view; unit vectors in the frame n = +z). Output: r,g,b = rho(wi, wo) in 1/sr without\n"
      "the cosine factor, %.17g. A pair with a direction below the horizon gives 0; a\n"
      "direction that is not a unit vector is an error naming the line.\n"
      "\n"
      "Example:\n"
      "  halfback eval --brdf ggx:alpha=0.2,f0=0.9 -i examples/pairs.csv");
  return {app, [o] { return run_eval(*o); }};
}

}  // namespace halfback::cli
