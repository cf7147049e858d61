#include "batch_registered.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include "halfback/core/parallel.hpp"
#include "row_kernels.hpp"

namespace halfback::detail {

namespace {

constexpr std::size_t kBlockRows = 4096;

bool concurrent(Form f) {
  return f.space.is_dirs() || f.space.has_kernels() || f.space.param().concurrent();
}

// One block of rows: decoded into pairs, encoded, measured, written.
template <class T>
class Block {
 public:
  Block(Form from, Form to, std::size_t m) : from_(from), to_(to), m_(m) {
    qin_.resize(m * dimension(from));
    qout_.resize(m * dimension(to));
    pairs_.resize(m);
    valid_.resize(m);
  }

  void run(std::span<const ConstColumn<T>> in, std::size_t r0, const ConvertOutput<T>& out) {
    read(in, r0);
    decode();
    encode();
    std::vector<double> jac;
    if (out.jacobian.data) jac = measure();
    write(out, r0, jac);
  }

 private:
  static constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

  // The pair the conversions use (accepted_pair), in T's precision as convert_row takes it.
  static DirPair<double> accepted_in_precision(const DirPair<double>& p) {
    const DirPair<T> a = accepted_pair(
        DirPair<T>{{T(p.wi.x), T(p.wi.y), T(p.wi.z)}, {T(p.wo.x), T(p.wo.y), T(p.wo.z)}});
    return {{a.wi.x, a.wi.y, a.wi.z}, {a.wo.x, a.wo.y, a.wo.z}};
  }

  void read(std::span<const ConstColumn<T>> in, std::size_t r0) {
    const std::size_t d = in.size();
    for (std::size_t i = 0; i < m_; ++i)
      for (std::size_t c = 0; c < d; ++c)
        qin_[i * d + c] = double(in[c].data[std::ptrdiff_t(r0 + i) * in[c].stride]);
  }

  // Rows of `from` to direction pairs and their validity (NaN pairs where invalid).
  void decode() {
    const std::size_t d = dimension(from_);
    if (!from_.space.is_dirs() && !from_.space.has_kernels()) {
      wrap_azimuth_rows(from_.space.param().axes(from_.isotropic), qin_.data(), m_);
      from_.space.param().inverse_rows(from_.isotropic, qin_.data(), m_, pairs_.data(),
                                       valid_.data());
      return;
    }
    for (std::size_t i = 0; i < m_; ++i) {  // in T's precision, as the SIMD tables
      T q[kMaxDim], w[6];
      for (std::size_t c = 0; c < d; ++c) q[c] = T(qin_[i * d + c]);
      valid_[i] = convert_row<T>(from_, Form{Space::dirs}, q, w, nullptr) ? 1 : 0;
      pairs_[i] = {{w[0], w[1], w[2]}, {w[3], w[4], w[5]}};
    }
  }

  void encode() {
    const std::size_t d = dimension(to_);
    if (to_.space.is_dirs()) {
      for (std::size_t i = 0; i < m_; ++i) {
        const auto& p = pairs_[i];
        const double v[6] = {p.wi.x, p.wi.y, p.wi.z, p.wo.x, p.wo.y, p.wo.z};
        std::copy(v, v + 6, qout_.begin() + std::ptrdiff_t(6 * i));
      }
    } else if (to_.space.has_kernels()) {
      for (std::size_t i = 0; i < m_; ++i) {
        const auto& p = pairs_[i];
        const T w[6] = {T(p.wi.x), T(p.wi.y), T(p.wi.z), T(p.wo.x), T(p.wo.y), T(p.wo.z)};
        T q[kMaxDim];
        if (valid_[i]) valid_[i] = convert_row<T>(Form{Space::dirs}, to_, w, q, nullptr) ? 1 : 0;
        for (std::size_t c = 0; c < d; ++c) qout_[i * d + c] = valid_[i] ? double(q[c]) : kNan;
      }
    } else {
      for (auto& p : pairs_) p = accepted_in_precision(p);
      to_.space.param().forward_rows(to_.isotropic, pairs_.data(), m_, qout_.data());
      for (double& v : qout_) v = double(T(v));  // what the caller gets, and the measure sees
    }
    for (std::size_t i = 0; i < m_; ++i)
      if (!valid_[i]) std::fill_n(qout_.begin() + std::ptrdiff_t(i * d), d, kNan);
  }

  // The measure of the output coordinates, or of the input ones when `to` is dirs.
  std::vector<double> measure() const {
    std::vector<double> jac(m_, 1.0);
    const bool out_side = !to_.space.is_dirs();
    const Form side = out_side ? to_ : from_;
    const std::vector<double>& q = out_side ? qout_ : qin_;
    const std::size_t d = dimension(side);
    if (!side.space.is_dirs() && !side.space.has_kernels()) {
      side.space.param().jacobian_rows(side.isotropic, q.data(), m_, jac.data());
    } else if (!side.space.is_dirs()) {
      for (std::size_t i = 0; i < m_; ++i) {
        T qt[kMaxDim];
        for (std::size_t c = 0; c < d; ++c) qt[c] = T(q[i * d + c]);
        jac[i] = double(visit_kernel_param(side.space.kernel_index(), [&](auto p) {
          return jacobian_of<decltype(p)>(side.isotropic, qt);
        }));
      }
    }
    for (std::size_t i = 0; i < m_; ++i)
      if (!valid_[i]) jac[i] = kNan;
    return jac;
  }

  void write(const ConvertOutput<T>& out, std::size_t r0, const std::vector<double>& jac) const {
    const std::size_t d = out.columns.size();
    for (std::size_t i = 0; i < m_; ++i) {
      const auto r = std::ptrdiff_t(r0 + i);
      for (std::size_t c = 0; c < d; ++c)
        out.columns[c].data[r * out.columns[c].stride] = T(qout_[i * d + c]);
      if (!jac.empty()) out.jacobian.data[r * out.jacobian.stride] = T(jac[i]);
      if (out.valid) out.valid[r0 + i] = valid_[i];
    }
  }

  Form from_, to_;
  std::size_t m_;
  std::vector<double> qin_, qout_;
  std::vector<DirPair<double>> pairs_;
  std::vector<std::uint8_t> valid_;
};

}  // namespace

template <class T>
void convert_registered(Form from, Form to, std::span<const ConstColumn<T>> in, std::size_t n,
                        const ConvertOutput<T>& out, const BatchOptions& options) {
  const std::size_t blocks = (n + kBlockRows - 1) / kBlockRows;
  const int threads = concurrent(from) && concurrent(to) ? options.threads : 1;
  parallel_for(
      blocks, 1,
      [&](std::size_t b0, std::size_t b1) {
        for (std::size_t b = b0; b < b1; ++b) {
          const std::size_t r0 = b * kBlockRows, m = std::min(kBlockRows, n - r0);
          Block<T>(from, to, m).run(in, r0, out);
        }
      },
      threads);
}

template void convert_registered<float>(Form, Form, std::span<const ConstColumn<float>>,
                                        std::size_t, const ConvertOutput<float>&,
                                        const BatchOptions&);
template void convert_registered<double>(Form, Form, std::span<const ConstColumn<double>>,
                                         std::size_t, const ConvertOutput<double>&,
                                         const BatchOptions&);

}  // namespace halfback::detail
