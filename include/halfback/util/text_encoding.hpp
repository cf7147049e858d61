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

// The text with every byte sequence that is not well-formed UTF-8 (RFC 3629: no overlong forms,
// no surrogates, nothing above U+10FFFF) replaced by U+FFFD, one per maximal invalid prefix:
// for text from outside (file names) that goes into JSON or HTML, which must be UTF-8.
std::string valid_utf8(std::string_view text);

}  // namespace halfback
