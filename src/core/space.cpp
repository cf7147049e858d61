#include "halfback/core/space.hpp"

#include "halfback/core/parameterization.hpp"
#include "row_kernels.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <mutex>

namespace halfback {

// ---------------------------------------------------------------------------------------------
// ParamDescriptor
// ---------------------------------------------------------------------------------------------
ParamDescriptor::ParamDescriptor(const Names& n)
    : name_(keep(n.name)),
      summary_(keep(n.summary)),
      axes_(n.axes),
      iso_axes_(n.iso_axes),
      chart_(n.chart),
      studied_by_default_(n.studied_by_default) {
  for (std::size_t i = 0; i < axes_.size(); ++i) {
    axes_[i].column = columns_[i] = keep(axes_[i].column);
    axes_[i].label = keep(axes_[i].label);
  }
  for (std::size_t i = 0; i < iso_axes_.size(); ++i) {
    iso_axes_[i].column = iso_columns_[i] = keep(iso_axes_[i].column);
    iso_axes_[i].label = keep(iso_axes_[i].label);
  }
}

std::string_view ParamDescriptor::keep(std::string_view s) {
  return strings_.emplace_back(s);
}

void ParamDescriptor::forward_rows(bool isotropic, const DirPair<double>* pairs, std::size_t m,
                                   double* coords) const {
  for (std::size_t i = 0; i < m; ++i) {
    if (isotropic) {
      const Tuple3<double> q = forward_iso(pairs[i]);
      std::copy(q.begin(), q.end(), coords + 3 * i);
    } else {
      const Tuple4<double> q = forward(pairs[i]);
      std::copy(q.begin(), q.end(), coords + 4 * i);
    }
  }
}

DirPair<double> mirror_pair(const DirPair<double>& p) {
  const double hx = p.wi.x + p.wo.x, hy = p.wi.y + p.wo.y;
  const double a = (hx == 0 && hy == 0) ? 0 : std::atan2(hy, hx);
  const double c = std::cos(2 * a), s = std::sin(2 * a);
  auto m = [&](const Vec3<double>& v) {
    return Vec3<double>{c * v.x + s * v.y, s * v.x - c * v.y, v.z};
  };
  return {m(p.wi), m(p.wo)};
}

void wrap_azimuth_rows(std::span<const Axis> axes, double* coords, std::size_t m) {
  const std::size_t d = axes.size();
  for (std::size_t c = 0; c < d; ++c)
    if (axes[c].kind == AxisKind::azimuth)
      for (std::size_t i = 0; i < m; ++i)
        coords[i * d + c] = detail::wrap_azimuth(coords[i * d + c]);
}

void ParamDescriptor::inverse_rows(bool isotropic, const double* coords, std::size_t m,
                                   DirPair<double>* pairs, std::uint8_t* in_domain) const {
  for (std::size_t i = 0; i < m; ++i) {
    const double* q = coords + (isotropic ? 3 : 4) * i;
    const Solved<double> s =
        isotropic ? inverse_iso({q[0], q[1], q[2]}) : inverse({q[0], q[1], q[2], q[3]});
    pairs[i] = s.pair;
    in_domain[i] = s.in_domain ? 1 : 0;
  }
}

void ParamDescriptor::jacobian_rows(bool isotropic, const double* coords, std::size_t m,
                                    double* jacobian) const {
  for (std::size_t i = 0; i < m; ++i) {
    const double* q = coords + (isotropic ? 3 : 4) * i;
    jacobian[i] =
        isotropic ? jacobian_iso({q[0], q[1], q[2]}) : this->jacobian({q[0], q[1], q[2], q[3]});
  }
}

// ---------------------------------------------------------------------------------------------
// The registry: the built-in list, then the registered parameterizations. Entries are never
// removed, so a reader holding a Space may use its descriptor without a lock once it is published.
// ---------------------------------------------------------------------------------------------
namespace {

constexpr std::size_t kMaxSpaces = 1024;

struct Registry {
  std::mutex mutex;  // serializes registrations
  std::array<std::shared_ptr<const ParamDescriptor>, kMaxSpaces> slots;
  std::atomic<std::size_t> count{0};  // published slots (ids 1 .. count)

  Registry() {
    std::size_t i = 0;
    auto add = [&]<class P, std::size_t I>() { slots[i++] = std::make_shared<CompiledParam<P>>(); };
    for_each_param(KernelParams{}, add);
    for_each_param(PortableParams{}, add);
    count.store(i, std::memory_order_release);
  }
  const ParamDescriptor* find(Space s) const {
    if (s.is_dirs() || s.id() > count.load(std::memory_order_acquire)) return nullptr;
    return slots[s.id() - 1].get();
  }
};

Registry& registry() {
  static Registry r;
  return r;
}

constexpr std::array<std::string_view, 6> kDirColumns{"wi_x", "wi_y", "wi_z",
                                                      "wo_x", "wo_y", "wo_z"};

}  // namespace

const ParamDescriptor& Space::param() const {
  if (const ParamDescriptor* d = registry().find(*this)) return *d;
  if (is_dirs())
    throw std::invalid_argument("dirs is not a parameterization (expected " +
                                parameterization_names() + ")");
  throw std::invalid_argument("no parameterization has the id " + std::to_string(id_));
}

std::vector<Space> parameterizations() {
  const std::size_t n = registry().count.load(std::memory_order_acquire);
  std::vector<Space> all;
  for (std::size_t i = 1; i <= n; ++i) all.push_back(Space::from_id(std::uint16_t(i)));
  return all;
}

Space register_parameterization(std::shared_ptr<const ParamDescriptor> descriptor) {
  if (!descriptor) throw std::invalid_argument("register_parameterization: no descriptor");
  const std::string_view name = descriptor->name();
  if (name.empty() || name == "dirs")
    throw std::invalid_argument("a parameterization cannot be named '" + std::string(name) + "'");
  for (Space s : kBuiltinSpaces)
    if (s.param().name() == name)
      throw std::invalid_argument("'" + std::string(name) +
                                  "' is a built-in parameterization: choose another name");
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  const std::size_t n = r.count.load(std::memory_order_relaxed);
  if (n >= kMaxSpaces)
    throw std::length_error("register_parameterization: more than " +
                            std::to_string(kMaxSpaces - 1) + " parameterizations");
  r.slots[n] = std::move(descriptor);
  r.count.store(n + 1, std::memory_order_release);
  return Space::from_id(std::uint16_t(n + 1));
}

std::string_view name_of(Space space) {
  if (space.is_dirs()) return "dirs";
  if (const ParamDescriptor* d = registry().find(space)) return d->name();
  return "unknown";
}

namespace {

struct Family {
  std::string usage;
  ParamFactory make;
};

struct Families {
  std::mutex mutex;  // also serializes the building of members (one registration per name)
  std::map<std::string, Family, std::less<>> by_prefix;
};

Families& families() {
  static Families f;
  return f;
}

std::optional<Space> registered_space(std::string_view name) {
  const std::vector<Space> all = parameterizations();
  for (auto it = all.rbegin(); it != all.rend(); ++it)  // the newest of a registered name
    if (it->param().name() == name) return *it;
  return std::nullopt;
}

}  // namespace

void register_parameterization_family(std::string prefix, std::string usage, ParamFactory make) {
  if (prefix.empty() || prefix.find(':') != std::string::npos || !make)
    throw std::invalid_argument(
        "register_parameterization_family: a prefix without ':' and a factory are needed");
  Families& f = families();
  std::lock_guard lock(f.mutex);
  f.by_prefix[std::move(prefix)] = Family{std::move(usage), std::move(make)};
}

std::vector<std::string> parameterization_families() {
  Families& f = families();
  std::lock_guard lock(f.mutex);
  std::vector<std::string> out;
  for (const auto& [prefix, family] : f.by_prefix) out.push_back(prefix + ":" + family.usage);
  return out;
}

std::optional<Space> space_from_name(std::string_view name) {
  if (name == "dirs") return Space::dirs;
  if (auto s = registered_space(name)) return s;
  const std::size_t colon = name.find(':');
  if (colon == std::string_view::npos) return std::nullopt;
  Families& f = families();
  std::lock_guard lock(f.mutex);
  const auto it = f.by_prefix.find(name.substr(0, colon));
  if (it == f.by_prefix.end()) return std::nullopt;
  if (auto s = registered_space(name)) return s;  // built by another thread meanwhile
  std::shared_ptr<const ParamDescriptor> member = it->second.make(name.substr(colon + 1));
  if (!member || member->name() != name)
    throw std::logic_error("the parameterization family '" + it->first +
                           "' built a member not named '" + std::string(name) + "'");
  return register_parameterization(std::move(member));
}

namespace {
// The current spaces' names: those registered again later are left out.
std::vector<std::string_view> current_names() {
  std::vector<std::string_view> names;
  for (Space s : parameterizations())
    if (space_from_name(s.param().name()) == s) names.push_back(s.param().name());
  return names;
}
}  // namespace

std::string space_names() {
  std::string s = "dirs";
  for (std::string_view n : current_names()) (s += ", ") += n;
  return s;
}

std::string parameterization_names(std::string_view last_separator) {
  const std::vector<std::string_view> names = current_names();
  std::string s;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) s += i + 1 == names.size() ? last_separator : std::string_view(", ");
    s += names[i];
  }
  return s;
}

std::size_t dimension(Form form) {
  if (form.space.is_dirs()) return 6;
  return form.isotropic ? 3 : 4;
}

std::span<const std::string_view> column_names(Form form) {
  if (form.space.is_dirs()) return kDirColumns;
  return form.space.param().columns(form.isotropic);
}

PairStatus check_pair(const DirPair<double>& p) {
  const double v[6] = {p.wi.x, p.wi.y, p.wi.z, p.wo.x, p.wo.y, p.wo.z};
  for (double x : v)
    if (!std::isfinite(x)) return PairStatus::not_finite;
  if (std::abs(detail::dot(p.wi, p.wi) - 1.0) > kUnitTolerance) return PairStatus::wi_not_unit;
  if (std::abs(detail::dot(p.wo, p.wo) - 1.0) > kUnitTolerance) return PairStatus::wo_not_unit;
  if (p.wi.z < -kDomainTolerance<double>) return PairStatus::wi_below_horizon;
  if (p.wo.z < -kDomainTolerance<double>) return PairStatus::wo_below_horizon;
  return PairStatus::ok;
}

PairStatus accept_pair(DirPair<double>& pair) {
  const PairStatus status = check_pair(pair);
  if (status == PairStatus::ok) pair = detail::accepted_pair(pair);
  return status;
}

std::string_view describe(PairStatus status) {
  switch (status) {
    case PairStatus::ok:
      return "valid";
    case PairStatus::not_finite:
      return "a direction component is not a finite number";
    case PairStatus::wi_not_unit:
      return "wi is not a unit vector";
    case PairStatus::wo_not_unit:
      return "wo is not a unit vector";
    case PairStatus::wi_below_horizon:
      return "wi is below the horizon (wi_z < 0)";
    case PairStatus::wo_below_horizon:
      return "wo is below the horizon (wo_z < 0)";
  }
  return "unknown";
}

}  // namespace halfback
