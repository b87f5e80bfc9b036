// files::read_text (common/read_file.h), the one reader of whole input files:
// the text as written, or one error naming the file, its role and the reason.
// Expected strings are written out by hand.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "../store/store_test_support.h"
#include "atonlab/common/read_file.h"

namespace atonlab::files {
namespace {

std::string error_of(const std::filesystem::path& file, std::uintmax_t max_bytes = text::kMaxInputFileBytes) {
    try {
        (void)read_text(file, "scene template", max_bytes);
    } catch (const InputError& e) {
        EXPECT_TRUE(e.where() && e.where()->file == file.string() && e.where()->line == 0);
        return e.what();
    }
    return "(no InputError)";
}

TEST(ReadFile, ReturnsTheWholeTextByteForByte) {
    store::test_support::TempDir dir;
    const std::filesystem::path f = dir / "scene.toml";
    const std::string bytes("[display]\r\nwidth_px = 64\n\0tail", 30);
    std::ofstream(f, std::ios::binary) << bytes;
    EXPECT_EQ(read_text(f, "scene template"), bytes);
}

TEST(ReadFile, NamesTheFileItsRoleAndWhyItCannotBeRead) {
    store::test_support::TempDir dir;
    EXPECT_EQ(error_of(dir / "missing.toml"),
              (dir / "missing.toml").string() + ": cannot read the scene template: No such file or directory.");
    EXPECT_EQ(error_of(dir.path()), dir.path().string() + ": cannot read the scene template: it is a directory.");
    EXPECT_EQ(error_of("/dev/zero"),
              "/dev/zero: cannot read the scene template: it is larger than 16.0 MiB, the most an input file may be.");
    const std::filesystem::path f = dir / "big.toml";
    std::ofstream(f, std::ios::binary) << std::string(11, 'a');
    EXPECT_EQ(read_text(f, "scene template", 11), std::string(11, 'a')) << "exactly the limit is allowed";
    EXPECT_EQ(
        error_of(f, 10),
        f.string() + ": cannot read the scene template: it is larger than 10 bytes, the most an input file may be.");
}

TEST(ReadFile, TheMessageAloneLeavesTheFileToTheCaller) {
    try {
        (void)read_text("/nonexistent/answers.txt", "answer file");
        FAIL() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_EQ(e.message(), "cannot read the answer file: No such file or directory.");
    }
}

}  // namespace
}  // namespace atonlab::files
