#pragma once
// What a call throws as InputError, for tests that check the message.
#include <string>

#include "atonlab/common/input_error.h"

namespace atonlab::test {

/// The what() of the InputError that f() throws, or `none` if it throws none.
template <class F>
std::string input_error_of(F&& f, const std::string& none = "(no InputError thrown)") {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return none;
}

}  // namespace atonlab::test
