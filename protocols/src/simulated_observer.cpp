// Simulated observers for planning a study (simulated_observer.h).
#include "atonlab/protocols/simulated_observer.h"

#include <fmt/format.h>

#include <array>
#include <boost/math/special_functions/beta.hpp>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace atonlab::protocols {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The keys, their meaning and ranges. The model observer's own keys keep
// ModelObserver's checks (observer.h); the departures' ranges keep each
// model defined (η < 1: ν > 0; a < 1: a stationary AR(1)).
constexpr std::array<ObserverKey, 11> kKeys = {{
    // name, meaning, min, max, min inclusive, max inclusive, departure
    {"noise_sd_log10", "σ: SD of the decision noise, log10 brightness (the slope: a larger σ is a shallower function)",
     0.0, 1.0, true, true, false},
    {"lapse_rate", "λ: the fraction of answers given at random", 0.0, 1.0, true, false, false},
    {"window_radius_deg", "the window a light's brightness is summed over, degrees of visual angle", 0.0, 10.0, false,
     true, false},
    {"exponent", "p: brightness = E^p (Stevens 1961)", 0.0, 2.0, false, true, false},
    {"detection_threshold_lux", "yes-no: the increment illuminance seen half the time, lux", 0.0, 1.0, false, true,
     false},
    {"bias_log10", "the PSE's shift in the level's units: the observer matches this far above the model", -5.0, 5.0,
     true, true, true},
    {"eta", "η: beta-binomial overdispersion (psignifit 4), 0 = binomial", 0.0, 1.0, true, false, true},
    {"learning_log10", "the PSE's drift over the session: learning_log10·(1 − exp(−t/τ)) at trial t", -5.0, 5.0, true,
     true, true},
    {"learning_tau_trials", "τ: the learning's time constant, trials", 0.0, 1e6, false, true, true},
    {"fluctuation_sd_log10", "σ_f: SD of the PSE's AR(1) fluctuation, level units", 0.0, 5.0, true, true, true},
    {"fluctuation_decay", "a: the AR(1) fluctuation's decay per trial (0: independent trials)", 0.0, 1.0, true, false,
     true},
}};

double* field(SimulatedObserverParams& p, std::string_view key) {
    ModelObserverParams& m = p.model;
    ObserverDepartures& d = p.departures;
    if (key == "noise_sd_log10") return &m.noise_sd_log10;
    if (key == "lapse_rate") return &m.lapse_rate;
    if (key == "window_radius_deg") return &m.window_radius_deg;
    if (key == "exponent") return &m.exponent;
    if (key == "detection_threshold_lux") return &m.detection_threshold_lux;
    if (key == "bias_log10") return &d.bias_log10;
    if (key == "eta") return &d.eta;
    if (key == "learning_log10") return &d.learning_log10;
    if (key == "learning_tau_trials") return &d.learning_tau_trials;
    if (key == "fluctuation_sd_log10") return &d.fluctuation_sd_log10;
    if (key == "fluctuation_decay") return &d.fluctuation_decay;
    return nullptr;
}

std::string key_list() {
    std::string s;
    for (const ObserverKey& k : kKeys) s += (s.empty() ? "" : ", ") + std::string(k.name);
    return s;
}

}  // namespace

std::span<const ObserverKey> observer_keys() noexcept {
    return kKeys;
}

const ObserverKey* find_observer_key(std::string_view name) noexcept {
    for (const ObserverKey& k : kKeys)
        if (k.name == name) return &k;
    return nullptr;
}

void set_observer_key(SimulatedObserverParams& params, std::string_view key, double value,
                      const SourceLocation& where) {
    double* f = field(params, key);
    const ObserverKey* k = find_observer_key(key);
    if (f == nullptr || k == nullptr)
        throw InputError(where, fmt::format("the observer has no key \"{}\"; its keys are {}.", key, key_list()));
    const bool above = k->min_inclusive ? value >= k->min : value > k->min;
    const bool below = k->max_inclusive ? value <= k->max : value < k->max;
    if (!std::isfinite(value) || !above || !below)
        throw InputError(where, fmt::format("the observer's {} must be in {}{}, {}{}, not {} ({}).", key,
                                            k->min_inclusive ? "[" : "(", k->min, k->max,
                                            k->max_inclusive ? "]" : ")", value, k->meaning));
    *f = value;
}

SimulatedObserverParams observer_params(const Protocol& protocol) {
    SimulatedObserverParams params;
    for (const ObserverSetting& s : protocol.observer) set_observer_key(params, s.key, s.value, s.where);
    return params;
}

std::vector<std::pair<std::string, double>> observer_values(const SimulatedObserverParams& params) {
    SimulatedObserverParams copy = params;
    std::vector<std::pair<std::string, double>> out;
    for (const ObserverKey& k : kKeys) out.emplace_back(std::string(k.name), *field(copy, k.name));
    return out;
}

ObserverDrift::ObserverDrift(const ObserverDepartures& departures, std::uint64_t seed)
    : d_(departures), rng_(derive_seed(seed, 0x6472696674ULL)) {}  // "drift": a stream of its own

double ObserverDrift::at(std::size_t step) {
    double shift = d_.bias_log10;
    if (d_.learning_log10 != 0.0)
        shift += d_.learning_log10 * (1.0 - std::exp(-static_cast<double>(step) / d_.learning_tau_trials));
    if (d_.fluctuation_sd_log10 > 0.0) {
        const double a = d_.fluctuation_decay, sd = d_.fluctuation_sd_log10;
        while (ar_.size() <= step) {
            const double e = standard_normal_quantile(rng_.uniform() + 0x1.0p-54);
            ar_.push_back(ar_.empty() ? sd * e : a * ar_.back() + sd * std::sqrt(1.0 - a * a) * e);
        }
        shift += ar_[step];
    }
    return shift;
}

double overdispersed_probability(double psi, double eta, std::uint64_t cell_seed) {
    if (eta <= 0.0 || psi <= 0.0 || psi >= 1.0) return psi;
    const double nu = 1.0 / (eta * eta) - 1.0;  // the Beta's concentration (psignifit 4)
    Rng rng(cell_seed);
    const double u = rng.uniform() + 0x1.0p-54;  // in (0, 1)
    return boost::math::ibeta_inv(psi * nu, (1.0 - psi) * nu, u);
}

std::uint64_t observer_cell(std::string_view condition, int arrangement, double level) noexcept {
    std::uint64_t h = 0xcbf29ce484222325ULL;  // FNV-1a, 64 bit
    auto mix = [&h](unsigned char c) {
        h ^= c;
        h *= 0x100000001b3ULL;
    };
    for (char c : condition) mix(static_cast<unsigned char>(c));
    mix(0);
    const auto cell = static_cast<std::int64_t>(std::llround(level * 1e6));
    for (int i = 0; i < 8; ++i) mix(static_cast<unsigned char>((static_cast<std::uint64_t>(cell) >> (8 * i)) & 0xff));
    mix(static_cast<unsigned char>(arrangement));
    return h;
}

Answer simulated_answer(const SimulatedObserverParams& params, Task task, double delta, std::uint64_t trial_seed,
                        std::uint64_t cell_seed) {
    if (task == Task::Adjust) throw std::invalid_argument("a simulated observer answers 2AFC and yes-no trials");
    ModelObserver model(params.model, trial_seed);
    if (params.departures.eta <= 0.0)
        return task == Task::TwoAfc ? model.answer_2afc_delta(delta) : model.answer_yes_no_delta(delta);
    // Beta-binomial: the model's probability ψ of choosing view 0 (saying
    // Yes), lapses included, then the cell's overdispersed draw of it.
    const ModelObserverParams& m = params.model;
    const double sigma = m.noise_sd_log10;
    double phi = 0.5;
    if (!std::isfinite(delta)) {
        phi = delta > 0 ? 1.0 : 0.0;
    } else if (sigma > 0) {
        phi = standard_normal_cdf(delta / sigma);
    } else if (delta != 0) {
        phi = delta > 0 ? 1.0 : 0.0;
    }
    const double psi = 0.5 * m.lapse_rate + (1.0 - m.lapse_rate) * phi;
    const double p = overdispersed_probability(psi, params.departures.eta, cell_seed);
    Rng rng(trial_seed);
    const bool first = rng.uniform() < p;
    const double z = sigma > 0 ? delta / sigma : (delta == 0 ? 0.0 : std::copysign(kInf, delta));
    const double rt = model_response_time_s(m, z);
    if (task == Task::TwoAfc) return {first ? Response::Left : Response::Right, rt};
    return {first ? Response::Yes : Response::No, rt};
}

std::optional<double> decision_at_probability(const ModelObserverParams& params, double p) {
    const double lapse = params.lapse_rate;
    const double q = (p - 0.5 * lapse) / (1.0 - lapse);
    if (!(q > 0.0 && q < 1.0)) return std::nullopt;
    return params.noise_sd_log10 * standard_normal_quantile(q);
}

}  // namespace atonlab::protocols
