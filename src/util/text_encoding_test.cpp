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
