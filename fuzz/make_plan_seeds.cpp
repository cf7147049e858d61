// Seeds of plan_fuzz (fuzz/run.sh): the sidecars of small plans as `halfback plan` writes them
// (both grid designs, isotropic and full; the two stages of the sequential design and of Dupuy &
// Jakob's layout, the pilots that `plan --pilot` reads, with pilot values of every kind: measured,
// NaN for rows not measured, zero, negative), and the same with a field cut, of another kind, or a
// row_of_point that does not match. With a second folder BIG: sidecars above 1 MiB, one JSON line
// each (a reader once refused lines above 1 MiB, the sidecars of budgets above ~170 000), which
// run.sh runs once each without the fuzzing's length limit.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "halfback/acquire/acquisition.hpp"

namespace fs = std::filesystem;
using namespace halfback;

int main(int argc, char** argv) {
  if (argc != 2 && argc != 3) {
    std::cerr << "usage: make_plan_seeds DIR [BIG]\n";
    return 2;
  }
  const fs::path dir = argv[1];
  fs::create_directories(dir);
  int k = 0;
  const auto write = [&](const std::string& text) {
    std::ofstream(dir / ("seed" + std::to_string(k++) + ".json"), std::ios::binary) << text;
  };
  for (const bool iso : {true, false})
    for (const acquire::Design design : acquire::kDesigns) {
      acquire::GonioSetup s;
      s.space = space_of<HalfDiff>;
      s.isotropic = iso;
      s.design = design;
      s.budget = iso ? 60 : 200;
      s.max_theta_deg = 80;
      const std::string text = acquire::plan_sidecar(acquire::acquisition_plan(s), "p.csv");
      write(text);
      write(text.substr(0, text.size() / 2));  // cut
      std::string other = text;
      other.replace(other.find("\"budget\":"), 9, "\"budget\":\"");  // a string
      write(other);
      std::string rows = text;
      rows.replace(rows.find("\"row_of_point\":[") + 16, 1, "9");  // does not match
      write(rows);
    }
  // Dupuy & Jakob's two stages (the slices' sidecar holds the retro-reflection's values).
  const acquire::AcquisitionPlan retro = acquire::dupuy_jakob_pilot_plan(200);
  write(acquire::plan_sidecar(retro, "p.csv"));
  const std::vector<Rgb> values(retro.measured.size(), Rgb{0.1, 0.2, 0.3});
  write(acquire::plan_sidecar(acquire::dupuy_jakob_main_plan(retro, values), "p.csv"));
  // The sequential design's pilot (what `plan --pilot` reads) and its main stages from pilot
  // values of each kind; a pilot whose values cannot make a main stage gives no seed of its own.
  acquire::GonioSetup seq;
  seq.design = acquire::Design::sequential;
  seq.budget = 400;
  seq.max_theta_deg = 80;
  const acquire::AcquisitionPlan pilot = acquire::sequential_pilot_plan(seq);
  write(acquire::plan_sidecar(pilot, "p.csv"));
  const std::size_t rows = pilot.measured.size();
  std::vector<std::vector<Rgb>> kinds(4, std::vector<Rgb>(rows));
  for (std::size_t r = 0; r < rows; ++r) {
    const double v = 0.05 + 0.9 * double(r % 17) / 16.0;  // measured, varying
    kinds[0][r] = {v, v / 2, v / 3};
    kinds[1][r] = r % 3 ? kinds[0][r] : Rgb{NAN, NAN, NAN};  // some rows not measured
    kinds[2][r] = {0, 0, 0};
    kinds[3][r] = {-v, v, v};
  }
  for (const std::vector<Rgb>& v : kinds) {
    try {
      write(acquire::plan_sidecar(acquire::sequential_main_plan(pilot, v), "p.csv"));
    } catch (const std::invalid_argument&) {
    }
  }
  if (argc == 3) {
    const fs::path big = argv[2];
    fs::create_directories(big);
    const auto put = [&](const std::string& name, const std::string& text) {
      std::ofstream(big / name, std::ios::binary) << text;
    };
    // A real sidecar of 1.9 MB (budget 300 000: the fuzz target's reader refuses budgets above
    // 5000 after reading the JSON).
    acquire::GonioSetup large;
    large.budget = 300000;
    put("budget300000.json", acquire::plan_sidecar(acquire::acquisition_plan(large), "p.csv"));
    // A budget of 5000, made longer than 1 MiB by JSON's own whitespace, and by a long name.
    acquire::GonioSetup small;
    small.budget = 5000;
    const std::string text = acquire::plan_sidecar(acquire::acquisition_plan(small), "p.csv");
    const std::size_t mib = std::size_t(1) << 20;
    put("spaces.json", "{" + std::string(mib + 1, ' ') + text.substr(1));
    put("long-name.json", acquire::plan_sidecar(acquire::acquisition_plan(small),
                                                std::string(mib + 1, 'm') + ".csv"));
    // The same, cut one byte past 1 MiB (inside the run of spaces: JSON that ends early).
    put("spaces-cut.json", ("{" + std::string(mib + 1, ' ') + text.substr(1)).substr(0, mib + 1));
  }
  return 0;
}
