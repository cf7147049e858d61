// A small JSON writer for the view's responses: objects and arrays built in order, numbers with
// 17 significant digits (the CLI's %.17g, so that the page shows what `halfback eval` prints),
// NaN and infinities as null, strings escaped (control characters as \u00XX).
#pragma once

#include <fmt/format.h>

#include <cmath>
#include <string>
#include <string_view>

#include "halfback/util/text_encoding.hpp"

namespace halfback::view {

class JsonWriter {
 public:
  JsonWriter& begin_object() { return open('{'); }
  JsonWriter& end_object() { return close('}'); }
  JsonWriter& begin_array() { return open('['); }
  JsonWriter& end_array() { return close(']'); }

  // The key of the next value inside an object.
  JsonWriter& key(std::string_view k) {
    separate();
    append_string(k);
    out_ += ':';
    after_key_ = true;
    return *this;
  }
  JsonWriter& value(std::string_view s) {
    separate();
    append_string(s);
    return *this;
  }
  JsonWriter& value(const char* s) { return value(std::string_view(s)); }
  JsonWriter& value(double x) {
    separate();
    if (std::isfinite(x))
      out_ += fmt::format("{:.17g}", x);
    else
      out_ += "null";
    return *this;
  }
  JsonWriter& value(int x) { return integer(x); }
  JsonWriter& value(long long x) { return integer(x); }
  JsonWriter& value(std::size_t x) { return integer(x); }
  JsonWriter& value(bool b) {
    separate();
    out_ += b ? "true" : "false";
    return *this;
  }
  JsonWriter& null() {
    separate();
    out_ += "null";
    return *this;
  }
  template <class T>
  JsonWriter& field(std::string_view k, const T& v) {
    return key(k).value(v);
  }

  const std::string& str() const { return out_; }

 private:
  template <class I>
  JsonWriter& integer(I x) {
    separate();
    out_ += fmt::format("{}", x);
    return *this;
  }
  JsonWriter& open(char c) {
    separate();
    out_ += c;
    first_ = true;
    return *this;
  }
  JsonWriter& close(char c) {
    out_ += c;
    first_ = false;
    return *this;
  }
  void separate() {
    if (after_key_) {
      after_key_ = false;
      return;
    }
    if (!first_) out_ += ',';
    first_ = false;
  }
  void append_string(std::string_view text) {
    const std::string s = valid_utf8(text);  // JSON is UTF-8: a file name may not be
    out_ += '"';
    for (const char ch : s) {
      const auto c = static_cast<unsigned char>(ch);
      if (c == '"' || c == '\\') {
        out_ += '\\';
        out_ += ch;
      } else if (c < 0x20) {
        out_ += fmt::format("\\u{:04x}", unsigned(c));
      } else {
        out_ += ch;
      }
    }
    out_ += '"';
  }

  std::string out_;
  bool first_ = true, after_key_ = false;
};

}  // namespace halfback::view
