#pragma once
// What several tests ask of a message or a file's text.
#include <string>

namespace atonlab::test {

/// Whether `part` occurs in `s`.
inline bool contains(const std::string& s, const std::string& part) {
    return s.find(part) != std::string::npos;
}

}  // namespace atonlab::test
