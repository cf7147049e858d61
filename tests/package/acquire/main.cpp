// Uses the installed acquisition layer alone: plans a measurement of a Lambertian BRDF written
// here, measures it at the plan's rows, reconstructs it and checks the value at one pair.
#include <halfback/acquire/acquisition.hpp>
#include <halfback/brdf/brdf.hpp>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

namespace {
// ρ = 0.5/π everywhere: the reconstruction of a constant must be that constant.
class Constant final : public halfback::Brdf {
 public:
  std::string name() const override { return "constant"; }
  std::string description() const override { return "a constant BRDF"; }
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return true; }
  halfback::Rgb eval(const halfback::DirPair<double>&) const override {
    const double v = 0.5 / std::numbers::pi;
    return {v, v, v};
  }
};
}  // namespace

int main() {
  using namespace halfback;
  acquire::PlanSettings settings;
  settings.budget = 2000;
  const acquire::AcquisitionPlan plan = acquire::acquisition_plan(acquire::plan_setup(settings));
  const Constant truth;
  std::vector<Rgb> values;
  for (const DirPair<double>& pair : plan.measured) values.push_back(truth.eval(pair));
  const acquire::GonioReconstruction brdf = acquire::reconstruct(plan, values, "constant");
  const DirPair<double> pair{{0.5, 0.0, 0.8660254037844386}, {-0.3, 0.4, 0.8660254037844386}};
  const double error = std::abs(brdf.eval(pair).r - 0.5 / std::numbers::pi);
  if (!(error < 1e-9)) {
    std::fprintf(stderr, "reconstruction of a constant is off by %g\n", error);
    return 1;
  }
  std::printf("acquire consumer: %zu rows measured, constant reconstructed\n",
              plan.measured.size());
  return 0;
}
