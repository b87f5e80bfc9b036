// Interleaved procedures (interleaver.h).
#include "atonlab/protocols/interleaver.h"

#include <fmt/format.h>

#include "checks.h"

namespace atonlab::protocols {

std::string_view to_string(InterleaveOrder o) noexcept {
    switch (o) {
        case InterleaveOrder::Random:
            return "random";
        case InterleaveOrder::Sequential:
            return "sequential";
    }
    return "?";
}

InterleaveOrder parse_interleave_order(std::string_view text) {
    if (text == "random") return InterleaveOrder::Random;
    if (text == "sequential") return InterleaveOrder::Sequential;
    throw ProcedureError("interleave", fmt::format("must be \"random\" or \"sequential\", not \"{}\"", text));
}

Interleaver::Interleaver(std::vector<std::unique_ptr<Procedure>> procedures, InterleaveOrder order, std::uint64_t seed)
    : procedures_(std::move(procedures)), order_(order), rng_(seed) {
    detail::require(!procedures_.empty(), "procedures", "an interleaved block needs at least one procedure");
    for (std::size_t i = 0; i < procedures_.size(); ++i) {
        detail::require(procedures_[i] != nullptr, "procedures", fmt::format("procedure {} is missing", i));
        detail::require(procedures_[i]->history().empty(), "procedures",
                        fmt::format("procedure {} ({}) already has responses; interleave fresh procedures", i,
                                    procedures_[i]->kind()));
    }
    current_ = procedures_.size();  // "none yet": sequential order starts at 0
    choose();
}

Interleaver::Interleaver(const Interleaver& other)
    : Procedure(other), order_(other.order_), rng_(other.rng_), current_(other.current_), finished_(other.finished_) {
    procedures_.reserve(other.procedures_.size());
    for (const auto& p : other.procedures_) procedures_.push_back(p->clone());
}

Interleaver& Interleaver::operator=(const Interleaver& other) {
    if (this != &other) {
        Interleaver copy(other);
        *this = std::move(copy);
    }
    return *this;
}

void Interleaver::choose() {
    std::vector<std::size_t> open;
    for (std::size_t i = 0; i < procedures_.size(); ++i)
        if (!procedures_[i]->finished()) open.push_back(i);
    if (open.empty()) {
        finished_ = true;
        return;
    }
    if (order_ == InterleaveOrder::Random) {
        current_ = open[static_cast<std::size_t>(rng_.below(open.size()))];
    } else {
        // The first unfinished procedure after the current one, cyclically.
        const std::size_t n = procedures_.size();
        const std::size_t start = current_ >= n ? 0 : current_ + 1;
        for (std::size_t k = 0; k < n; ++k) {
            const std::size_t i = (start + k) % n;
            if (!procedures_[i]->finished()) {
                current_ = i;
                break;
            }
        }
    }
}

std::optional<Proposal> Interleaver::next() const {
    if (finished_) return std::nullopt;
    std::optional<Proposal> p = procedures_[current_]->next();
    if (p) p->stream = current_;
    return p;
}

bool Interleaver::mid_trial() const {
    return !finished_ && procedures_[current_]->mid_trial();
}

void Interleaver::do_record(Response r) {
    Procedure& p = *procedures_[current_];
    p.record(r);                                 // throws, unchanged, for an answer it cannot take
    if (!p.finished() && p.mid_trial()) return;  // the same procedure continues its trial
    choose();
}

Estimate Interleaver::estimate() const {
    Estimate e;
    for (const auto& p : procedures_)
        if (p->finished()) ++e.n;
    e.method = "none pooled: see each interleaved procedure";
    return e;
}

std::string Interleaver::state() const {
    const auto w = rng_.raw();
    std::string s = fmt::format("{} current={} finished={} rng={:016x}{:016x}{:016x}{:016x}", kind(), current_,
                                finished_ ? 1 : 0, w[0], w[1], w[2], w[3]);
    for (std::size_t i = 0; i < procedures_.size(); ++i) s += fmt::format(" [{}: {}]", i, procedures_[i]->state());
    return s;
}

}  // namespace atonlab::protocols
