#include "halfback/brdf/registry.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <set>
#include <stdexcept>

namespace halfback {

namespace {

bool valid_identifier(std::string_view s, bool allow_dash) {
  if (s.empty() || !(s[0] >= 'a' && s[0] <= 'z')) return false;
  for (char c : s)
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || (allow_dash && c == '-')))
      return false;
  return true;
}

std::string format_number(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
  while (!s.empty() && s.back() == ' ') s.remove_suffix(1);
  return s;
}

// Checks the parameter `p` that defaults to another one of `params`.
void check_default_from(const std::string& model, const std::vector<ModelParam>& params,
                        const ModelParam& p) {
  const std::string what =
      "model '" + model + "': parameter '" + p.name + "' defaults to '" + p.default_from + "'";
  const ModelParam* from = nullptr;
  for (const ModelParam& q : params) {
    if (&q == &p) break;  // only those declared before
    if (q.name == p.default_from) from = &q;
  }
  if (!from) throw std::invalid_argument(what + ", which is not declared before it");
  if (!from->default_from.empty() || !from->choices.empty() || !p.choices.empty())
    throw std::invalid_argument(what + ": both must be numbers, the other with a default value");
  if (!(p.min <= from->min && from->max <= p.max))
    throw std::invalid_argument(what + ", whose range [" + format_number(from->min) + ", " +
                                format_number(from->max) + "] is not inside [" +
                                format_number(p.min) + ", " + format_number(p.max) + "]");
}

}  // namespace

ModelParam defaults_to(std::string name, std::string description, std::string from, double min,
                       double max) {
  ModelParam p{std::move(name), std::move(description), min, min, max};
  p.default_from = std::move(from);
  return p;
}

double ModelArgs::operator[](std::string_view name) const {
  const auto it = values_.find(name);
  if (it == values_.end()) throw std::out_of_range("model parameter '" + std::string(name) + "'");
  return it->second;
}

void ModelRegistry::add(ModelInfo info) {
  for (auto& p : info.params)
    if (!p.choices.empty()) {
      p.min = 0;
      p.max = double(p.choices.size() - 1);
    }
  if (!valid_identifier(info.name, true))
    throw std::invalid_argument("model name '" + info.name + "' must match [a-z][a-z0-9_-]*");
  if (!info.factory) throw std::invalid_argument("model '" + info.name + "' has no factory");
  std::set<std::string_view> seen;
  for (const auto& p : info.params) {
    if (!valid_identifier(p.name, false))
      throw std::invalid_argument("model '" + info.name + "': parameter name '" + p.name +
                                  "' must match [a-z][a-z0-9_]*");
    if (!seen.insert(p.name).second)
      throw std::invalid_argument("model '" + info.name + "': parameter '" + p.name +
                                  "' declared twice");
    if (!p.default_from.empty()) {
      check_default_from(info.name, info.params, p);
      continue;
    }
    if (!(p.min <= p.default_value && p.default_value <= p.max))
      throw std::invalid_argument("model '" + info.name + "': default of '" + p.name +
                                  "' is outside [" + format_number(p.min) + ", " +
                                  format_number(p.max) + "]");
  }
  std::lock_guard lock(mutex_);
  if (models_.count(info.name))
    throw std::invalid_argument("model '" + info.name + "' is already registered");
  std::string key = info.name;
  models_.emplace(std::move(key), std::move(info));
}

bool ModelRegistry::remove(std::string_view name) {
  std::lock_guard lock(mutex_);
  const auto it = models_.find(name);
  if (it == models_.end()) return false;
  models_.erase(it);
  return true;
}

const ModelInfo* ModelRegistry::find(std::string_view name) const {
  std::lock_guard lock(mutex_);
  const auto it = models_.find(name);
  return it == models_.end() ? nullptr : &it->second;
}

std::vector<std::string> ModelRegistry::names() const {
  std::lock_guard lock(mutex_);
  std::vector<std::string> r;
  for (const auto& [name, info] : models_) r.push_back(name);
  return r;
}

ParsedModelSpec ModelRegistry::parse(std::string_view spec) const {
  const std::string spec_s(spec);
  const std::size_t colon = spec.find(':');
  const std::string_view name = trim(spec.substr(0, colon));
  const ModelInfo* info = find(name);
  if (!info) {
    std::string known;
    for (const auto& n : names()) known += (known.empty() ? "" : ", ") + n;
    throw std::invalid_argument(
        "'" + spec_s + "' is neither an existing file nor a known BRDF model" +
        (known.empty() ? std::string(" (no models are registered)") : " (models: " + known + ")"));
  }
  ParsedModelSpec parsed{info, {}};
  std::set<std::string, std::less<>> given;
  if (colon != std::string_view::npos) {
    std::string_view rest = spec.substr(colon + 1);
    while (true) {
      const std::size_t comma = rest.find(',');
      const std::string_view item = trim(rest.substr(0, comma));
      const std::size_t eq = item.find('=');
      if (item.empty()) throw std::invalid_argument("model spec '" + spec_s + "': empty parameter");
      // A bare value sets the first parameter ("test:S" is "test:fn=S").
      const bool positional = eq == std::string_view::npos;
      if (positional && (info->params.empty() || !given.empty()))
        throw std::invalid_argument("model spec '" + spec_s + "': '" + std::string(item) +
                                    "' is not key=value");
      const std::string_view key =
          positional ? std::string_view(info->params.front().name) : trim(item.substr(0, eq));
      const std::string_view text = positional ? item : trim(item.substr(eq + 1));
      const ModelParam* param = nullptr;
      for (const auto& p : info->params)
        if (p.name == key) param = &p;
      if (!param) {
        std::string list;
        for (const auto& p : info->params) list += (list.empty() ? "" : ", ") + p.name;
        throw std::invalid_argument(
            "model '" + info->name + "' has no parameter '" + std::string(key) + "'" +
            (list.empty() ? " (it takes none)" : " (parameters: " + list + ")"));
      }
      if (!given.insert(std::string(key)).second)
        throw std::invalid_argument("model spec '" + spec_s + "': '" + std::string(key) +
                                    "' given twice");
      double v = 0;
      if (!param->choices.empty()) {
        const auto it = std::find(param->choices.begin(), param->choices.end(), text);
        if (it == param->choices.end()) {
          std::string list;
          for (const auto& c : param->choices) list += (list.empty() ? "" : ", ") + c;
          throw std::invalid_argument("model '" + info->name + "': " + param->name + "=" +
                                      std::string(text) + " is not one of: " + list);
        }
        v = double(it - param->choices.begin());
      } else {
        const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
        if (text.empty() || r.ec != std::errc() || r.ptr != text.data() + text.size() ||
            !std::isfinite(v))
          throw std::invalid_argument("model '" + info->name + "': value '" + std::string(text) +
                                      "' of '" + param->name + "' is not a finite number");
        if (v < param->min || v > param->max)
          throw std::invalid_argument(
              "model '" + info->name + "': " + param->name + "=" + std::string(text) +
              " is outside [" + format_number(param->min) + ", " + format_number(param->max) + "]");
      }
      parsed.given.emplace_back(param->name, v);
      if (comma == std::string_view::npos) break;
      rest.remove_prefix(comma + 1);
    }
  }
  return parsed;
}

BrdfPtr ModelRegistry::create(std::string_view spec) const {
  const ParsedModelSpec parsed = parse(spec);
  const ModelInfo& info = *parsed.info;
  ModelArgs args;
  for (const auto& p : info.params) args.set(p.name, p.default_value);
  for (const auto& [name, value] : parsed.given) args.set(name, value);
  // Parameters not given that default to another one (declared before, so already final).
  const auto is_given = [&](const std::string& name) {
    return std::any_of(parsed.given.begin(), parsed.given.end(),
                       [&](const auto& g) { return g.first == name; });
  };
  for (const auto& p : info.params)
    if (!p.default_from.empty() && !is_given(p.name)) args.set(p.name, args[p.default_from]);
  return info.factory(args);
}

}  // namespace halfback
