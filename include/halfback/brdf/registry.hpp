// The registry of analytic BRDF models, addressed by a spec "name" or "name:key=value,...":
// each model declares a name, a description, its parameters (default and range) and a factory.
// A registry is filled with add(...); the loader's model_registry() (loader/load.hpp) holds every
// built-in model. The registry validates every spec before the factory sees it.
#pragma once

#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "halfback/brdf/brdf.hpp"

namespace halfback {

struct ModelParam {
  std::string name;         // [a-z][a-z0-9_]*
  std::string description;  // one line
  double default_value = 0;
  double min = 0, max = 0;  // inclusive range of every value given; default_value must lie in it
  // Named values (e.g. {"F", "S", "G"}): the spec gives a name, the factory receives its index.
  // For such a parameter min and max are set by add() to 0 and choices.size() − 1.
  std::vector<std::string> choices = {};
  // When not empty: a parameter that is not given takes the value of this one (e.g. alpha_x
  // defaults to alpha), and default_value is unused. "Not given" is said here, never by a value
  // inside the range. The named parameter must be declared before, be numeric, default to a
  // value of its own, and have a range inside [min, max] (so the value it passes is valid).
  std::string default_from = {};
};

// A parameter that defaults to another one (see ModelParam::default_from).
ModelParam defaults_to(std::string name, std::string description, std::string from, double min,
                       double max);

// The parameter values a factory receives: every declared parameter, defaults filled in.
class ModelArgs {
 public:
  double operator[](std::string_view name) const;  // throws std::out_of_range if undeclared
  const std::map<std::string, double, std::less<>>& values() const { return values_; }
  void set(std::string name, double value) { values_[std::move(name)] = value; }

 private:
  std::map<std::string, double, std::less<>> values_;
};

struct ModelInfo {
  std::string name;  // [a-z][a-z0-9_-]*
  std::string description;
  std::vector<ModelParam> params;
  std::function<BrdfPtr(const ModelArgs&)> factory;
};

// A spec as the registry read it: the model and the parameters given, in the spec's order (a
// named value as its index in the parameter's choices), each checked against its range.
struct ParsedModelSpec {
  const ModelInfo* info = nullptr;  // never nullptr in a value returned by parse()
  std::vector<std::pair<std::string, double>> given;
};

class ModelRegistry {
 public:
  // Registers a model; throws std::invalid_argument on a malformed entry (bad or duplicate name,
  // default outside its range, no factory).
  void add(ModelInfo info);
  // Removes a model (for tests); returns whether it was registered.
  bool remove(std::string_view name);

  // nullptr when unknown. The pointer stays valid until the model is removed.
  const ModelInfo* find(std::string_view name) const;
  std::vector<std::string> names() const;  // sorted

  // Parses "name", "name:key=value,key=value" or "name:value,key=value" (a value without a key
  // sets the model's first parameter, so "test:S" is "test:fn=S"; spaces around names, keys and
  // values are ignored). Throws std::invalid_argument with a message for users: unknown model
  // (listing the known ones), unknown or repeated parameter, a value that is not a number or is
  // out of range.
  ParsedModelSpec parse(std::string_view spec) const;
  // parse(), then the model with every parameter not given at its default.
  BrdfPtr create(std::string_view spec) const;

 private:
  mutable std::mutex mutex_;
  std::map<std::string, ModelInfo, std::less<>> models_;
};

}  // namespace halfback
