// Input as errors echo it and as readers take it in (common/input_text.h):
// echoed values cut to 80 characters with control characters escaped, whole
// messages kept to one line of bounded length, files read only up to a limit
// (/dev/zero refused instead of read until the memory runs out). Expected
// strings are written out by hand.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "../store/store_test_support.h"
#include "atonlab/common/input_text.h"
#include "atonlab/stimuli/error.h"

namespace atonlab::text {
namespace {

TEST(InputText, EchoKeepsShortValuesAndEscapesControlCharacters) {
    EXPECT_EQ(echo("red"), "red");
    EXPECT_EQ(echo(""), "");
    EXPECT_EQ(echo("red\nblue"), "red\\nblue");
    EXPECT_EQ(echo("a\tb\rc"), "a\\tb\\rc");
    EXPECT_EQ(echo(std::string("nul\0bell\x07", 9)), "nul\\x00bell\\x07");
    EXPECT_EQ(echo("del\x7f"), "del\\x7F");
    EXPECT_EQ(echo("0.5 cd/m² at 4°"), "0.5 cd/m² at 4°") << "UTF-8 is not escaped";
}

// Bytes that are not well-formed UTF-8 (RFC 3629 section 4) are escaped as
// \xNN, so that every message is valid UTF-8 (a damaged record echoed "doc"
// and the raw byte 0xB0). Each case by hand from the RFC's table.
TEST(InputText, EchoEscapesBytesThatAreNotUtf8) {
    EXPECT_EQ(echo("doc\xb0"), "doc\\xB0") << "a stray continuation byte";
    EXPECT_EQ(echo("\xc3"), "\\xC3") << "a lead byte cut short at the end";
    EXPECT_EQ(echo("\xc3("), "\\xC3(") << "a lead byte without its continuation";
    EXPECT_EQ(echo("\xc0\xaf"), "\\xC0\\xAF") << "an overlong '/'";
    EXPECT_EQ(echo("\xe0\x80\xaf"), "\\xE0\\x80\\xAF") << "an overlong 3-byte form";
    EXPECT_EQ(echo("\xed\xa0\x80"), "\\xED\\xA0\\x80") << "a surrogate (U+D800)";
    EXPECT_EQ(echo("\xf4\x90\x80\x80"), "\\xF4\\x90\\x80\\x80") << "past U+10FFFF";
    EXPECT_EQ(echo("\xff\xfe"), "\\xFF\\xFE");
    EXPECT_EQ(echo("\xf0\x9f\x92\xa1 \xe2\x82\xac \xc2\xb0"), "\xf0\x9f\x92\xa1 \xe2\x82\xac \xc2\xb0")
        << "4-, 3- and 2-byte characters are kept";
    EXPECT_EQ(echo("\xed\x9f\xbf\xf4\x8f\xbf\xbf"), "\xed\x9f\xbf\xf4\x8f\xbf\xbf") << "U+D7FF and U+10FFFF are kept";
    EXPECT_EQ(one_line("at byte 2042: doc\xb0\n"), "at byte 2042: doc\\xB0\\n");
}

TEST(InputText, EchoCutsLongValuesAtEightyCharactersAndSaysHowLong) {
    const std::string four_mib(4u << 20, 'x');
    EXPECT_EQ(echo(four_mib), std::string(80, 'x') + "… (4194304 bytes in all)");
    EXPECT_EQ(echo(std::string(80, 'y')), std::string(80, 'y')) << "exactly 80: not cut";
    EXPECT_EQ(echo(std::string(81, 'y')), std::string(80, 'y') + "… (81 bytes in all)");
    // Characters, not bytes, and a cut never splits a UTF-8 sequence: 100 '°' (2 bytes each).
    std::string degrees;
    for (int i = 0; i < 100; ++i) degrees += "°";
    std::string first80;
    for (int i = 0; i < 80; ++i) first80 += "°";
    EXPECT_EQ(echo(degrees), first80 + "… (200 bytes in all)");
    EXPECT_EQ(echo("abcdef", 3), "abc… (6 bytes in all)");
}

TEST(InputText, OneLineEscapesNewlinesAndBoundsTheLength) {
    EXPECT_EQ(one_line("a\nb"), "a\\nb");
    const std::string long_message(10000, 'm');
    const std::string cut = one_line(long_message);
    EXPECT_EQ(cut, std::string(kMessageMax, 'm') + "…");
}

TEST(InputText, InputErrorsAreOneLineWhateverTheyEcho) {
    const InputError e(SourceLocation{"f.toml", 3, 1, "light[0].na\nme"}, "bad\nvalue " + std::string(5000, 'v'));
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_EQ(what.rfind("f.toml:3: key 'light[0].na\\nme': bad\\nvalue vvv", 0), 0u) << what;
    EXPECT_LE(what.size(), kMessageMax + 3);  // + the 3 bytes of "…"
}

TEST(InputText, ReadsAFileWhole) {
    store::test_support::TempDir dir;
    const std::filesystem::path f = dir / "scene.toml";
    std::ofstream(f, std::ios::binary) << "[display]\nwidth_px = 64\n";
    const FileText t = read_text_file(f);
    EXPECT_TRUE(t.ok()) << t.error;
    EXPECT_TRUE(t.opened);
    EXPECT_EQ(t.text, "[display]\nwidth_px = 64\n");
}

TEST(InputText, RefusesFilesLargerThanTheLimitWithoutReadingThemWhole) {
    // /dev/zero never ends: a reader without a limit allocates until bad_alloc.
    const FileText zero = read_text_file("/dev/zero");
    EXPECT_FALSE(zero.ok());
    EXPECT_TRUE(zero.text.empty());
    EXPECT_EQ(zero.error, "it is larger than 16.0 MiB, the most an input file may be");

    store::test_support::TempDir dir;
    const std::filesystem::path f = dir / "big.toml";
    std::ofstream(f, std::ios::binary) << std::string(1001, 'a');
    EXPECT_TRUE(read_text_file(f, 1001).ok()) << "exactly the limit is allowed";
    const FileText big = read_text_file(f, 1000);
    EXPECT_FALSE(big.ok());
    EXPECT_EQ(big.error, "it is larger than 1000 bytes, the most an input file may be");
}

TEST(InputText, SaysWhyAFileCannotBeRead) {
    store::test_support::TempDir dir;
    const FileText missing = read_text_file(dir / "no-such.toml");
    EXPECT_FALSE(missing.opened);
    EXPECT_EQ(missing.error, "No such file or directory");
    const FileText folder = read_text_file(dir.path());
    EXPECT_FALSE(folder.ok());
    EXPECT_EQ(folder.error, "it is a directory");
}

}  // namespace
}  // namespace atonlab::text
