#include "child_process.h"

#include <fstream>
#include <iterator>

namespace atonlab::test {
namespace {

std::string file_text(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

Captured run_captured(std::vector<std::string> argv, const std::filesystem::path& dir, const std::string& tag) {
    const std::filesystem::path out = dir / (tag + ".out"), err = dir / (tag + ".err");
    Captured r;
    r.code = run_to_files(std::move(argv), out, err, /*stdin_null=*/true);
    r.out = file_text(out);
    r.err = file_text(err);
    return r;
}

}  // namespace atonlab::test
