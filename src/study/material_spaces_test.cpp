// The study's per-material spaces (material_spaces.hpp): the placeholder "dupuy-jakob:per-material"
// replaced by each BRDF's own warp, once per BRDF, the other spaces untouched; an anisotropic BRDF
// and one with no NDF to recover get a warp too.
#include "material_spaces.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "halfback/core/parameterization.hpp"
#include "halfback/formats/adaptive_param.hpp"
#include "halfback/loader/load.hpp"

namespace halfback::study {
namespace {

Space placeholder() {
  register_brdf_parameterization_families();
  return *space_from_name(kPerMaterialWarp);
}

TEST(MaterialSpaces, ThePlaceholderBecomesEachBrdfsOwnWarpOnce) {
  const Space halfdiff = space_of<HalfDiff>, p = placeholder();
  const BrdfPtr glossy = load_brdf("ggx:alpha=0.2"), rough = load_brdf("ggx:alpha=0.6");
  const std::vector<Space> params{halfdiff, p};
  const std::vector<Space> a = material_spaces(*glossy, "glossy", params);
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a[0], halfdiff);
  EXPECT_NE(a[1], p);
  EXPECT_EQ(name_of(a[1]), "dupuy-jakob:ggx (glossy)");
  EXPECT_FALSE(is_per_material_placeholder(a[1].param()));
  EXPECT_EQ(material_spaces(*glossy, "glossy", params)[1], a[1]) << "registered once";
  const Space other = material_spaces(*rough, "rough", params)[1];
  EXPECT_NE(other, a[1]);
  // Their own warps: the same pair has other coordinates s.
  const DirPair<double> pair{{0.3, 0.1, 0.9486832980505138}, {-0.2, 0.4, 0.8944271909999159}};
  EXPECT_NE(a[1].param().forward(pair)[2], other.param().forward(pair)[2]);
  // The placeholder itself refuses to map.
  EXPECT_THROW(p.param().forward(pair), std::logic_error);
}

// A retro-reflection that is not finite (an ALTA file's gaps): the warp of a Lambertian surface.
class NoBackscatter final : public Brdf {
 public:
  std::string name() const override { return "no-backscatter"; }
  std::string description() const override { return "NaN where ωi = ωo"; }
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return true; }
  Rgb eval(const DirPair<double>& p) const override {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return p.wi.x == p.wo.x && p.wi.y == p.wo.y ? Rgb{nan, nan, nan} : Rgb{0.3, 0.3, 0.3};
  }
};

TEST(MaterialSpaces, EveryBrdfGetsAWarp) {
  const std::vector<Space> params{placeholder()};
  const Space none = material_spaces(NoBackscatter(), "none", params)[0];
  EXPECT_EQ(name_of(none), "dupuy-jakob:no-backscatter (none) [Lambertian warp]");
  const Space aniso =
      material_spaces(*load_brdf("ggx:alpha_x=0.1,alpha_y=0.4"), "aniso", params)[0];
  EXPECT_EQ(name_of(aniso), "dupuy-jakob:ggx (aniso)");
}

}  // namespace
}  // namespace halfback::study
