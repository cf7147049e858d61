#include "halfback/acquire/dupuy_jakob_design.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <mutex>
#include <set>
#include <stdexcept>

#include "halfback/formats/rgl.hpp"

namespace halfback::acquire {

namespace {

// A BRDF known at some pairs only, the values measured there. At any other pair it either
// records the pair and answers `placeholder` (planning: the pairs the export asks for, in the
// order it asks) or refuses it (reconstructing: every pair read must have been measured).
class MeasuredPairs final : public Brdf {
 public:
  enum class Unknown { record, refuse };
  MeasuredPairs(Unknown unknown, Rgb placeholder = {})
      : unknown_(unknown), placeholder_(placeholder) {}

  void add(std::span<const DirPair<double>> pairs, std::span<const Rgb> values, const char* stage) {
    if (pairs.size() != values.size())
      throw std::invalid_argument(
          fmt::format("Dupuy & Jakob's layout: {} values for the {} pairs of {}", values.size(),
                      pairs.size(), stage));
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      if (!values[k].finite())
        throw std::invalid_argument(fmt::format(
            "Dupuy & Jakob's layout: the value of pair {} of {} is not finite (every pair of the "
            "layout must be measured)",
            k, stage));
      known_[key(pairs[k])] = values[k];
    }
  }
  const std::vector<DirPair<double>>& recorded() const { return recorded_; }

  std::string name() const override { return "measured"; }
  std::string description() const override { return "values measured in Dupuy & Jakob's layout"; }
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return false; }
  Rgb eval(const DirPair<double>& pair) const override {
    const auto k = key(pair);
    if (const auto it = known_.find(k); it != known_.end()) return it->second;
    if (unknown_ == Unknown::refuse)
      throw std::invalid_argument(
          "Dupuy & Jakob's layout: a pair the plan did not measure was read (a plan of another "
          "version of halfback?)");
    const std::lock_guard lock(mutex_);
    if (seen_.insert(k).second) recorded_.push_back(pair);
    return placeholder_;
  }

 private:
  // -0 and 0 compare equal: the same direction.
  using Key = std::array<double, 6>;
  static Key key(const DirPair<double>& p) {
    return {p.wi.x, p.wi.y, p.wi.z, p.wo.x, p.wo.y, p.wo.z};
  }
  Unknown unknown_;
  Rgb placeholder_;
  std::map<Key, Rgb> known_;
  mutable std::mutex mutex_;
  mutable std::set<Key> seen_;
  mutable std::vector<DirPair<double>> recorded_;
};

}  // namespace

RglExportOptions DupuyJakobLayout::export_options(int threads) const {
  RglExportOptions o;
  o.theta_i = theta_i;
  o.resolution = resolution;
  o.vndf_resolution = ndf_nodes;
  o.threads = threads;
  // An instrument measures ρ at points, at elevations it can choose before it knows the albedo.
  o.incidences = RglIncidences::sigma;
  o.tabulation = RglTabulation::point;
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
  return dupuy_jakob_material(rgl_fields(brdf, layout.export_options(threads)),
                              fmt::format("dupuy-jakob:{}", brdf.name()));
}

std::shared_ptr<const Brdf> dupuy_jakob_material(const std::vector<TensorFieldData>& fields,
                                                 const std::string& name) {
  return std::make_shared<RglBrdf>(
      parse_tensor_file(serialize_tensor_file(fields), "dupuy-jakob layout"), name);
}

// The pairs are those the export evaluates, recorded on one thread (in its order): the NDF's
// power iteration reads the retro-reflection only (any positive value records its pairs), and
// with the incidences evenly spaced in σ and the tables sampled at their nodes, the slices'
// pairs depend on the recovered distribution only, not on the values read there.
std::vector<DirPair<double>> dupuy_jakob_retro_pairs(const DupuyJakobLayout& layout) {
  const MeasuredPairs record(MeasuredPairs::Unknown::record, Rgb{1, 1, 1});
  (void)recover_ndf(record, layout.ndf_nodes, 1);
  return record.recorded();
}

std::vector<DirPair<double>> dupuy_jakob_slice_pairs(const DupuyJakobLayout& layout,
                                                     std::span<const Rgb> retro) {
  MeasuredPairs record(MeasuredPairs::Unknown::record);
  record.add(dupuy_jakob_retro_pairs(layout), retro, "the retro-reflection");
  (void)rgl_fields(record, layout.export_options(1));
  return record.recorded();
}

std::vector<TensorFieldData> dupuy_jakob_fields(const DupuyJakobLayout& layout,
                                                std::span<const Rgb> retro,
                                                std::span<const Rgb> slices, int threads) {
  MeasuredPairs measured(MeasuredPairs::Unknown::refuse);
  measured.add(dupuy_jakob_retro_pairs(layout), retro, "the retro-reflection");
  measured.add(dupuy_jakob_slice_pairs(layout, retro), slices, "the incidence slices");
  return rgl_fields(measured, layout.export_options(threads));
}

}  // namespace halfback::acquire
