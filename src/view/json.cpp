#include "json.hpp"

#include "halfback/util/text_encoding.hpp"

namespace halfback::view {

namespace {

void make_utf8(Json& j) {
  if (j.is_string())
    j = valid_utf8(j.get_ref<const std::string&>());
  else if (j.is_structured())
    for (Json& v : j) make_utf8(v);
}

}  // namespace

std::string json_text(Json j) {
  make_utf8(j);
  // The keys are the code's own UTF-8: `replace` only guards them (dump would throw on a bad one).
  return j.dump(-1, ' ', false, Json::error_handler_t::replace);
}

}  // namespace halfback::view
