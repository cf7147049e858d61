// Uses the installed halfback: a conversion round trip, the batch API, and a BRDF evaluation.
#include <halfback/core/batch.hpp>
#include <halfback/core/param.hpp>
#include <halfback/loader/load.hpp>

#include <cmath>
#include <cstdio>
#include <numbers>

int main() {
  using namespace halfback;
  const DirPair<double> pair{{0.5, 0.0, std::sqrt(0.75)}, {-0.3, 0.4, std::sqrt(0.75)}};
  const Solved<double> back = inverse<Hybrid>(Hybrid::forward(pair));
  const double err = std::abs(back.pair.wi.x - pair.wi.x) + std::abs(back.pair.wo.y - pair.wo.y);
  const double in[6] = {pair.wi.x, pair.wi.y, pair.wi.z, pair.wo.x, pair.wo.y, pair.wo.z};
  double out[4];
  const bool ok = convert_one<double>({Space::dirs, false}, {space_of<Hybrid>, false}, in, out);
  const Rgb rho = load_brdf("lambert:albedo=0.5")->eval(pair);
  std::printf("round trip error %.3g, hbar %.17g, rho %.17g\n", err, out[0], rho.r);
  return err < 1e-12 && ok && std::abs(rho.r - 0.5 / std::numbers::pi) < 1e-15 ? 0 : 1;
}
