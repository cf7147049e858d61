// Uses the installed core alone: a pair in hybrid coordinates and back, one by one and batched.
#include <halfback/core/batch.hpp>
#include <halfback/core/param.hpp>

#include <cmath>
#include <cstdio>

int main() {
  using namespace halfback;
  const DirPair<double> pair{{0.5, 0.0, 0.8660254037844386}, {-0.3, 0.4, 0.8660254037844386}};
  const Solved<double> back = inverse<Hybrid>(Hybrid::forward(pair));
  const double error = std::abs(back.pair.wi.x - pair.wi.x) + std::abs(back.pair.wo.y - pair.wo.y);
  if (!back.in_domain || error > 1e-12) {
    std::fprintf(stderr, "round trip failed (%g)\n", error);
    return 1;
  }
  const double in[6] = {pair.wi.x, pair.wi.y, pair.wi.z, pair.wo.x, pair.wo.y, pair.wo.z};
  double out[4];
  if (!convert_one<double>({Space::dirs, false}, {space_of<Hybrid>, false}, in, out)) return 1;
  std::printf("core consumer: round trip ok, hbar %.17g\n", out[0]);
  return 0;
}
