#include "atonlab/common/error_list.h"

#include <fmt/format.h>

#include <algorithm>

namespace atonlab::text {

void ErrorList::add(Problem p) {
    for (const Problem& k : kept_)
        if (k.file == p.file && k.line == p.line && k.column == p.column && k.key == p.key) return;
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
