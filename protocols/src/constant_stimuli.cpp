// The method of constant stimuli (constant_stimuli.h).
#include "atonlab/protocols/constant_stimuli.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "atonlab/protocols/rng.h"
#include "checks.h"
#include "state_text.h"

namespace atonlab::protocols {

std::string_view to_string(ConstantOrder o) noexcept {
    switch (o) {
        case ConstantOrder::Blocked:
            return "blocked";
        case ConstantOrder::Passes:
            return "passes";
        case ConstantOrder::Random:
            return "random";
    }
    return "?";
}

ConstantOrder parse_constant_order(std::string_view text) {
    if (text == "blocked") return ConstantOrder::Blocked;
    if (text == "passes") return ConstantOrder::Passes;
    if (text == "random") return ConstantOrder::Random;
    throw ProcedureError("order", fmt::format("must be \"blocked\", \"passes\" or \"random\", not \"{}\"", text));
}

namespace {

void validate(const ConstantStimuliParams& p) {
    using detail::require;
    require(!p.levels.empty(), "levels", "needs at least one level");
    for (double v : p.levels) detail::require_finite(v, "levels");
    std::vector<double> sorted = p.levels;
    std::sort(sorted.begin(), sorted.end());
    const auto dup = std::adjacent_find(sorted.begin(), sorted.end());
    require(dup == sorted.end(), "levels", fmt::format("lists {} twice", dup == sorted.end() ? 0.0 : *dup));
    require(p.repetitions >= 1, "repetitions", fmt::format("must be >= 1, not {}", p.repetitions));
    require(std::isfinite(p.criterion) && p.criterion > 0.0 && p.criterion < 1.0, "criterion",
            fmt::format("must lie strictly between 0 and 1, not {}", p.criterion));
}

}  // namespace

ConstantStimuli::ConstantStimuli(ConstantStimuliParams params, std::uint64_t seed) : params_(std::move(params)) {
    validate(params_);
    const std::size_t n = params_.levels.size();
    const auto reps = static_cast<std::size_t>(params_.repetitions);
    Rng rng(seed);
    std::vector<std::size_t> order(n);
    std::iota(order.begin(), order.end(), std::size_t{0});
    switch (params_.order) {
        case ConstantOrder::Blocked:
            rng.shuffle(order);
            for (std::size_t level : order) schedule_.insert(schedule_.end(), reps, level);
            break;
        case ConstantOrder::Passes:
            for (std::size_t r = 0; r < reps; ++r) {
                rng.shuffle(order);
                schedule_.insert(schedule_.end(), order.begin(), order.end());
            }
            break;
        case ConstantOrder::Random:
            for (std::size_t r = 0; r < reps; ++r) schedule_.insert(schedule_.end(), order.begin(), order.end());
            rng.shuffle(schedule_);
            break;
    }
    shown_.assign(n, 0);
    yes_.assign(n, 0);
}

std::optional<Proposal> ConstantStimuli::next() const {
    if (finished()) return std::nullopt;
    Proposal p;
    p.level = params_.levels[schedule_[answered_]];
    p.trial = answered_;
    return p;
}

void ConstantStimuli::do_record(Response r) {
    const bool y = detail::require_binary(r, kind());
    const std::size_t level = schedule_[answered_];
    ++shown_[level];
    if (y) ++yes_[level];
    ++answered_;
}

Estimate ConstantStimuli::estimate() const {
    Estimate e;
    e.n = answered_;
    e.method = fmt::format("interpolated {} crossing of the proportion of Yes", params_.criterion);
    std::vector<std::size_t> idx(params_.levels.size());
    std::iota(idx.begin(), idx.end(), std::size_t{0});
    std::sort(idx.begin(), idx.end(),
              [&](std::size_t a, std::size_t b) { return params_.levels[a] < params_.levels[b]; });
    std::vector<std::size_t> seen;
    for (std::size_t i : idx)
        if (shown_[i] > 0) seen.push_back(i);
    const double c = params_.criterion;
    for (std::size_t k = 0; k + 1 < seen.size(); ++k) {
        const std::size_t a = seen[k], b = seen[k + 1];
        const double pa = static_cast<double>(yes_[a]) / shown_[a];
        const double pb = static_cast<double>(yes_[b]) / shown_[b];
        if (pa == c) {
            e.value = params_.levels[a];
            return e;
        }
        if ((pa - c) * (pb - c) < 0.0) {
            const double xa = params_.levels[a], xb = params_.levels[b];
            e.value = xa + (c - pa) / (pb - pa) * (xb - xa);
            return e;
        }
    }
    if (!seen.empty()) {
        const std::size_t last = seen.back();
        if (static_cast<double>(yes_[last]) / shown_[last] == c) e.value = params_.levels[last];
    }
    return e;
}

std::string ConstantStimuli::state() const {
    return fmt::format("{} trial={} of {} schedule={:016x} shown={:016x} yes={:016x}", kind(), answered_,
                       schedule_.size(), detail::hash_ints(schedule_), detail::hash_ints(shown_),
                       detail::hash_ints(yes_));
}

}  // namespace atonlab::protocols
