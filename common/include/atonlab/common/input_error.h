#pragma once
// Errors: "this input is wrong" (InputError, carries where) versus "this is a
// bug" (assert). pbrt carries a FileLoc into every parse error; so do we. The
// one error type of every library's input: scene files, protocol files,
// answer files, conditions files and command-line options.
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace atonlab {

/// Where a value came from: a file and line with the dotted key inside it
/// ("light[2].intensity_cd"), or a command-line option (`option`: "--set" with
/// the key "camera.yaw_deg", or "--display-width-px").
struct SourceLocation {
    std::string file;            ///< file path; empty for a command-line value
    int line = 0;                ///< 1-based; 0 when unknown
    int column = 0;              ///< 1-based; 0 when unknown
    std::string key;             ///< dotted key path; empty when the error is about the whole file or option
    std::string option = {};     ///< the command-line option that gave the value ("--set"); empty for a file
    bool key_is_column = false;  ///< `key` names a CSV file's column: what() says "column 'NAME'"

    /// A value given on the command line by `option` (and, for --set, its key).
    static SourceLocation command_line(std::string option, std::string key = {}) {
        SourceLocation w;
        w.key = std::move(key);
        w.option = std::move(option);
        return w;
    }
    /// A value in a CSV file: its line and the column's name (may be empty).
    static SourceLocation csv(std::string file, int line, std::string column) {
        SourceLocation w{std::move(file), line, 0, std::move(column)};
        w.key_is_column = true;
        return w;
    }
    bool from_command_line() const noexcept { return !option.empty(); }
};

/// Bad input from a user: a message that is one clear sentence, and where it
/// happened. what() gives "FILE:LINE: key 'KEY': MESSAGE" (parts omitted when
/// unknown; "column 'NAME'" for a CSV column), or "OPTION: key 'KEY': MESSAGE"
/// for a command-line value.
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

/// A spelling that still works but is deprecated: writes one line to stderr, once
/// per process for each old spelling, "WHERE: note: OLD is deprecated; write NEW"
/// (WHERE as InputError gives it). Returns the line, empty when already said.
std::string note_deprecated(const SourceLocation& where, const std::string& old_spelling,
                            const std::string& new_spelling);

}  // namespace atonlab
