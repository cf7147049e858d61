#include "halfback/study/dupuy_jakob_design.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "halfback/formats/rgl.hpp"

namespace halfback::study {

RglExportOptions DupuyJakobLayout::export_options(int threads) const {
  RglExportOptions o;
  o.theta_i = theta_i;
  o.resolution = resolution;
  o.vndf_resolution = ndf_nodes;
  o.threads = threads;
  return o;
}

DupuyJakobLayout dupuy_jakob_layout(std::size_t budget) {
  DupuyJakobLayout l;
  l.ndf_nodes = int(std::clamp<std::size_t>(budget / 16, 16, 128));
  const std::size_t smallest = std::size_t(l.ndf_nodes) + std::size_t(l.theta_i) * 4;
  if (budget < smallest)
    throw std::invalid_argument(
        fmt::format("Dupuy & Jakob's layout: a budget of {} measurements is below its smallest "
                    "({}: {} retro-reflection nodes and {} slices of 2 x 2)",
                    budget, smallest, l.ndf_nodes, l.theta_i));
  const double per_slice = double(budget - std::size_t(l.ndf_nodes)) / l.theta_i;
  l.resolution = std::min(512, int(std::floor(std::sqrt(per_slice))));
  while (l.measurements() > budget) --l.resolution;  // rounding of the square root
  return l;
}

std::shared_ptr<const Brdf> dupuy_jakob_acquisition(const Brdf& brdf,
                                                    const DupuyJakobLayout& layout, int threads) {
  const TensorFile file =
      parse_tensor_file(serialize_tensor_file(rgl_fields(brdf, layout.export_options(threads))),
                        "dupuy-jakob layout");
  return std::make_shared<RglBrdf>(file, fmt::format("dupuy-jakob:{}", brdf.name()));
}

}  // namespace halfback::study
