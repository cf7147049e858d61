// The table files of brdf/resample.hpp's tables: .npy, .npz and .exr read back.
#include "halfback/formats/table_file.hpp"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

#include "halfback/brdf/test_functions.hpp"
#include "support/exr_offsets.hpp"
#include "support/test_brdfs.hpp"
#include "support/test_support.hpp"

namespace halfback {
namespace {

using test::Smooth;

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(TableFile, NpyHeaderAndData) {
  test::TempDir dir;
  const GridSpec g = default_grid(space_of<Hybrid>, GridKind::slice, {3, 5}, 0.5);
  const ResampledTable t = resample(Smooth(), g);
  write_table(dir.path() / "t.npy", t);
  const std::string b = slurp(dir.path() / "t.npy");
  ASSERT_GE(b.size(), 10u);
  EXPECT_EQ(b.substr(0, 8), std::string("\x93NUMPY\x01\x00", 8));
  const std::size_t header_len = std::size_t(std::uint8_t(b[8])) | std::size_t(std::uint8_t(b[9]))
                                                                       << 8;
  EXPECT_EQ((10 + header_len) % 64, 0u);
  const std::string header = b.substr(10, header_len);
  EXPECT_NE(header.find("'descr': '<f8'"), std::string::npos) << header;
  EXPECT_NE(header.find("'shape': (3, 5, 3)"), std::string::npos) << header;
  EXPECT_EQ(header.back(), '\n');
  ASSERT_EQ(b.size(), 10 + header_len + 8 * t.rgb.size());
  for (std::size_t i = 0; i < t.rgb.size(); ++i) {
    double v;
    std::memcpy(&v, b.data() + 10 + header_len + 8 * i, 8);
    if (std::isnan(t.rgb[i]))
      EXPECT_TRUE(std::isnan(v));
    else
      EXPECT_EQ(v, t.rgb[i]);
  }
}

TEST(TableFile, ExrChannelsAndAttributes) {
  test::TempDir dir;
  GridSpec g = default_grid(space_of<HalfDiff>, GridKind::isotropic, {4, 6, 8});
  g.axes[0].hi = 1.0;  // a custom range shows in the attributes
  const ResampledTable t = resample(Smooth(), g);
  const auto path = dir.path() / "t.exr";
  write_table(path, t);
  // A complete offset table: every chunk's offset, increasing, inside the file (it was all zeros
  // when the bytes were taken before the OpenEXR writer had finished).
  const std::string bytes = test::read_file(path);
  const std::vector<std::uint64_t> offsets = test::exr_scanline_offsets(bytes);
  ASSERT_EQ(offsets.size(), 2u) << "24 rows in ZIP chunks of 16 lines";
  EXPECT_GT(offsets[0], 0u);
  EXPECT_GT(offsets[1], offsets[0]);
  EXPECT_LT(offsets[1], bytes.size());
  Imf::InputFile in(path.c_str());
  const auto dw = in.header().dataWindow();
  const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
  ASSERT_EQ(w, 8);
  ASSERT_EQ(h, 24);
  for (const char* c : {"R", "G", "B", "valid"})
    EXPECT_NE(in.header().channels().findChannel(c), nullptr) << c;
  auto attr = [&](const char* name) {
    const auto* a = in.header().findTypedAttribute<Imf::StringAttribute>(name);
    return a ? a->value() : std::string("(missing)");
  };
  EXPECT_EQ(attr("halfback:parameterization"), "halfdiff");
  EXPECT_EQ(attr("halfback:kind"), "isotropic");
  EXPECT_EQ(attr("halfback:shape"), "4 6 8");
  EXPECT_EQ(attr("halfback:axis0"), "theta_h [0, 1] 4 centres");
  EXPECT_EQ(attr("halfback:brdf"), "smooth");
  EXPECT_NE(attr("halfback:metadata").find("\"axes\""), std::string::npos);
  std::vector<float> px(std::size_t(w) * h * 4);
  Imf::FrameBuffer fb;
  char* base = reinterpret_cast<char*>(px.data());
  const char* names[] = {"R", "G", "B", "valid"};
  for (int c = 0; c < 4; ++c)
    fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), 4 * sizeof(float),
                                   4 * sizeof(float) * w));
  in.setFrameBuffer(fb);
  in.readPixels(dw.min.y, dw.max.y);
  for (std::size_t p = 0; p < g.points(); ++p) {
    EXPECT_EQ(px[4 * p + 3], t.valid[p] ? 1.f : 0.f);
    if (t.valid[p]) {
      EXPECT_EQ(px[4 * p], float(t.rgb[3 * p]));
    }
  }
}

TEST(TableFile, BadNamesAndDestinations) {
  test::TempDir dir;
  const ResampledTable t = resample(Smooth(), default_grid(space_of<Hybrid>, GridKind::slice, {2}));
  EXPECT_THROW(write_table(dir.path() / "t.csv", t), std::invalid_argument);
  EXPECT_ANY_THROW(write_table(dir.path() / "missing" / "t.npz", t));
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "missing"));
  ResampledTable broken = t;
  broken.rgb.pop_back();
  EXPECT_THROW(write_table(dir.path() / "t.npz", broken), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "t.npz"));
}
}  // namespace
}  // namespace halfback
