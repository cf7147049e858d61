// Seeds of plan_fuzz (fuzz/run.sh): the sidecars of small plans as `halfback plan` writes them
// (both grid designs, isotropic and full; Dupuy & Jakob's two stages), and the same with a field cut, of another kind, or a
// row_of_point that does not match.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "halfback/acquire/acquisition.hpp"

namespace fs = std::filesystem;
using namespace halfback;

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: make_plan_seeds DIR\n";
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
  return 0;
}
