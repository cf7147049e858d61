// Text encodings for the files the project writes by hand: XML/HTML character escapes (SVG
// figures, HTML reports) and base64 (images embedded in them as data: URIs).
#pragma once

#include <string>
#include <string_view>

namespace halfback {

// `&`, `<`, `>` and `"` as character references; everything else (UTF-8 included) unchanged.
std::string escape_xml(std::string_view text);

// RFC 4648 base64 with padding, no line breaks.
std::string base64_encode(std::string_view bytes);

}  // namespace halfback
