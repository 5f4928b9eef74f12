// io/text_files.h: the encodings of `atmos viewer`'s scripts.
#include <gtest/gtest.h>

#include <string>

#include "atmos/error.h"
#include "io/text_files.h"

namespace atmos {
namespace {

TEST(TextFiles, Base64MatchesTheRfcVectors) {
    // RFC 4648 section 10.
    EXPECT_EQ(Base64Encode(""), "");
    EXPECT_EQ(Base64Encode("f"), "Zg==");
    EXPECT_EQ(Base64Encode("fo"), "Zm8=");
    EXPECT_EQ(Base64Encode("foo"), "Zm9v");
    EXPECT_EQ(Base64Encode("foob"), "Zm9vYg==");
    EXPECT_EQ(Base64Encode("fooba"), "Zm9vYmE=");
    EXPECT_EQ(Base64Encode("foobar"), "Zm9vYmFy");
    EXPECT_EQ(Base64Encode(std::string("\xff\xfe\x00", 3)), "//4A");
}

TEST(TextFiles, JsStringLiteralEscapesWhatEndsAStringOrAScript) {
    EXPECT_EQ(JsStringLiteral("a\"b\\c</script>\r\n"), "\"a\\\"b\\\\c\\x3c/script>\\n\"");
    EXPECT_THROW(ReadWholeFile("/nonexistent/atmos/file"), Error);
}

}  // namespace
}  // namespace atmos
