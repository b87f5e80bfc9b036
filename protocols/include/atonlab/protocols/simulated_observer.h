#pragma once
// Simulated observers for planning a study (docs/simulate.md): the model
// observer's decision (observer.h) with the departures from an ideal,
// stationary observer that psignifit 4's simulate_data offers (Schütt,
// Harmeling, Macke & Wichmann 2016, Vision Research 122:105-123): a bias,
// beta-binomial overdispersion, learning and a fluctuating threshold
// (Fründ, Haenel & Wichmann 2011, JoV 11(6):16). Every departure is 0 by
// default, which is the model observer itself.
//
// Each departure acts on the level the observer perceives, in the level's own
// units (log10 units for level_scale = "log10", as every example protocol
// has): a trial shown at level x is judged as the model judges level
// x − shift(t), so the observer's PSE (or threshold) at trial t lies shift(t)
// above the model's.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "atonlab/common/input_error.h"
#include "atonlab/protocols/observer.h"
#include "atonlab/protocols/rng.h"

namespace atonlab::protocols {

struct ObserverDepartures {
    /// The PSE's shift, level units: the observer matches at the model's PSE + bias_log10.
    double bias_log10 = 0.0;
    /// Beta-binomial overdispersion η, 0 <= η < 1: at each distinct level of a
    /// condition and arrangement the session's probability of each answer is
    /// drawn once from Beta(ψν, (1 − ψ)ν), ν = 1/η² − 1, ψ the model's
    /// probability (psignifit 4's beta-binomial observer; its variance is
    /// η²·ψ(1 − ψ) for η → 0 … ψ(1 − ψ) for η → 1).
    double eta = 0.0;
    /// Learning: the PSE moves by learning_log10 · (1 − exp(−t / learning_tau_trials))
    /// at the session's trial t (negative: the match falls as the observer learns).
    double learning_log10 = 0.0;
    double learning_tau_trials = 50.0;  ///< the learning's time constant, trials (> 0)
    /// Fluctuation: an AR(1) shift x_t = a·x_{t−1} + σ·√(1 − a²)·ε_t with
    /// x_0 = σ·ε_0, so its SD is σ at every trial (σ = fluctuation_sd_log10,
    /// a = fluctuation_decay, 0 <= a < 1).
    double fluctuation_sd_log10 = 0.0;
    double fluctuation_decay = 0.9;

    /// True when nothing but the bias departs from the model observer (a
    /// rendered session can then be answered by the model itself).
    bool only_bias() const noexcept {
        return eta == 0.0 && learning_log10 == 0.0 && fluctuation_sd_log10 == 0.0;
    }
    friend bool operator==(const ObserverDepartures&, const ObserverDepartures&) = default;
};

/// The observer a protocol's [observer] table and `--observer KEY=VALUE` describe.
struct SimulatedObserverParams {
    ModelObserverParams model;
    ObserverDepartures departures;
};

/// The protocol's [observer] table applied over the defaults (each value was
/// checked when the file was read).
SimulatedObserverParams observer_params(const Protocol& protocol);

/// One key of the observer table: its name, what it means (docs, help) and its range.
struct ObserverKey {
    std::string_view name;
    std::string_view meaning;
    double min;
    double max;
    bool min_inclusive;
    bool max_inclusive;
    /// A departure from the stationary model observer (atonlab simulate's
    /// alone); false for the model observer's own keys.
    bool departure;
};

/// The key called `name`, or nullptr.
const ObserverKey* find_observer_key(std::string_view name) noexcept;

/// Every key of the observer table, in the order the docs list them.
std::span<const ObserverKey> observer_keys() noexcept;

/// Sets `key` to `value`; throws InputError at `where` for an unknown key
/// (with the keys it takes) or a value out of its range.
void set_observer_key(SimulatedObserverParams& params, std::string_view key, double value, const SourceLocation& where);

/// Every key's value, in observer_keys() order (what a simulated session stores).
std::vector<std::pair<std::string, double>> observer_values(const SimulatedObserverParams& params);

/// The shift of the observer's PSE at each step of a session (level units):
/// bias + learning + the fluctuation's AR(1) state. A pure function of
/// (departures, seed, step), so a session recomputed from its seed sees the
/// same shifts.
class ObserverDrift {
public:
    ObserverDrift(const ObserverDepartures& departures, std::uint64_t seed);
    /// The shift at the session's step `step` (0-based).
    double at(std::size_t step);

private:
    ObserverDepartures d_;
    Rng rng_;
    std::vector<double> ar_;  ///< the fluctuation's state at steps 0 … size − 1
};

/// The overdispersed probability of an answer (beta-binomial, η > 0): the
/// session's draw for the cell `cell_seed` (one per condition, arrangement and
/// level) from Beta(ψν, (1 − ψ)ν). ψ itself for η = 0. Pure.
double overdispersed_probability(double psi, double eta, std::uint64_t cell_seed);

/// A stable 64-bit key of (condition, arrangement, level rounded to 1e-6): the
/// beta-binomial observer's cell (FNV-1a; the same on every platform).
std::uint64_t observer_cell(std::string_view condition, int arrangement, double level) noexcept;

/// The answer of a simulated observer to a 2AFC or yes-no trial whose
/// noiseless decision variable at the perceived level is `delta` (observer.h:
/// 2AFC log10 B(view 0) − log10 B(view 1); yes-no p·log10(E_inc / E_θ),
/// −∞ for no increment). With η = 0 this is ModelObserver's answer from the
/// same seed, draw for draw; with η > 0 one uniform draw against the cell's
/// overdispersed probability. Throws std::invalid_argument for an adjust task.
Answer simulated_answer(const SimulatedObserverParams& params, Task task, double delta, std::uint64_t trial_seed,
                        std::uint64_t cell_seed);

/// The decision variable at which the model chooses view 0 (2AFC) or says Yes
/// with probability p (lapses included): σ·Φ⁻¹((p − λ/2)/(1 − λ)); none when
/// p is out of the lapses' reach.
std::optional<double> decision_at_probability(const ModelObserverParams& params, double p);

}  // namespace atonlab::protocols
