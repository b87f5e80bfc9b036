#pragma once
// Errors: "this input is wrong" (InputError, carries where) versus "this is a
// bug" (assert). pbrt carries a FileLoc into every parse error; so do we.
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace atonlab {

/// Where a value came from: a file and line, and the dotted key inside it
/// ("light[2].intensity_cd"), or a command-line override ("--set camera.yaw_deg").
struct SourceLocation {
    std::string file;          ///< file path, or "--set" for command-line overrides
    int line = 0;              ///< 1-based; 0 when unknown
    int column = 0;            ///< 1-based; 0 when unknown
    std::string key;           ///< dotted key path; empty when the error is about the whole file
};

/// Bad input from a user: a message that is one clear sentence, and where it
/// happened. what() gives "FILE:LINE: key 'KEY': MESSAGE" (parts omitted when unknown).
class InputError : public std::runtime_error {
public:
    InputError(SourceLocation where, const std::string& message);
    /// The first of several errors (in file order) with the others' whole
    /// lines: what() is the first line, then each further one on its own line.
    InputError(SourceLocation where, const std::string& message, std::vector<std::string> further);
    explicit InputError(const std::string& message);  ///< no location

    const std::optional<SourceLocation>& where() const noexcept { return where_; }
    const std::string& message() const noexcept { return message_; }
    /// The other errors found in the same run, each a whole line; empty when one.
    const std::vector<std::string>& further() const noexcept { return further_; }

private:
    std::vector<std::string> further_;
    std::optional<SourceLocation> where_;
    std::string message_;
};

}  // namespace atonlab
