#include "instrument_session.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numeric>

namespace atonlab::runner {
namespace {

using Clock = std::chrono::steady_clock;

/// Keeps the window alive for `seconds`; false when the operator gave up.
bool settle(PatchScreen& screen, double seconds) {
    const auto until =
        Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
    while (Clock::now() < until && !screen.quit_requested()) screen.pump();
    return !screen.quit_requested();
}

/// Why a reading cannot be used, or "": finite and not negative, but for the
/// scatter of a meter at black (an OLED's black reads 0, a colorimeter's
/// correction matrix can put X or Z a little below it).
std::string refused(const glm::dvec3& xyz) {
    for (int i = 0; i < 3; ++i)
        if (!std::isfinite(xyz[i]) || xyz[i] < -InstrumentOptions::kRepeatFloorCdM2)
            return fmt::format("{} = {} cd/m² is not a reading (finite, >= -{} cd/m²)", "XYZ"[i], xyz[i],
                               InstrumentOptions::kRepeatFloorCdM2);
    return {};
}

}  // namespace

std::optional<std::vector<PhotometerReading>> measure_with_instrument(const std::vector<Patch>& patches,
                                                                      PatchScreen& screen, Instrument& instrument,
                                                                      const InstrumentOptions& o, bool quiet) {
    const std::size_t n = patches.size();
    std::vector<PhotometerReading> out;
    if (!quiet)
        std::printf("measuring with the %s: %d readings a patch after %g s to settle\n",
                    instrument.description().c_str(), o.repeats, o.settle_s);
    for (std::size_t i = 0; i < n; ++i) {
        const Patch& p = patches[i];
        const std::string where = fmt::format("patch \"{}\" ({} of {})", p.name, i + 1, n);
        screen.show(p);
        screen.set_progress(fmt::format("atonlab calibrate: patch {}/{}, {}", i + 1, n, p.description()));
        std::string transcript;
        std::optional<PhotometerReading> accepted;
        std::string why;
        for (int attempt = 1; attempt <= o.attempts && !accepted; ++attempt) {
            if (!settle(screen, o.settle_s)) return std::nullopt;
            std::vector<glm::dvec3> xyz;
            why.clear();
            for (int k = 0; k < o.repeats; ++k) {
                InstrumentReading r;
                try {
                    r = instrument.read(screen);
                } catch (const InstrumentError& e) {
                    throw InstrumentError(fmt::format("{} at {}", e.what(), where));
                }
                if (screen.quit_requested()) return std::nullopt;
                transcript += fmt::format("{}--- attempt {}, reading {} of {}\n{}", transcript.empty() ? "" : "\n",
                                          attempt, k + 1, o.repeats, r.transcript);
                if (why = refused(r.xyz_cd_m2); !why.empty()) break;
                xyz.push_back(r.xyz_cd_m2);
            }
            if (why.empty()) {
                const glm::dvec3 mean =
                    std::accumulate(xyz.begin(), xyz.end(), glm::dvec3(0.0)) / static_cast<double>(xyz.size());
                double lo = xyz.front().y, hi = lo, ss = 0.0;
                for (const glm::dvec3& v : xyz) {
                    lo = std::min(lo, v.y);
                    hi = std::max(hi, v.y);
                    ss += (v.y - mean.y) * (v.y - mean.y);
                }
                const double allowed =
                    o.repeat_tolerance_percent / 100.0 * mean.y + InstrumentOptions::kRepeatFloorCdM2;
                if (hi - lo <= allowed) {
                    const double m = static_cast<double>(xyz.size());
                    // Standard uncertainty of the mean: the repeats' own scatter (GUM
                    // type A), not below the instrument's stated repeatability (type B).
                    const double type_a = xyz.size() > 1 ? std::sqrt(ss / (m - 1.0) / m) : 0.0;
                    const double type_b = instrument.repeatability() * mean.y / std::sqrt(m);
                    PhotometerReading r;
                    r.luminance_cd_m2 = std::max(mean.y, 0.0);  // black's scatter below 0 is 0 cd/m²
                    r.xyz_cd_m2 = mean;
                    r.uncertainty_cd_m2 = std::max(type_a, type_b);
                    accepted = r;
                } else {
                    why = fmt::format("its {} readings span {:.5g} to {:.5g} cd/m², more than {} % + {} cd/m² apart",
                                      xyz.size(), lo, hi, o.repeat_tolerance_percent,
                                      InstrumentOptions::kRepeatFloorCdM2);
                }
            }
            if (!accepted && attempt < o.attempts)
                std::printf("  %s: %s; measuring it again (attempt %d of %d)\n", p.name.c_str(), why.c_str(),
                            attempt + 1, o.attempts);
        }
        if (!accepted)
            throw InstrumentError(fmt::format(
                "{} could not be measured in {} attempts ({}): is the instrument held still on the screen and the "
                "display warmed up",
                where, o.attempts, why));
        accepted->transcript = std::move(transcript);
        if (!quiet)
            std::printf("  %2zu/%zu %-28s Y %.6g ± %.3g cd/m² (X %.5g Z %.5g)\n", i + 1, n, p.description().c_str(),
                        accepted->luminance_cd_m2, *accepted->uncertainty_cd_m2, accepted->xyz_cd_m2->x,
                        accepted->xyz_cd_m2->z);
        std::fflush(stdout);
        out.push_back(std::move(*accepted));
    }
    screen.set_progress("atonlab calibrate: measured");
    return out;
}

}  // namespace atonlab::runner
