// The view's JSON (nlohmann-json, keys in the order they are set) and the text of a response:
// numbers as nlohmann writes them (the shortest text that reads back as the same double, so the
// page gets the double `halfback eval` prints), NaN and infinities as null, strings escaped.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace halfback::view {

using Json = nlohmann::ordered_json;

// The text of j, every string in it made well-formed UTF-8 first (valid_utf8: a file name or a
// request's text may not be).
std::string json_text(Json j);

}  // namespace halfback::view
