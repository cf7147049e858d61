// The fitter's recovery tests (private header of src/fit's tests): fit a model to the BRDF of
// one of its own specs and check that every fitted parameter comes back.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <string_view>

#include "halfback/fit/fit.hpp"
#include "halfback/loader/load.hpp"

namespace halfback::fit::recovery_test {

// The value of parameter `name` of term `term` in `m` (a failure and NaN when there is none).
inline double value_in(const Model& m, std::size_t term, std::string_view name) {
  for (const Param& p : m.params)
    if (p.term == term && p.name == name) return p.value;
  ADD_FAILURE() << "no parameter " << name;
  return std::numeric_limits<double>::quiet_NaN();
}

struct Recovery {
  std::size_t samples = 3000;
  double tolerance = 1e-4;  // on each fitted parameter, relative
  Loss loss = Loss::ngan;
  double max_loss = 1e-12;  // the fit's loss; infinity: not checked
};

// Fits `model` to the BRDF of `truth` (the same terms, every fitted parameter given) from `start`
// (empty: the fitter's automatic starts) and checks every fitted parameter to the tolerance, that
// there is at least one, and the loss.
inline void expect_recovered(const std::string& model, const std::string& truth,
                             const std::string& start, const Recovery& check = {}) {
  SCOPED_TRACE(truth + " from " + (start.empty() ? "the automatic starts" : start) + " under " +
               std::string(name_of(check.loss)));
  FitOptions o;
  o.samples = check.samples;
  o.loss = check.loss;
  if (!start.empty()) o.starts = {start};
  const FitResult r = fit(*load_brdf(truth), model, o);
  const Model want = parse_model(truth);
  int fitted = 0;
  for (const Param& p : r.model.params) {
    if (!p.fitted) continue;
    ++fitted;
    const double w = value_in(want, p.term, p.name);
    EXPECT_NEAR(p.value, w, check.tolerance * std::abs(w)) << p.name << " of term " << p.term;
  }
  EXPECT_GT(fitted, 0);
  EXPECT_LT(r.loss_value, check.max_loss);
}

}  // namespace halfback::fit::recovery_test
