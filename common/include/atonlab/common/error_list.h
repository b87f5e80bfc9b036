#pragma once
// Every error of an input file at once: the scene and protocol loaders read
// on past an error in one table or entry, collect what each part throws, and
// report all of it (up to a limit) in file order in one run — a protocol
// written by trial and error then takes one run per batch of mistakes, not
// one run per mistake. This is the one mechanism both use.
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "atonlab/common/input_error.h"

namespace atonlab::text {

/// One error: where (file, 1-based line and column, 0 when unknown; the dotted
/// key) and the whole sentence as the loader's error prints it (`text`).
struct Problem {
    std::string file;
    int line = 0;
    int column = 0;
    std::string key;
    std::string message;  ///< the sentence without its location
    std::string text;     ///< "FILE:LINE: key 'KEY': MESSAGE"
    std::string option;   ///< the command-line option, when the value came from one

    /// The error `e` as a Problem.
    static Problem of(const InputError& e);
    /// The location as an InputError takes it.
    SourceLocation where() const { return SourceLocation{file, line, column, key, option}; }
};

class ErrorList {
public:
    /// At most this many errors are kept (the rest are counted).
    static constexpr std::size_t kLimit = 20;

    /// Keeps `p` unless one at the same place (file, line, column, key) is kept
    /// already (a [defaults] error met again by every condition that inherits it).
    void add(Problem p);

    /// Runs `f`; an error of type E that it throws is added (through `convert`,
    /// E -> Problem) and false returned. Other exceptions pass through.
    template <class E, class F, class Convert>
    bool attempt(F&& f, Convert&& convert) {
        try {
            f();
            return true;
        } catch (const E& e) {
            add(convert(e));
            return false;
        }
    }

    /// Runs `f`; an InputError that it throws is added and false returned.
    template <class F>
    bool attempt(F&& f) {
        return attempt<InputError>(std::forward<F>(f), Problem::of);
    }

    /// When errors were kept: throws the first (in file order) as an
    /// InputError whose further() holds the others' lines.
    void throw_if_any() const;

    bool empty() const noexcept { return kept_.empty(); }
    std::size_t size() const noexcept { return kept_.size() + dropped_; }

    /// The kept errors in file order: whole-file errors (line 0) first, then by
    /// line and column; errors at the same place in the order they were met.
    std::vector<Problem> in_file_order() const;
    /// The lines after the first (in file order): each further error's text,
    /// then "... and N more errors" when some were not kept.
    std::vector<std::string> further_lines() const;

private:
    std::vector<Problem> kept_;
    std::size_t dropped_ = 0;
};

}  // namespace atonlab::text
