// Files written whole or not at all (common/atomic_file.h): the destination
// holds the old file or the complete new one, never a part; failures name the
// file; no temporary is left behind.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <unistd.h>

#include "atonlab/common/atomic_file.h"

namespace atonlab::files {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
    const fs::path d = fs::temp_directory_path() / ("atonlab-atomic-" + name + "-" + std::to_string(::getpid()));
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

std::string read_all(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

std::size_t entries(const fs::path& d) {
    std::size_t n = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(d)) ++n;
    return n;
}

TEST(AtomicFile, WritesTheBytesAndReplacesAnOldFileLeavingNoTemporary) {
    const fs::path d = fresh_dir("write");
    const fs::path f = d / "summary.json";
    write_file_atomically(f, "old");
    const std::string big(3'000'000, 'x');  // more than one write() may take
    write_file_atomically(f, big);
    EXPECT_EQ(read_all(f), big);
    write_file_atomically(f, std::string("a\0b", 3));
    EXPECT_EQ(read_all(f), std::string("a\0b", 3));
    EXPECT_EQ(entries(d), 1u) << "only the destination remains";
    fs::remove_all(d);
}

TEST(AtomicFile, AnUncommittedFileLeavesTheOldOneAndNoTemporary) {
    const fs::path d = fresh_dir("abandon");
    const fs::path f = d / "report.html";
    write_file_atomically(f, "finished");
    {
        AtomicFile half(f);
        ASSERT_TRUE(fs::exists(half.temp_path()));
        EXPECT_EQ(half.temp_path().parent_path(), d) << "a sibling, so the rename stays on one file system";
    }  // destroyed without commit, as on an exception
    EXPECT_EQ(read_all(f), "finished");
    EXPECT_EQ(entries(d), 1u);
    fs::remove_all(d);
}

TEST(AtomicFile, AFolderThatDoesNotExistIsAWriteErrorNamingTheFile) {
    const fs::path f = fs::temp_directory_path() / "atonlab-no-such-folder-x9" / "fits.csv";
    try {
        write_file_atomically(f, "x");
        FAIL() << "no error";
    } catch (const WriteError& e) {
        EXPECT_EQ(e.path(), f);
        EXPECT_NE(e.reason().find("cannot create a temporary file"), std::string::npos) << e.reason();
        EXPECT_EQ(std::string(e.what()).rfind(f.string() + ": ", 0), 0u) << e.what();
    }
    EXPECT_FALSE(fs::exists(f));
}

}  // namespace
}  // namespace atonlab::files
