// XML escapes and base64, against the RFC 4648 test vectors.
#include "halfback/util/text_encoding.hpp"

#include <gtest/gtest.h>

namespace halfback {
namespace {

TEST(TextEncoding, Base64MatchesTheRfc4648Vectors) {
  const char* plain[] = {"", "f", "fo", "foo", "foob", "fooba", "foobar"};
  const char* coded[] = {"", "Zg==", "Zm8=", "Zm9v", "Zm9vYg==", "Zm9vYmE=", "Zm9vYmFy"};
  for (int k = 0; k < 7; ++k) EXPECT_EQ(base64_encode(plain[k]), coded[k]) << plain[k];
  // Bytes above 127 are not sign-extended.
  EXPECT_EQ(base64_encode(std::string_view("\xff\xfe\x00", 3)), "//4A");
}

TEST(TextEncoding, XmlEscapesOnlyTheSpecialCharacters) {
  EXPECT_EQ(escape_xml("a<b & \"c\">d ‖h̄‖"), "a&lt;b &amp; &quot;c&quot;&gt;d ‖h̄‖");
  EXPECT_EQ(escape_xml(""), "");
}

}  // namespace
}  // namespace halfback

namespace halfback {
namespace {

// Well-formed UTF-8 passes unchanged; each invalid byte becomes U+FFFD (overlong forms,
// surrogates, code points above U+10FFFF, truncated sequences, stray continuation bytes).
TEST(TextEncoding, ValidUtf8ReplacesInvalidSequences) {
  const std::string ok = "abc \xC3\xA9 \xE2\x82\xAC \xF0\x9F\x98\x80";  // é € 😀
  EXPECT_EQ(valid_utf8(ok), ok);
  const std::string fffd = "\xEF\xBF\xBD";
  EXPECT_EQ(valid_utf8("a\xFF"
                       "b"),
            "a" + fffd + "b");
  EXPECT_EQ(valid_utf8("\xC0\xAF"), fffd + fffd);                        // overlong '/'
  EXPECT_EQ(valid_utf8("\xED\xA0\x80"), fffd + fffd + fffd);             // a surrogate
  EXPECT_EQ(valid_utf8("\xF4\x90\x80\x80"), fffd + fffd + fffd + fffd);  // above U+10FFFF
  EXPECT_EQ(valid_utf8("x\xE2\x82"), "x" + fffd + fffd);                 // truncated
  EXPECT_EQ(valid_utf8("\x80"), fffd);                                   // a lone continuation byte
  EXPECT_EQ(valid_utf8(""), "");
}

}  // namespace
}  // namespace halfback
