// The BRDF base (threaded batch evaluation, eval_at), the model registry, and load_brdf's format
// detection by content.
#include "halfback/loader/load.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <fstream>
#include <iterator>
#include <numbers>
#include <random>
#include <stdexcept>

#include "formats/rgl_synthetic.hpp"
#include "halfback/brdf/registry.hpp"
#include "halfback/core/batch.hpp"
#include "halfback/formats/alta.hpp"
#include "halfback/formats/merl.hpp"
#include "halfback/formats/rgl.hpp"
#include "halfback/models/analytic.hpp"
#include "loader/embedded.hpp"
#include "support/test_brdfs.hpp"
#include "support/test_support.hpp"

namespace halfback {
namespace {

using test::TempDir;

using test::Smooth;

class Throwing final : public Brdf {
 public:
  std::string name() const override { return "throwing"; }
  std::string description() const override { return ""; }
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return true; }
  Rgb eval(const DirPair<double>& p) const override {
    if (p.wi.x > 0.99) throw std::runtime_error("boom");
    return {};
  }
};

std::vector<DirPair<double>> random_pairs(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<DirPair<double>> v(n);
  for (auto& p : v) p = {test::uniform_hemisphere(rng), test::uniform_hemisphere(rng)};
  return v;
}

// --------------------------------------------------------------------------------------------
// Brdf base
// --------------------------------------------------------------------------------------------

TEST(BrdfBatch, MatchesPerPairOnAllThreads) {
  const Smooth b;
  for (std::size_t n : {0u, 1u, 100u, 1023u, 100000u}) {
    const auto pairs = random_pairs(n, n);
    std::vector<Rgb> out(n, Rgb{-1, -1, -1});
    b.calls = 0;
    b.eval_batch(pairs, out);
    EXPECT_EQ(b.calls.load(), static_cast<long>(n));
    for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(out[i], b.eval(pairs[i])) << i;
  }
  std::vector<Rgb> wrong(3);
  const auto pairs = random_pairs(4, 1);
  EXPECT_THROW(b.eval_batch(pairs, wrong), std::invalid_argument);
}

TEST(BrdfBatch, PropagatesExceptions) {
  const Throwing b;
  auto pairs = random_pairs(50000, 2);
  pairs[40000].wi = {1, 0, 0};
  std::vector<Rgb> out(pairs.size());
  EXPECT_THROW(b.eval_batch(pairs, out), std::runtime_error);
}

TEST(EvalAt, EveryFormAgreesWithDirections) {
  const Smooth b;
  const auto pairs = random_pairs(500, 3);
  for (Space space : kKernelSpaces) {
    for (bool iso : {false, true}) {
      const Form form{space, iso};
      for (const auto& p : pairs) {
        const double d[6] = {p.wi.x, p.wi.y, p.wi.z, p.wo.x, p.wo.y, p.wo.z};
        std::array<double, 4> q{};
        ASSERT_TRUE(convert_one<double>(Form{Space::dirs, false}, form, d,
                                        std::span<double>(q.data(), dimension(form))));
        const Rgb got = eval_at(b, form, std::span<const double>(q.data(), dimension(form)));
        // The isotropic forms stand for the canonical pose (rotated about n).
        DirPair<double> want_pair = p;
        if (iso) {
          std::array<double, 6> back{};
          ASSERT_TRUE(convert_one<double>(form, Form{Space::dirs, false},
                                          std::span<const double>(q.data(), 3), back));
          want_pair = {{back[0], back[1], back[2]}, {back[3], back[4], back[5]}};
        }
        const Rgb want = b.eval(want_pair);
        EXPECT_NEAR(got.r, want.r, 1e-9) << name_of(space) << (iso ? " iso" : "");
        EXPECT_NEAR(got.g, want.g, 1e-9);
      }
    }
  }
  // Dirs, as given.
  const auto& p = pairs[0];
  const double d[6] = {p.wi.x, p.wi.y, p.wi.z, p.wo.x, p.wo.y, p.wo.z};
  EXPECT_EQ(eval_at(b, Form{Space::dirs, false}, d), b.eval(p));
}

TEST(EvalAt, InvalidCoordinatesGiveNaN) {
  const Smooth b;
  const double out_of_domain[4] = {0.9, 0.0, 0.9, 0.0};  // ortho: ‖h̄‖ + ‖k̄‖ > 1
  EXPECT_TRUE(std::isnan(eval_at(b, Form{space_of<Ortho>, false}, out_of_domain).r));
  const double bad_angle[4] = {2.0, 0.0, 0.1, 0.0};  // halfdiff: θh > π/2
  EXPECT_TRUE(std::isnan(eval_at(b, Form{space_of<HalfDiff>, false}, bad_angle).g));
  const double not_unit[6] = {0, 0, 2, 0, 0, 1};
  EXPECT_TRUE(std::isnan(eval_at(b, Form{Space::dirs, false}, not_unit).b));
  const double below[6] = {0, 0, 1, 0.6, 0, -0.8};
  EXPECT_TRUE(std::isnan(eval_at(b, Form{Space::dirs, false}, below).r));
  const double three[3] = {0.1, 0.2, 0.3};
  EXPECT_THROW(eval_at(b, Form{space_of<HalfDiff>, false}, three), std::invalid_argument);
  EXPECT_THROW(eval_at(b, Form{Space::dirs, false}, three), std::invalid_argument);
}

// --------------------------------------------------------------------------------------------
// Registry
// --------------------------------------------------------------------------------------------

class Constant final : public Brdf {
 public:
  explicit Constant(Rgb v) : v_(v) {}
  std::string name() const override { return "constant"; }
  std::string description() const override { return "constant"; }
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return true; }
  Rgb eval(const DirPair<double>&) const override { return v_; }

 private:
  Rgb v_;
};

ModelInfo constant_model(std::string name = "test-constant") {
  return {std::move(name),
          "a constant BRDF (tests)",
          {{"value", "the value", 0.25, 0, 10}, {"blue", "blue channel", 1, 0, 2}},
          [](const ModelArgs& a) {
            return std::make_shared<Constant>(Rgb{a["value"], a["value"], a["blue"]});
          }};
}

TEST(Registry, CreateFromSpec) {
  ModelRegistry r;
  r.add(constant_model());
  EXPECT_EQ(r.names(), (std::vector<std::string>{"test-constant"}));
  ASSERT_NE(r.find("test-constant"), nullptr);
  EXPECT_EQ(r.find("test-constant")->params.size(), 2u);
  const DirPair<double> p{{0, 0, 1}, {0, 0, 1}};
  EXPECT_EQ(r.create("test-constant")->eval(p), (Rgb{0.25, 0.25, 1}));
  EXPECT_EQ(r.create("test-constant:value=2")->eval(p), (Rgb{2, 2, 1}));
  EXPECT_EQ(r.create("test-constant: blue = 0.5 ,value=1e-1")->eval(p), (Rgb{0.1, 0.1, 0.5}));
  EXPECT_TRUE(r.remove("test-constant"));
  EXPECT_FALSE(r.remove("test-constant"));
  EXPECT_EQ(r.find("test-constant"), nullptr);
}

void expect_invalid(const ModelRegistry& r, const std::string& spec,
                    std::initializer_list<std::string> parts) {
  try {
    r.create(spec);
    ADD_FAILURE() << "no error for " << spec;
  } catch (const std::invalid_argument& e) {
    for (const auto& part : parts)
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
          << "message: " << e.what() << "\nexpected: " << part;
  }
}

TEST(Registry, SpecErrors) {
  ModelRegistry r;
  expect_invalid(
      r, "ggx",
      {"'ggx'", "neither an existing file nor a known BRDF model", "no models are registered"});
  r.add(constant_model());
  r.add(constant_model("other"));
  expect_invalid(r, "nope:x=1", {"'nope:x=1'", "models: other, test-constant"});
  expect_invalid(r, "test-constant:alpha=1", {"no parameter 'alpha'", "parameters: value, blue"});
  // A bare value sets the first parameter, and must then be a number (or one of its choices).
  expect_invalid(r, "test-constant:value", {"'value' of 'value' is not a finite number"});
  expect_invalid(r, "test-constant:blue=1,0.5", {"'0.5' is not key=value"});
  expect_invalid(r, "test-constant:value=1,", {"empty parameter"});
  expect_invalid(r, "test-constant:value=abc", {"value 'abc' of 'value' is not a finite number"});
  expect_invalid(r, "test-constant:value=nan", {"not a finite number"});
  expect_invalid(r, "test-constant:value=", {"not a finite number"});
  expect_invalid(r, "test-constant:value=11", {"value=11 is outside [0, 10]"});
  expect_invalid(r, "test-constant:value=1,value=2", {"'value' given twice"});
}

TEST(Registry, AddValidation) {
  ModelRegistry r;
  r.add(constant_model());
  EXPECT_THROW(r.add(constant_model()), std::invalid_argument);  // duplicate
  EXPECT_THROW(r.add(constant_model("Bad Name")), std::invalid_argument);
  auto no_factory = constant_model("x");
  no_factory.factory = nullptr;
  EXPECT_THROW(r.add(no_factory), std::invalid_argument);
  auto bad_default = constant_model("y");
  bad_default.params[0].default_value = 20;
  EXPECT_THROW(r.add(bad_default), std::invalid_argument);
  auto dup_param = constant_model("z");
  dup_param.params.push_back(dup_param.params[0]);
  EXPECT_THROW(r.add(dup_param), std::invalid_argument);
  auto bad_param = constant_model("w");
  bad_param.params[0].name = "Value";
  EXPECT_THROW(r.add(bad_param), std::invalid_argument);
  ModelArgs args;
  EXPECT_THROW(args["missing"], std::out_of_range);
}

// --------------------------------------------------------------------------------------------
// load_brdf
// --------------------------------------------------------------------------------------------

void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

const std::string kAlta =
    "#DIM 3 1\n#PARAM_IN ISOTROPIC_TL_TV_PROJ_DPHI\n#PARAM_OUT INV_STERADIAN\n"
    "0.5 0 0 1\n0.5 0.1 0 1\n0.5 0 0.1 1\n";

// "merl-trilinear:FILE" reads a MERL file with the trilinear lookup: the nearest lookup's value
// at a bin centre, between centres a blend of its neighbours; anything but a MERL file refused.
TEST(LoadBrdf, MerlTrilinearSpec) {
  TempDir tmp;
  const BrdfPtr ggx = load_brdf("ggx:alpha=0.3,f0=0.5");
  write_merl(tmp / "g.binary", *ggx);
  const BrdfPtr nearest = load_brdf((tmp / "g.binary").string());
  const BrdfPtr trilinear = load_brdf("merl-trilinear:" + (tmp / "g.binary").string());
  EXPECT_NE(trilinear->description().find("trilinear"), std::string::npos);
  const DirPair<double> centre = *merl_bin_pair(40, 30, 45);
  EXPECT_NEAR(trilinear->eval(centre).g, nearest->eval(centre).g, 1e-12);
  // Between centres the trilinear value is nearer the model than the nearest bin's, on average.
  double err_nearest = 0, err_trilinear = 0;
  for (int k = 0; k < 200; ++k) {
    const double t = 0.2 + 0.005 * k, o = 0.3 + 0.004 * k;
    const DirPair<double> p{{std::sin(t), 0, std::cos(t)},
                            {-std::sin(o) * 0.8, std::sin(o) * 0.6, std::cos(o)}};
    const double truth = ggx->eval(p).g;
    err_nearest += std::abs(nearest->eval(p).g - truth);
    err_trilinear += std::abs(trilinear->eval(p).g - truth);
  }
  EXPECT_LT(err_trilinear, err_nearest);
  EXPECT_THROW(load_brdf("merl-trilinear:" + (tmp / "none.binary").string()),
               std::invalid_argument);
  write_text(tmp / "alta.txt", kAlta);
  EXPECT_THROW(load_brdf("merl-trilinear:" + (tmp / "alta.txt").string()), FormatError);
}

TEST(LoadBrdf, DetectsFormatsByContent) {
  TempDir tmp;
  // MERL content under a misleading extension.
  MerlData data;
  data.values.assign(3 * merl::kBins, 1500.0);
  write_merl(tmp / "merl.dat", data);
  // RGL content under a .binary name.
  const auto rgl = test::Synthetic{}.bytes();
  test::write_bytes(tmp / "rgl.binary", rgl.data(), rgl.size());
  // ALTA text under a .txt name.
  write_text(tmp / "alta.txt", "\n# comment\n" + kAlta);

  EXPECT_EQ(detect_brdf_format(tmp / "merl.dat"), BrdfFileFormat::merl);
  EXPECT_EQ(detect_brdf_format(tmp / "rgl.binary"), BrdfFileFormat::rgl);
  EXPECT_EQ(detect_brdf_format(tmp / "alta.txt"), BrdfFileFormat::alta);

  const BrdfPtr m = load_brdf((tmp / "merl.dat").string());
  EXPECT_EQ(m->name(), "merl:merl");
  EXPECT_NEAR(m->eval({{0, 0, 1}, {0, 0, 1}}).r, 1.0, 1e-15);
  EXPECT_EQ(load_brdf((tmp / "rgl.binary").string())->name(), "rgl:rgl");
  EXPECT_EQ(load_brdf((tmp / "alta.txt").string())->name(), "alta:alta");

  // The BRDF files of a directory, by content, sorted; other files and directories left out.
  write_text(tmp / "notes.txt", "not a BRDF\n");
  std::filesystem::create_directories(tmp / "sub");
  EXPECT_EQ(
      brdf_files_in(tmp.path()),
      (std::vector<std::filesystem::path>{tmp / "alta.txt", tmp / "merl.dat", tmp / "rgl.binary"}));
  EXPECT_EQ(brdf_files_in(tmp.path(), BrdfFileFormat::rgl),
            std::vector<std::filesystem::path>{tmp / "rgl.binary"});
  EXPECT_THROW(brdf_files_in(tmp / "missing"), FormatError);
}

TEST(LoadBrdf, ErrorsForFiles) {
  TempDir tmp;
  write_text(tmp / "junk.xyz", "hello world\n");
  EXPECT_FORMAT_ERROR(load_brdf((tmp / "junk.xyz").string()), "junk.xyz", "format",
                      "not a MERL .binary");
  // Unrecognized content: the extension picks the reader that explains the problem.
  write_text(tmp / "short.binary", std::string(100, 'x'));
  EXPECT_FORMAT_ERROR(load_brdf((tmp / "short.binary").string()), "short.binary",
                      "header dimension 1");
  write_text(tmp / "bad.bsdf", "not a tensor");
  EXPECT_FORMAT_ERROR(load_brdf((tmp / "bad.bsdf").string()), "bad.bsdf", "magic");
  write_text(tmp / "bad.dat", "1 2 3 4\n");
  EXPECT_FORMAT_ERROR(load_brdf((tmp / "bad.dat").string()), "bad.dat", "line 1",
                      "data before #DIM");
  // A recognized format with a content error.
  write_text(tmp / "broken.txt", kAlta + "0.5 0 0\n");
  EXPECT_FORMAT_ERROR(load_brdf((tmp / "broken.txt").string()), "broken.txt", "line 7",
                      "3 numbers, expected 4");
  // A folder is read as the NumPy form of a neural BRDF, which says what is missing.
  EXPECT_FORMAT_ERROR(load_brdf(tmp.path().string()), "folder", "holds no NAME_fc1.npy");
  // A file whose name contains '+' is that file, not a sum.
  write_text(tmp / "tape+lambert.dat", kAlta);
  EXPECT_NE(load_brdf((tmp / "tape+lambert.dat").string())->name().find("tape+lambert"),
            std::string::npos);
}

TEST(LoadBrdf, ModelSpecs) {
  ModelRegistry& global = model_registry();
  global.add(constant_model("test-load-constant"));
  const BrdfPtr b = load_brdf("test-load-constant:value=3");
  EXPECT_EQ(b->eval({{0, 0, 1}, {0, 0, 1}}), (Rgb{3, 3, 1}));
  try {
    load_brdf("/no/such/file.binary");
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("neither an existing file nor a known BRDF model"),
              std::string::npos);
    EXPECT_NE(std::string(e.what()).find("test-load-constant"), std::string::npos);
  }
  EXPECT_THROW(load_brdf(""), std::invalid_argument);
  EXPECT_TRUE(global.remove("test-load-constant"));
}

TEST(LoadBrdf, PublishedFiles) {
  HALFBACK_REQUIRE_SHARED(rgl, "rgl");
  HALFBACK_REQUIRE_SHARED(alta, "alta");
  EXPECT_EQ(load_brdf((rgl / "cardboard_rgb.bsdf").string())->name(), "rgl:cardboard_rgb");
  EXPECT_EQ(load_brdf((alta / "retro-3M-jaune.dat").string())->name(), "alta:retro-3M-jaune");
}

}  // namespace
}  // namespace halfback

// --- Built-in models, named choices, positional values, sums -----------------------------------
namespace halfback {
namespace {

TEST(BuiltinModels, GlobalRegistryKnowsTheAnalyticModelsAndTestFunctions) {
  for (const char* name : {"lambert", "ggx", "beckmann", "abc", "sheen", "test"})
    EXPECT_NE(model_registry().find(name), nullptr) << name;
}

TEST(BuiltinModels, TestFunctionByPositionalName) {
  const DirPair<double> p{{0.6, 0, 0.8}, {-0.6, 0, 0.8}};  // mirror pair: ‖h̄‖ = 0
  EXPECT_EQ(load_brdf("test:S")->eval(p).r, 1.0);          // S = 1 − ‖h̄‖
  EXPECT_NEAR(load_brdf("test:fn=G")->eval(p).g, 1 - 0.64, 1e-15);
  EXPECT_EQ(load_brdf("test")->name(), "test:S");  // default
  try {
    load_brdf("test:X");
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("fn=X is not one of: F, S, G"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(load_brdf("ggx:alpha=0.1,0.3"), std::invalid_argument);  // bare value not first
}

TEST(BuiltinModels, SumOfSpecs) {
  const DirPair<double> p{{0.3, 0.2, std::sqrt(0.87)}, {-0.5, 0.1, std::sqrt(0.74)}};
  const BrdfPtr sum = load_brdf("lambert:albedo=0.25+ggx:alpha=0.3,f0=0.5");
  const double expected =
      load_brdf("lambert:albedo=0.25")->eval(p).r + load_brdf("ggx:alpha=0.3,f0=0.5")->eval(p).r;
  EXPECT_NEAR(sum->eval(p).r, expected, 1e-15);
  EXPECT_EQ(sum->name(), "lambert+ggx");
  // An exponent's sign is not a separator.
  EXPECT_NO_THROW(load_brdf("abc:b=1e+3"));
  EXPECT_THROW(load_brdf("lambert+nosuchmodel"), std::invalid_argument);
  // An empty term is named as such (not as a model called '').
  for (const char* spec : {"+ggx", "ggx+", "lambert++ggx", "ggx+lambert+"}) {
    try {
      load_brdf(spec);
      ADD_FAILURE() << "no error for " << spec;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("a sum has an empty term"), std::string::npos)
          << spec << ": " << e.what();
    }
  }
}

// The assembler's .incbin (cmake/embed_files.cmake) put every file's exact bytes, 16-aligned.
TEST(Embedded, BytesAreTheFilesBytes) {
  const auto files = detail::embedded_files();
  ASSERT_EQ(files.size(), 6u);
  for (const detail::EmbeddedFile& f : files) {
    const bool rgl = f.name.find('-') == std::string_view::npos;
    const std::string path =
        std::string(HALFBACK_SOURCE_DIR) + (rgl ? "/data/rgl/" + std::string(f.name) + "_rgb.bsdf"
                                                : "/data/nbrdf/" + std::string(f.name) + ".h5");
    std::ifstream in(path, std::ios::binary);
    ASSERT_TRUE(in) << path;
    const std::vector<unsigned char> bytes{std::istreambuf_iterator<char>(in), {}};
    ASSERT_EQ(f.bytes.size(), bytes.size()) << f.name;
    EXPECT_TRUE(std::equal(bytes.begin(), bytes.end(), f.bytes.begin())) << f.name;
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(f.bytes.data()) % 16, 0u) << f.name;
  }
}

// The embedded materials are the files of data/rgl/ and data/nbrdf/ (same bytes, so the same
// values), and an unknown name lists the known ones.
TEST(Embedded, MaterialsAreTheDataFiles) {
  const auto names = embedded_material_names();
  ASSERT_EQ(names, (std::vector<std::string>{"ilm_l3_37_metallic", "colodur_azure_4e",
                                             "acrylic_felt_green", "gold-metallic-paint3",
                                             "colonial-maple-223", "pink-felt"}));
  const auto pairs = random_pairs(500, 17);
  for (std::size_t k = 0; k < names.size(); ++k) {
    const std::string& n = names[k];
    const bool rgl = k < 3;
    const BrdfPtr e = load_brdf("embedded:" + n);
    EXPECT_EQ(e->name(), rgl ? "rgl:" + n + "_rgb" : "nbrdf:" + n);
    const BrdfPtr f =
        load_brdf(std::string(HALFBACK_SOURCE_DIR) +
                  (rgl ? "/data/rgl/" + n + "_rgb.bsdf" : "/data/nbrdf/" + n + ".h5"));
    for (const auto& p : pairs) {
      const Rgb a = e->eval(p), b = f->eval(p);
      ASSERT_EQ(a, b) << n;
    }
    EXPECT_FALSE(e->facts().empty());
  }
  try {
    load_brdf("embedded:gold");
    FAIL() << "no error";
  } catch (const std::invalid_argument& ex) {
    EXPECT_NE(std::string(ex.what()).find("no such embedded material (embedded: "),
              std::string::npos)
        << ex.what();
    EXPECT_NE(std::string(ex.what()).find("acrylic_felt_green"), std::string::npos);
  }
}

}  // namespace
}  // namespace halfback

// --- docs/reliability/cli.md, "Model parameters are checked against their real ranges": no "not
// given" sentinel inside a range; every parameter checked ----------
namespace halfback {
namespace {

ModelInfo tinted_model() {
  return {"test-tinted",
          "a constant BRDF whose blue channel defaults to its grey value (tests)",
          {{"grey", "the value", 0.25, 0.1, 1}, defaults_to("blue", "blue channel", "grey", 0, 2)},
          [](const ModelArgs& a) {
            return std::make_shared<Constant>(Rgb{a["grey"], a["grey"], a["blue"]});
          }};
}

TEST(Registry, ParameterThatDefaultsToAnotherOne) {
  ModelRegistry r;
  r.add(tinted_model());
  const DirPair<double> p{{0, 0, 1}, {0, 0, 1}};
  EXPECT_EQ(r.create("test-tinted")->eval(p), (Rgb{0.25, 0.25, 0.25}));
  EXPECT_EQ(r.create("test-tinted:grey=0.5")->eval(p), (Rgb{0.5, 0.5, 0.5}));
  EXPECT_EQ(r.create("test-tinted:grey=0.5,blue=0")->eval(p), (Rgb{0.5, 0.5, 0}));
  // A negative value is out of range, not "not given".
  expect_invalid(r, "test-tinted:blue=-1", {"blue=-1 is outside [0, 2]"});
  expect_invalid(r, "test-tinted:blue=-0.3", {"blue=-0.3 is outside [0, 2]"});
}

TEST(Registry, DefaultFromIsCheckedWhenAdded) {
  ModelRegistry r;
  auto undeclared = tinted_model();
  undeclared.params[1].default_from = "green";
  EXPECT_THROW(r.add(undeclared), std::invalid_argument);
  auto declared_after = tinted_model();
  std::swap(declared_after.params[0], declared_after.params[1]);
  EXPECT_THROW(r.add(declared_after), std::invalid_argument);
  auto narrower = tinted_model();
  narrower.params[1].max = 0.5;  // grey's range [0.1, 1] would pass values out of [0, 0.5]
  try {
    r.add(narrower);
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("[0.1, 1] is not inside [0, 0.5]"), std::string::npos)
        << e.what();
  }
  auto chained = tinted_model();
  chained.params.push_back(defaults_to("red", "red", "blue", 0, 2));
  EXPECT_THROW(r.add(chained), std::invalid_argument);
  EXPECT_NO_THROW(r.add(tinted_model()));
}

// Values out of range, each once silently treated as "not given" (or let through).
TEST(BuiltinModels, EveryParameterIsCheckedAgainstItsRange) {
  const std::pair<const char*, const char*> cases[] = {
      {"lambert:albedo_r=-0.3", "albedo_r=-0.3 is outside [0, 1]"},
      {"lambert:albedo_g=-1", "albedo_g=-1 is outside [0, 1]"},
      {"ggx:f0_r=-0.5", "f0_r=-0.5 is outside [0, 1]"},
      {"ggx:alpha_x=-0.5", "alpha_x=-0.5 is outside [0.001, 10]"},
      {"ggx:alpha_y=0.0001", "alpha_y=0.0001 is outside [0.001, 10]"},
      {"beckmann:alpha_x=-1", "alpha_x=-1 is outside [0.001, 10]"},
      {"sheen:color_b=-1", "color_b=-1 is outside [0, 1]"},
  };
  for (const auto& [spec, message] : cases) {
    try {
      load_brdf(spec);
      ADD_FAILURE() << spec << " was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
}

TEST(BuiltinModels, ChannelsAndAxesDefaultToTheirParameter) {
  const auto ggx = [](const std::string& spec) {
    const BrdfPtr b = load_brdf(spec);
    const auto* m = dynamic_cast<const models::Microfacet*>(b.get());
    EXPECT_NE(m, nullptr) << spec;
    return m ? m->params() : models::MicrofacetParams{};
  };
  const models::MicrofacetParams a = ggx("ggx:alpha=0.3,f0=0.5,f0_g=0.25");
  EXPECT_EQ(a.alpha_x, 0.3);
  EXPECT_EQ(a.alpha_y, 0.3);
  EXPECT_EQ(a.fresnel.f0, (Rgb{0.5, 0.25, 0.5}));
  const models::MicrofacetParams b = ggx("ggx:alpha=0.3,alpha_y=0.001,f0_r=0");
  EXPECT_EQ(b.alpha_x, 0.3);
  EXPECT_EQ(b.alpha_y, 0.001);
  EXPECT_EQ(b.fresnel.f0, (Rgb{0, 0.04, 0.04}));
  const DirPair<double> n{{0, 0, 1}, {0, 0, 1}};
  EXPECT_NEAR(load_brdf("lambert:albedo=0.6,albedo_b=0")->eval(n).r, 0.6 / std::numbers::pi, 1e-15);
  EXPECT_EQ(load_brdf("lambert:albedo=0.6,albedo_b=0")->eval(n).b, 0.0);
}

}  // namespace
}  // namespace halfback
