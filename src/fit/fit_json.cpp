#include "fit_json.hpp"

#include "halfback/util/text_encoding.hpp"

namespace halfback::fit {

using Json = nlohmann::ordered_json;

std::string_view fit_parameter_unit(std::string_view model, std::string_view param) {
  if (model == "abc" && param == "a") return "1/sr";
  return "1";
}

namespace {

Json term_json(const FitResult& r, std::size_t t) {
  Json params = Json::array();
  for (const Param& p : r.model.params) {
    if (p.term != t) continue;
    Json param;
    param["name"] = p.name;
    param["value"] = p.value;
    param["unit"] = fit_parameter_unit(r.model.terms[t], p.name);
    param["fitted"] = p.fitted;
    param["min"] = p.min;
    param["max"] = p.max;
    params.push_back(std::move(param));
  }
  Json term;
  term["model"] = r.model.terms[t];
  term["parameters"] = std::move(params);
  if (t < r.albedo_share.size()) {  // a dead lobe: docs/fit.md, "Dead lobes"
    term["albedo_share"] = r.albedo_share[t];
    term["loss_without"] = r.loss_without[t];
    term["dead"] = bool(r.dead[t]);
  }
  return term;
}

}  // namespace

Json fit_json(const FitResult& r, std::string_view brdf, std::string_view model,
              const FitEnergy& energy) {
  Json j;
  j["brdf"] = valid_utf8(brdf);  // a file name may not be UTF-8
  j["model"] = valid_utf8(model);
  j["spec"] = r.spec;
  j["loss"]["name"] = name_of(r.loss);
  j["loss"]["value"] = r.loss_value;
  j["samples"]["layout"] = r.layout.empty() ? kLayoutName : std::string_view(r.layout);
  j["samples"]["count"] = r.samples;
  j["samples"]["missing"] = r.missing;
  j["samples"]["out_of_reach"] = r.out_of_reach;
  j["terms"] = Json::array();
  for (std::size_t t = 0; t < r.model.terms.size(); ++t) j["terms"].push_back(term_json(r, t));
  // docs/fit.md, "Energy": above 1, the fitted model creates light.
  j["energy"]["max_albedo"] = energy.max_albedo;
  j["energy"]["theta_deg"] = energy.theta_deg;
  j["energy"]["standard_error"] = energy.standard_error;
  j["energy"]["creates_energy"] = energy.creates_energy();
  j["starts"] = r.starts;
  j["iterations"] = r.iterations;
  j["seconds"] = r.seconds;
  return j;
}

}  // namespace halfback::fit
