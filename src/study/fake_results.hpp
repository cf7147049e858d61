// Made-up study results for the tests of the parts and the report: the numbers of each
// parameterization as typed records, turned into a BrdfResult's tables by the metrics' own
// functions (metric_tables.hpp), as study_brdf() does.
#pragma once

#include <string>
#include <vector>

#include "halfback/study/metric_tables.hpp"

namespace halfback::study::fakes {

// The four built-in parameterizations in the order of the default study.
inline std::vector<Space> builtin_params() {
  return {space_of<HalfDiff>, space_of<Ortho>, space_of<Hybrid>, space_of<Spherical>};
}

// One parameterization's numbers (dims 4: the anisotropic BRDFs' full form).
struct FakeParam {
  Space space = space_of<Hybrid>;
  double azimuthal = 0, azimuthal_4d = 0;
  std::vector<int> ranks{1, 2, 4, 8};
  std::vector<double> separability_2d, separability_3d, separability_4d;  // one per rank
  std::vector<GonioPoint> gonio, gonio_4d;
  std::vector<ImagePoint> images;
};

struct FakeBrdf {
  std::string label;
  bool isotropic = true;
  double seconds = 0;
  std::vector<FakeParam> params;
  std::vector<render::Image> example_images;
};

inline BrdfResult to_result(const FakeBrdf& f) {
  BrdfResult b;
  b.label = f.label;
  b.isotropic = f.isotropic;
  b.seconds = f.seconds;
  b.example_images = f.example_images;
  b.tables = stored_tables();
  auto table = [&](const char* name) -> MetricTable& {
    for (MetricTable& t : b.tables)
      if (t.name == name) return t;
    throw std::logic_error(name);
  };
  for (const FakeParam& p : f.params) {
    b.params.push_back(p.space);
    add_azimuthal(table("azimuthal"), p.space, p.azimuthal, 3);
    if (!f.isotropic) add_azimuthal(table("azimuthal"), p.space, p.azimuthal_4d, 4);
    add_separability(table("separability"), p.space, p.ranks, p.separability_2d, 2);
    add_separability(table("separability"), p.space, p.ranks, p.separability_3d, 3);
    if (!f.isotropic)
      add_separability(table("separability"), p.space, p.ranks, p.separability_4d, 4);
    for (const GonioPoint& g : p.gonio) add_gonio(table("gonio"), p.space, g, 3);
    for (const GonioPoint& g : p.gonio_4d) add_gonio(table("gonio"), p.space, g, 4);
    for (const ImagePoint& i : p.images) add_image(table("image"), p.space, i);
  }
  return b;
}

}  // namespace halfback::study::fakes
