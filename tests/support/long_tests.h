// The suite's bounded forms and their long forms (docs/measured.md, "The
// README's commands"): a check that costs minutes on 2 cores runs a bounded
// form in `bash scripts/test.sh` (and so in CI, within its 20 minutes) and its
// whole form with ATONLAB_LONG_TESTS=1, e.g.
//   ATONLAB_LONG_TESTS=1 ctest --test-dir build -R 'ExampleConvergence|AddingLight'
#pragma once

#include <cstdlib>
#include <string_view>

namespace atonlab::test {

/// True when ATONLAB_LONG_TESTS=1: run every seed, setting and repetition.
inline bool long_tests() {
    const char* on = std::getenv("ATONLAB_LONG_TESTS");
    return on != nullptr && std::string_view(on) == "1";
}

}  // namespace atonlab::test
