#include "fit_json.hpp"

namespace halfback::view {

std::string_view fit_parameter_unit(std::string_view model, std::string_view param) {
  if (model == "abc" && param == "a") return "1/sr";
  return "1";
}

void write_fit(JsonWriter& j, const fit::FitResult& r, std::string_view brdf,
               std::string_view model) {
  j.begin_object();
  j.field("brdf", brdf).field("model", model).field("spec", r.spec);
  j.key("loss").begin_object();
  j.field("name", fit::name_of(r.loss)).field("value", r.loss_value).end_object();
  j.key("samples").begin_object();
  j.field("layout", fit::kLayoutName).field("count", r.samples).end_object();
  j.key("terms").begin_array();
  for (std::size_t t = 0; t < r.model.terms.size(); ++t) {
    j.begin_object().field("model", r.model.terms[t]).key("parameters").begin_array();
    for (const fit::Param& p : r.model.params) {
      if (p.term != t) continue;
      j.begin_object().field("name", p.name).field("value", p.value);
      j.field("unit", fit_parameter_unit(r.model.terms[t], p.name)).field("fitted", p.fitted);
      j.field("min", p.min).field("max", p.max).end_object();
    }
    j.end_array().end_object();
  }
  j.end_array();
  j.field("starts", r.starts).field("iterations", r.iterations).field("seconds", r.seconds);
  j.end_object();
}

}  // namespace halfback::view
