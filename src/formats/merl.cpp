#include "halfback/formats/merl.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <new>
#include <numbers>
#include <stdexcept>
#include <system_error>

#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "binary_io.hpp"
#include "halfback/core/batch.hpp"
#include "halfback/core/parallel.hpp"
#include "halfback/core/param.hpp"
#include "halfback/util/atomic_file.hpp"
#include "halfback/util/bounded_read.hpp"
#include "halfback/util/format_error.hpp"
#include "halfback/util/sha256.hpp"
#include "merl_kernel.hpp"

namespace halfback {

namespace {

using io_detail::load_le;
using io_detail::store_le;

constexpr double kPi = std::numbers::pi;
constexpr std::array<int, 3> kDims{merl::kThetaH, merl::kThetaD, merl::kPhiD};
constexpr std::array<const char*, 3> kDimNames{"theta_h", "theta_d", "phi_d"};
constexpr std::array<const char*, 3> kChannelNames{"red", "green", "blue"};
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string bin_field(int c, std::size_t flat) {
  const std::size_t pd = flat % merl::kPhiD, td = (flat / merl::kPhiD) % merl::kThetaD,
                    th = flat / (std::size_t(merl::kPhiD) * merl::kThetaD);
  return std::string(kChannelNames[c]) + " value at bin (theta_h " + std::to_string(th) +
         ", theta_d " + std::to_string(td) + ", phi_d " + std::to_string(pd) + ")";
}

// Checks the 12-byte header and the total size. `head` holds at least min(size, 12) bytes.
void check_header(std::span<const std::byte> head, std::uintmax_t size, const std::string& name) {
  if (size < merl::kHeaderBytes)
    throw FormatError(name, "header",
                      "file is " + std::to_string(size) +
                          " bytes, too short for the 12-byte header (three int32 dimensions)");
  for (int i = 0; i < 3; ++i) {
    const auto dim = load_le<std::int32_t>(head.data() + 4 * i);
    if (dim != kDims[i])
      throw FormatError(name,
                        "header dimension " + std::to_string(i + 1) + " (" + kDimNames[i] + ")",
                        "is " + std::to_string(dim) + ", expected " + std::to_string(kDims[i]) +
                            " (not a MERL file, or a different resolution)");
  }
  require_declared_size(name, merl::kFileBytes, size, "12-byte header + 3 × 90·90·180 float64");
}

}  // namespace

namespace merl {

BinIndex bin_of(double theta_h, double theta_d, double phi_d) {
  return {merl_kernel::theta_h_index(theta_h), merl_kernel::theta_d_index(theta_d),
          merl_kernel::phi_d_index(phi_d)};
}

BinIndex bin_of(const DirPair<double>& pair) {
  const Tuple4<double> q = HalfDiff::forward(pair);
  return bin_of(q[0], q[2], q[3]);
}

std::array<double, 3> bin_centre(int theta_h, int theta_d, int phi_d) {
  const double u = (theta_h + 0.5) / kThetaH;
  return {u * u * (kPi / 2), (theta_d + 0.5) / kThetaD * (kPi / 2), (phi_d + 0.5) / kPhiD * kPi};
}

void FreeBinTable::operator()(BinValues* p) const {
  std::free(p);
}

}  // namespace merl

MerlData parse_merl(std::span<const std::byte> bytes, std::string_view name_view, bool identify) {
  const std::string name(name_view);
  check_header(bytes.first(std::min(bytes.size(), merl::kHeaderBytes)), bytes.size(), name);
  MerlData data;
  data.values.resize(3 * merl::kBins);
  const std::byte* p = bytes.data() + merl::kHeaderBytes;
  for (int c = 0; c < 3; ++c) {
    for (std::size_t i = 0; i < merl::kBins; ++i) {
      const double v = load_le<double>(p + 8 * (c * merl::kBins + i));
      if (!std::isfinite(v))
        throw FormatError(name, bin_field(c, i), std::isnan(v) ? "is NaN" : "is infinite");
      if (!rho_within_bound(v * merl::kScale[c]))
        throw FormatError(name, bin_field(c, i),
                          fmt::format("is {:g}: {} (a corrupt file, or big-endian values: MERL "
                                      "files are little-endian)",
                                      v, rho_above_bound(v * merl::kScale[c])));
      if (v < 0) ++data.missing[c];
      data.values[c * merl::kBins + i] = v;
    }
  }
  if (identify) {
    data.sha256 = sha256_hex(bytes);
    if (const MerlMaterial* m = find_merl_material(data.sha256))
      data.material = std::string(m->name);
  }
  return data;
}

MerlData read_merl(const std::filesystem::path& path, bool identify) {
  // The header and the size first: a file of the wrong size is refused without reading it.
  BoundedFile file(path);
  const std::vector<std::byte> head = file.head(merl::kHeaderBytes);
  check_header(head, file.size(), file.name());
  std::vector<std::byte> bytes = head;
  file.extend(bytes, merl::kFileBytes, "data");
  return parse_merl(bytes, file.name(), identify);
}

// ---------------------------------------------------------------------------------------------
// Evaluation
// ---------------------------------------------------------------------------------------------

namespace {

// The interleaved table (47 MB), on 2 MB pages when the kernel gives them: a random lookup then
// costs one cache miss and rarely a page walk (with 4 KB pages, nearly every lookup missed the
// TLB too). Linux's default (transparent huge pages on request, "madvise") needs the request.
std::unique_ptr<merl::BinValues[], merl::FreeBinTable> allocate_bin_table() {
  constexpr std::size_t kPage = std::size_t(2) << 20;
  const std::size_t bytes = (merl::kBins * sizeof(merl::BinValues) + kPage - 1) / kPage * kPage;
  void* p = std::aligned_alloc(kPage, bytes);
  if (!p) throw std::bad_alloc();
#if defined(MADV_HUGEPAGE)
  madvise(p, bytes, MADV_HUGEPAGE);  // advice only: a refusal leaves ordinary pages
#endif
  return std::unique_ptr<merl::BinValues[], merl::FreeBinTable>(static_cast<merl::BinValues*>(p));
}

}  // namespace

MerlBrdf::MerlBrdf(MerlData data, MerlOptions options, std::string label)
    : data_(std::move(data)), options_(options), label_(std::move(label)) {
  if (data_.values.size() != 3 * merl::kBins)
    throw std::invalid_argument("MerlBrdf: data has " + std::to_string(data_.values.size()) +
                                " values, expected " + std::to_string(3 * merl::kBins));
  bins_ = allocate_bin_table();
  for (std::size_t i = 0; i < merl::kBins; ++i)
    bins_[i] = {
        {data_.values[i], data_.values[i + merl::kBins], data_.values[i + 2 * merl::kBins], 0.0}};
}

std::string MerlBrdf::name() const {
  return "merl:" + (data_.material ? *data_.material : label_);
}

std::string MerlBrdf::description() const {
  std::string d = "MERL measured BRDF";
  if (data_.material) d += " '" + *data_.material + "' (identified by SHA-256)";
  d += options_.lookup == MerlLookup::nearest ? ", nearest-bin lookup" : ", trilinear lookup";
  const std::size_t missing = std::max({data_.missing[0], data_.missing[1], data_.missing[2]});
  if (missing > 0) d += ", " + std::to_string(missing) + " unmeasured bins";
  return d;
}

std::vector<Brdf::Fact> MerlBrdf::facts() const {
  std::vector<Fact> f;
  f.push_back({"format", "MERL .binary: 90 θh × 90 θd × 180 φd bins, RGB float64"});
  f.push_back({"lookup", options_.lookup == MerlLookup::nearest
                             ? "nearest bin (the reference reader's)"
                             : "trilinear in the stored coordinates"});
  f.push_back({"unmeasured bins", fmt::format("R {}, G {}, B {} of {}", data_.missing[0],
                                              data_.missing[1], data_.missing[2], merl::kBins)});
  std::array<double, 3> max{};
  for (int c = 0; c < 3; ++c)
    for (std::size_t i = 0; i < merl::kBins; ++i)
      max[c] = std::max(max[c], data_.values[c * merl::kBins + i] * merl::kScale[c]);
  f.push_back(
      {"max stored ρ", fmt::format("R {:.6g}, G {:.6g}, B {:.6g} sr⁻¹", max[0], max[1], max[2])});
  if (!data_.sha256.empty()) f.push_back({"sha256", data_.sha256});
  f.push_back({"MERL material", data_.material ? *data_.material + " (one of the 100 published)"
                                               : std::string("not one of the 100 published")});
  return f;
}

Rgb MerlBrdf::bin_value(int th, int td, int pd) const {
  const double* v = bins_[merl::bin(th, td, pd)].rgb;
  return {v[0] * merl::kScale[0], v[1] * merl::kScale[1], v[2] * merl::kScale[2]};
}

Rgb MerlBrdf::nearest(double theta_h, double theta_d, double phi_d) const {
  // An unmeasured bin (a negative stored value) is missing: NaN, never a negative ρ.
  return merl_kernel::bin_rgb(bins_[merl_kernel::nearest_bin(theta_h, theta_d, phi_d)]);
}

Rgb MerlBrdf::trilinear(double theta_h, double theta_d, double phi_d) const {
  return merl_kernel::blend(bins_.get(), merl_kernel::cell_of(theta_h, theta_d, phi_d));
}

Rgb MerlBrdf::eval(const DirPair<double>& pair) const {
  const double v[6] = {pair.wi.x, pair.wi.y, pair.wi.z, pair.wo.x, pair.wo.y, pair.wo.z};
  for (double x : v)
    if (std::isnan(x)) return {kNaN, kNaN, kNaN};
  if (pair.wi.z < 0 || pair.wo.z < 0) return {};
  const Tuple4<double> q = HalfDiff::forward(pair);
  return options_.lookup == MerlLookup::nearest ? nearest(q[0], q[2], q[3])
                                                : trilinear(q[0], q[2], q[3]);
}

namespace {

using merl_kernel::kBlock;
constexpr std::uint32_t kScalarRow = 0xffffffffu;  // a row left to eval()

// The isotropic halfdiff coordinates (θh, θd, φd) of a block's rows, and which rows go through
// eval().
struct Coordinates {
  alignas(64) double q[3][kBlock];
  alignas(64) std::uint8_t apart[kBlock];
};

// The coordinates by the SIMD conversion (the φh that the lookups do not use is not computed).
// Rows the conversion rejects (NaN, not unit) or below the horizon are left to eval(), which
// gives them its exact values (NaN or 0); so are pairs with ωi + ωo along the normal, whose φd the
// isotropic form sets to 0 (eval() keeps the full form's).
void convert_block(std::span<const DirPair<double>> pairs, Coordinates& c) {
  static_assert(sizeof(DirPair<double>) == 6 * sizeof(double), "pairs are rows of 6 doubles");
  const std::size_t m = pairs.size();
  const double* rows = &pairs[0].wi.x;
  const ConstColumn<double> in[6] = {{rows, 6},     {rows + 1, 6}, {rows + 2, 6},
                                     {rows + 3, 6}, {rows + 4, 6}, {rows + 5, 6}};
  alignas(64) std::uint8_t valid[kBlock];
  const Column<double> cols[3] = {{c.q[0], 1}, {c.q[1], 1}, {c.q[2], 1}};
  convert<double>(Form{Space::dirs}, Form{space_of<HalfDiff>, true}, in, m,
                  ConvertOutput<double>{cols, {}, valid}, BatchOptions{1});
  merl_kernel::rows_apart(rows, valid, m, c.apart);
}

// A block of the nearest-bin pipeline: its rows and their bins (kScalarRow: through eval()).
struct NearestBlock {
  std::size_t first = 0, m = 0;
  alignas(64) std::uint32_t bin[kBlock];
};

}  // namespace

// Blocks in a pipeline: a block's slots are prefetched row by row between the reads of the
// previous block's values.
void MerlBrdf::nearest_blocks(std::span<const DirPair<double>> pairs, std::span<Rgb> out,
                              std::size_t begin, std::size_t end) const {
  Coordinates c;
  NearestBlock stage[2];
  const NearestBlock* previous = nullptr;
  const merl::BinValues* table = bins_.get();
  auto finish = [&](const NearestBlock& t, std::size_t i) {
    const std::size_t row = t.first + i;
    out[row] = t.bin[i] == kScalarRow ? eval(pairs[row]) : merl_kernel::bin_rgb(table[t.bin[i]]);
  };
  for (std::size_t b = begin; b < end; ++b) {
    NearestBlock& t = stage[(b - begin) % 2];
    t.first = b * kBlock;
    t.m = std::min(kBlock, pairs.size() - t.first);
    convert_block(pairs.subspan(t.first, t.m), c);
    merl_kernel::nearest_bins(c.q[0], c.q[1], c.q[2], c.apart, t.m, kScalarRow, t.bin);
    const std::size_t mp = previous ? previous->m : 0;
    for (std::size_t i = 0; i < std::max(t.m, mp); ++i) {
      if (i < t.m && t.bin[i] != kScalarRow) __builtin_prefetch(table + t.bin[i]);
      if (i < mp) finish(*previous, i);
    }
    previous = &t;
  }
  if (previous)
    for (std::size_t i = 0; i < previous->m; ++i) finish(*previous, i);
}

// Block by block: the conversion, the cells, then the blends (merl_kernel::blend_rows prefetches
// its own corners a step ahead). Rows left to eval() get its values over the blend's. Not
// pipelined (the next block's conversion before this block's blends): that is no faster, as the
// prefetches wait for miss buffers and the out-of-order window cannot run the conversion under
// them (docs/performance.md, "Measured lookups", "Software pipelining").
void MerlBrdf::trilinear_blocks(std::span<const DirPair<double>> pairs, std::span<Rgb> out,
                                std::size_t begin, std::size_t end) const {
  Coordinates c;
  merl_kernel::Cells cells;
  for (std::size_t b = begin; b < end; ++b) {
    const std::size_t first = b * kBlock, m = std::min(kBlock, pairs.size() - first);
    convert_block(pairs.subspan(first, m), c);
    merl_kernel::cells(c.q[0], c.q[1], c.q[2], m, cells);  // in range even for NaN
    merl_kernel::blend_rows(bins_.get(), cells, 0, m, out.data() + first);
    for (std::size_t i = 0; i < m; ++i)
      if (c.apart[i]) out[first + i] = eval(pairs[first + i]);
  }
}

void MerlBrdf::eval_batch(std::span<const DirPair<double>> pairs, std::span<Rgb> out) const {
  if (out.size() != pairs.size())
    throw std::invalid_argument("MerlBrdf::eval_batch: " + std::to_string(pairs.size()) +
                                " pairs but " + std::to_string(out.size()) + " outputs");
  // Tasks of 4 blocks at most (1024 rows, 50-90 µs on a core: well above the cost of a task, and
  // fine enough that the last task leaves the other thread idle for a few percent of a 65536-row
  // batch at most, where tasks of 16 blocks leave it up to 12 %: docs/performance.md, "Measured
  // lookups"). Blocks start at multiples of kBlock whatever the split, as the batch engine's tiles
  // do.
  const std::size_t n = pairs.size(), blocks = (n + kBlock - 1) / kBlock;
  parallel_for(blocks, 4, [&](std::size_t begin, std::size_t end) {
    if (options_.lookup == MerlLookup::nearest)
      nearest_blocks(pairs, out, begin, end);
    else
      trilinear_blocks(pairs, out, begin, end);
  });
}

std::shared_ptr<const MerlBrdf> load_merl(const std::filesystem::path& path, MerlOptions options) {
  return std::make_shared<const MerlBrdf>(read_merl(path), options, path.stem().string());
}

// ---------------------------------------------------------------------------------------------
// Writer
// ---------------------------------------------------------------------------------------------

namespace {

std::optional<DirPair<double>> valid_pair(const std::array<double, 3>& q) {
  const Solved<double> s = inverse<HalfDiff>(Tuple4<double>{q[0], 0.0, q[1], q[2]});
  if (!s.in_domain) return std::nullopt;
  return s.pair;
}

}  // namespace

// The pair a bin's value is tabulated at: its centre where that is a valid configuration (both
// directions above the horizon); else, where some of the bin is valid, the point of its valid
// part midway between the bin's most valid corner and the horizon on the segment from that corner
// to the centre. Both directions are above the horizon where cos θh cos θd > sin θh sin θd
// |cos φd| (φh = 0), which is largest at the bin's smallest θh and θd and its φd nearest π/2: the
// bin holds valid pairs iff that corner is valid, and a valid pair of the bin is looked up in it.
// Bins with no valid pair give nullopt.
std::optional<DirPair<double>> merl_bin_pair(int th, int td, int pd) {
  const std::array<double, 3> centre = merl::bin_centre(th, td, pd);
  if (auto pair = valid_pair(centre)) return pair;
  const double u = double(th) / merl::kThetaH;
  const double phi_lo = double(pd) / merl::kPhiD * kPi, phi_hi = double(pd + 1) / merl::kPhiD * kPi;
  const std::array<double, 3> corner = {u * u * (kPi / 2), double(td) / merl::kThetaD * (kPi / 2),
                                        std::clamp(kPi / 2, phi_lo, phi_hi)};
  if (!valid_pair(corner)) return std::nullopt;
  auto at = [&](double t) {
    std::array<double, 3> q;
    for (int k = 0; k < 3; ++k) q[k] = corner[k] + t * (centre[k] - corner[k]);
    return q;
  };
  double valid = 0, invalid = 1;  // bisection for the horizon on the segment
  for (int i = 0; i < 48; ++i) {
    const double mid = 0.5 * (valid + invalid);
    (valid_pair(at(mid)) ? valid : invalid) = mid;
  }
  return valid_pair(at(0.5 * valid));
}

MerlData tabulate_merl(const Brdf& brdf) {
  // The φh = 0 slice of an anisotropic BRDF would be read back as the whole BRDF: refuse, as the
  // RGL writer does (docs/reliability/readers.md, "Missing and negative measurements").
  if (!brdf.isotropic())
    throw std::invalid_argument(brdf.name() +
                                " is anisotropic: a MERL file holds an isotropic BRDF only (its "
                                "φh = 0 slice would be read back as the whole BRDF)");
  MerlData data;
  data.values.assign(3 * merl::kBins, -1.0);
  constexpr std::size_t kSlab = std::size_t(merl::kThetaD) * merl::kPhiD;  // bins per θh index
  std::vector<DirPair<double>> pairs;
  std::vector<std::size_t> where;
  std::vector<Rgb> rho;
  pairs.reserve(kSlab);
  where.reserve(kSlab);
  for (int th = 0; th < merl::kThetaH; ++th) {
    pairs.clear();
    where.clear();
    for (int td = 0; td < merl::kThetaD; ++td) {
      for (int pd = 0; pd < merl::kPhiD; ++pd) {
        const std::optional<DirPair<double>> pair = merl_bin_pair(th, td, pd);
        if (!pair) continue;  // no valid pair is looked up in this bin: left unmeasured (-1)
        pairs.push_back(*pair);
        where.push_back(merl::bin(th, td, pd));
      }
    }
    rho.resize(pairs.size());
    brdf.eval_batch(pairs, rho);
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      const double v[3] = {rho[k].r, rho[k].g, rho[k].b};
      for (int ch = 0; ch < 3; ++ch) {
        if (!rho_within_bound(v[ch]))
          throw std::invalid_argument(
              fmt::format("{}: {}: a MERL file cannot hold it", brdf.name(),
                          rho_above_bound(v[ch], describe_halfdiff(pairs[k]))));
        const double stored = v[ch] / merl::kScale[ch];
        data.values[where[k] + ch * merl::kBins] = std::isfinite(stored) ? stored : -1.0;
      }
    }
  }
  for (int ch = 0; ch < 3; ++ch)
    data.missing[ch] = static_cast<std::size_t>(std::count_if(
        data.values.begin() + ch * merl::kBins, data.values.begin() + (ch + 1) * merl::kBins,
        [](double x) { return x < 0; }));
  return data;
}

void write_merl(const std::filesystem::path& path, const MerlData& data) {
  if (data.values.size() != 3 * merl::kBins)
    throw std::invalid_argument("write_merl: data has " + std::to_string(data.values.size()) +
                                " values, expected " + std::to_string(3 * merl::kBins));
  std::vector<std::byte> bytes(merl::kFileBytes);
  for (int i = 0; i < 3; ++i) store_le<std::int32_t>(bytes.data() + 4 * i, kDims[i]);
  for (std::size_t i = 0; i < data.values.size(); ++i)
    store_le<double>(bytes.data() + merl::kHeaderBytes + 8 * i, data.values[i]);
  try {
    AtomicFile file(path);  // temporary file + rename: no partial file on error
    file.write(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
    file.commit();
  } catch (const std::system_error& e) {
    throw FormatError(path.string(), "write", e.what());
  }
}

void write_merl(const std::filesystem::path& path, const Brdf& brdf) {
  write_merl(path, tabulate_merl(brdf));
}

// ---------------------------------------------------------------------------------------------
// Published materials
// ---------------------------------------------------------------------------------------------

namespace merl_table {
// Generated at build time from src/io/merl_sha256.tsv (cmake/embed_merl_table.cmake).
extern const MerlMaterial kMaterials[];
extern const std::size_t kMaterialCount;
}  // namespace merl_table

std::span<const MerlMaterial> merl_materials() {
  return {merl_table::kMaterials, merl_table::kMaterialCount};
}

const MerlMaterial* find_merl_material(std::string_view sha256_hex) {
  for (const MerlMaterial& m : merl_materials())
    if (m.sha256 == sha256_hex) return &m;
  return nullptr;
}

}  // namespace halfback
