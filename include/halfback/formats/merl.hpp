// MERL BRDF database files (Matusik, Pfister, Brand, McMillan 2003, "A Data-Driven Reflectance
// Model"): reader, evaluation and writer. docs/formats.md describes the format and the choices.
//
// A `.binary` file is three little-endian int32 dimensions (90, 90, 180) followed by three planar
// float64 blocks R, G, B of 90·90·180 values each, indexed [θh][θd][φd] (φd fastest). A stored
// value times the channel's scale (1/1500, 1.15/1500, 1.66/1500) is ρ in sr⁻¹. Bins:
//   θh: ⌊90·√(θh/(π/2))⌋   (non-linear: fine near the specular peak)
//   θd: ⌊θd/(π/2)·90⌋
//   φd: folded to [0, π) by reciprocity (φd and φd+π are the same configuration), ⌊φd/π·180⌋
// each clamped to its range. Negative values mark bins that were not measured.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "halfback/brdf/brdf.hpp"
#include "halfback/brdf/rho_bound.hpp"

namespace halfback {

namespace merl {
inline constexpr int kThetaH = 90, kThetaD = 90, kPhiD = 180;
inline constexpr std::size_t kBins = std::size_t(kThetaH) * kThetaD * kPhiD;  // per channel
inline constexpr std::size_t kHeaderBytes = 12;
inline constexpr std::size_t kFileBytes = kHeaderBytes + 3 * kBins * sizeof(double);  // 34992012
// The reference reader's scale factors, as the same double expressions.
inline constexpr std::array<double, 3> kScale{1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0};
// The largest ρ (sr⁻¹) a bin may hold: the bound on every BRDF's value (brdf/rho_bound.hpp). A
// perfect mirror averaged over MERL's smallest bin reaches about 2e6; a stored value far above that
// is a corrupt file or the wrong byte order, and would overflow every integral (albedo, renderings)
// to infinity.
inline constexpr double kMaxRho = halfback::kMaxRho;

// Flat index of a bin in one channel's block.
constexpr std::size_t bin(int th, int td, int pd) {
  return (std::size_t(th) * kThetaD + std::size_t(td)) * kPhiD + std::size_t(pd);
}

struct BinIndex {
  int theta_h, theta_d, phi_d;
};

// The reference reader's bin of a (θh, θd, φd) in radians, φd in (-π, π] or [0, 2π) (both fold to
// the same bin). NaN input is mapped to bin 0 (callers filter NaN first).
BinIndex bin_of(double theta_h, double theta_d, double phi_d);

// Bin of a direction pair: (θh, θd, φd) from the core's HalfDiff::forward (docs/formats.md,
// "MERL bins" on how this matches the reference's acos-based computation).
BinIndex bin_of(const DirPair<double>& pair);

// The coordinates of a bin's centre in the stored (non-linear) coordinates: θh = ((i+½)/90)²·π/2,
// θd = (j+½)/90·π/2, φd = (k+½)/180·π.
std::array<double, 3> bin_centre(int theta_h, int theta_d, int phi_d);

// The stored R, G, B of one bin side by side (and a pad): a lookup reads one 32-byte slot, which
// never straddles a cache line, instead of three values 11 MB apart (docs/performance.md).
struct alignas(32) BinValues {
  double rgb[4];
};
// Frees a table of kBins slots (allocated on 2 MB pages where the system allows: the random reads
// of a lookup then miss the TLB far less).
struct FreeBinTable {
  void operator()(BinValues* p) const;
};
}  // namespace merl

// The content of a MERL file.
struct MerlData {
  std::vector<double> values;  // 3·kBins stored values, channel blocks R, G, B (unscaled)
  std::array<std::size_t, 3> missing{};  // negative (unmeasured) values per channel
  std::string sha256;  // of the whole file, lowercase hex ("" when built in memory)
  std::optional<std::string> material;  // name when sha256 matches a published MERL material
};

// Reads and validates a MERL file: size exactly kFileBytes, dimensions 90 90 180, every value
// finite. Throws FormatError naming the file, the field and the problem. Negative values are
// accepted and counted (MerlData::missing). With `identify`, computes the file's SHA-256 (~0.1 s)
// and names the published material it matches, if any.
MerlData read_merl(const std::filesystem::path& path, bool identify = true);
// The same from bytes in memory; `name` stands for the file in messages.
MerlData parse_merl(std::span<const std::byte> bytes, std::string_view name, bool identify = true);

// The 100 published materials: name, SHA-256 (lowercase hex) and size, from
// src/io/merl_sha256.tsv (embedded at build time).
struct MerlMaterial {
  std::string_view name, sha256;
  std::uint64_t size;
};
std::span<const MerlMaterial> merl_materials();
const MerlMaterial* find_merl_material(std::string_view sha256_hex);

enum class MerlLookup {
  // The reference reader's bin (bit for bit: same indices, same scale factors) for measured bins.
  // An unmeasured bin is missing: NaN in its channel (the reference returns its negative stored
  // value times the scale; docs/formats.md, "Missing and negative measurements").
  nearest,
  // Trilinear between the 8 bin centres around the point in the stored coordinates (√θh index
  // space, θd, φd). φd wraps (0 ≡ π); θh and θd are clamped at their ends, which is the even
  // extension of ρ at θh = 0 and θd = 0. Unmeasured corners are skipped and the weights of the
  // others renormalized, per channel; when all 8 are unmeasured, the channel is missing (NaN).
  trilinear,
};

struct MerlOptions {
  MerlLookup lookup = MerlLookup::nearest;
};

class MerlBrdf final : public Brdf {
 public:
  // `label` names the BRDF ("merl:LABEL") when the data matches no published material.
  explicit MerlBrdf(MerlData data, MerlOptions options = {}, std::string label = "data");

  std::string name() const override;
  std::string description() const override;
  bool isotropic() const override { return true; }
  bool reciprocal() const override { return true; }
  // 0 when a direction is below the horizon (z < 0), NaN when the pair has a NaN or the lookup
  // finds only unmeasured bins (missing, per channel).
  Rgb eval(const DirPair<double>& pair) const override;
  // The same values, through the SIMD conversion of the batch engine (core/batch.hpp) with the
  // table reads prefetched, on all threads. A pair whose conversion lands within a few ulps of a
  // bin boundary may get the neighbouring bin (as eval() may against the reference reader).
  void eval_batch(std::span<const DirPair<double>> pairs, std::span<Rgb> out) const override;
  std::vector<Fact> facts() const override;

  // The value stored in a bin, times the channel scale (what the reference returns for it).
  Rgb bin_value(int theta_h, int theta_d, int phi_d) const;

  const MerlData& data() const { return data_; }
  const MerlOptions& options() const { return options_; }

 private:
  Rgb nearest(double theta_h, double theta_d, double phi_d) const;
  Rgb trilinear(double theta_h, double theta_d, double phi_d) const;
  // eval_batch over blocks [begin, end) of kBlock rows (merl.cpp).
  void nearest_blocks(std::span<const DirPair<double>> pairs, std::span<Rgb> out, std::size_t begin,
                      std::size_t end) const;
  void trilinear_blocks(std::span<const DirPair<double>> pairs, std::span<Rgb> out,
                        std::size_t begin, std::size_t end) const;

  MerlData data_;
  std::unique_ptr<merl::BinValues[], merl::FreeBinTable> bins_;  // data_.values, one slot a bin
  MerlOptions options_;
  std::string label_;
};

// Loads a MERL file as a BRDF; the name is "merl:MATERIAL" when the file is one of the published
// materials, else "merl:STEM" (the file name without extension).
std::shared_ptr<const MerlBrdf> load_merl(const std::filesystem::path& path,
                                          MerlOptions options = {});

// Where a bin's value is tabulated (at φh = 0: the canonical pose of the isotropic halfdiff
// form): its centre (merl::bin_centre) when that is a valid configuration; else a valid point of
// the bin (merl.cpp says which), so that every bin a valid pair can be looked up in has a value;
// nullopt for a bin that holds no valid pair.
std::optional<DirPair<double>> merl_bin_pair(int theta_h, int theta_d, int phi_d);

// Tabulates any BRDF at merl_bin_pair of every bin and writes a MERL file: value / scale per
// channel, so that reading it back gives ρ at those pairs up to the rounding of the division.
// Bins that hold no valid pair and non-finite values of ρ are written as -1 (unmeasured). Writes to
// a temporary file in the same directory and renames it into place, so that no partial file is left
// on error. Throws FormatError on I/O errors, std::invalid_argument for an anisotropic BRDF (a MERL
// file is isotropic; its φh = 0 slice would pass for the whole).
void write_merl(const std::filesystem::path& path, const Brdf& brdf);
// The same, tabulated in memory (the file's content as MerlData, without sha256).
MerlData tabulate_merl(const Brdf& brdf);
// Writes tabulated data (same atomic rename).
void write_merl(const std::filesystem::path& path, const MerlData& data);

}  // namespace halfback
