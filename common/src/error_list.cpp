#include "atonlab/common/error_list.h"

#include <fmt/format.h>

#include <algorithm>

namespace atonlab::text {

Problem Problem::of(const InputError& e) {
    const SourceLocation w = e.where().value_or(SourceLocation{});
    return Problem{w.file, w.line, w.column, w.key, e.message(), e.what(), w.option};
}

void ErrorList::throw_if_any() const {
    if (kept_.empty()) return;
    const Problem first = in_file_order().front();
    throw InputError(first.where(), first.message, further_lines());
}

void ErrorList::add(Problem p) {
    for (const Problem& k : kept_)
        if (k.file == p.file && k.option == p.option && k.line == p.line && k.column == p.column && k.key == p.key) return;
    if (kept_.size() >= kLimit) {
        ++dropped_;
        return;
    }
    kept_.push_back(std::move(p));
}

std::vector<Problem> ErrorList::in_file_order() const {
    std::vector<Problem> out = kept_;
    std::stable_sort(out.begin(), out.end(), [](const Problem& a, const Problem& b) {
        if (a.line != b.line) return a.line < b.line;
        return a.column < b.column;
    });
    return out;
}

std::vector<std::string> ErrorList::further_lines() const {
    std::vector<std::string> out;
    const std::vector<Problem> all = in_file_order();
    for (std::size_t i = 1; i < all.size(); ++i) out.push_back(all[i].text);
    if (dropped_ > 0)
        out.push_back(fmt::format("... and {} more error{} (the first {} are shown)", dropped_,
                                  dropped_ == 1 ? "" : "s", kLimit));
    return out;
}

}  // namespace atonlab::text
