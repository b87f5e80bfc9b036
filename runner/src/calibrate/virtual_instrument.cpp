#include "virtual_instrument.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>

#include "patch_screen.h"
#include "atonlab/display/calibration.h"
#include "atonlab/stimuli/error.h"

namespace atonlab::runner {
namespace {

/// Linear sRGB to CIE 1931 XYZ (IEC 61966-2-1:1999, Rec. 709 primaries, D65
/// white): column c is primary c at full drive for white Y = 1.
constexpr double kSrgbToXyz[3][3] = {
    {0.4124, 0.3576, 0.1805},
    {0.2126, 0.7152, 0.0722},
    {0.0193, 0.1192, 0.9505},
};

class Virtual final : public Instrument {
public:
    Virtual(VirtualDisplayLaw law, double noise, unsigned seed) : law_(std::move(law)), noise_(noise), rng_(seed) {}

    std::string description() const override {
        return fmt::format("virtual instrument on a {}{}", law_.description(),
                           noise_ > 0.0 ? fmt::format(", {} % noise", 100.0 * noise_) : std::string());
    }

    double repeatability() const override { return noise_; }

    InstrumentReading read(PatchScreen& screen) override {
        const PatchScreen::Aperture a = screen.read_shown();
        const glm::dvec3 drive = a.mean_codes / static_cast<double>(a.max_code);
        const double factor = noise_ > 0.0 ? 1.0 + noise_ * normal_(rng_) : 1.0;
        InstrumentReading r;
        r.xyz_cd_m2 = law_.xyz_cd_m2(drive) * factor;
        r.transcript = fmt::format(
            "virtual: {} x {} px at the centre of the shown frame, mean codes {:.3f} {:.3f} {:.3f} of {}; noise "
            "factor {:.6f}\nResult is XYZ: {:.6f} {:.6f} {:.6f}",
            a.width_px, a.height_px, a.mean_codes.r, a.mean_codes.g, a.mean_codes.b, a.max_code, factor, r.xyz_cd_m2.x,
            r.xyz_cd_m2.y, r.xyz_cd_m2.z);
        return r;
    }

private:
    VirtualDisplayLaw law_;
    double noise_;
    std::mt19937_64 rng_;
    std::normal_distribution<double> normal_;
};

}  // namespace

VirtualDisplayLaw VirtualDisplayLaw::gog(double peak_cd_m2, double black_cd_m2, double gamma) {
    VirtualDisplayLaw l;
    l.peak_ = peak_cd_m2;
    l.black_ = black_cd_m2;
    l.gamma_ = gamma;
    return l;
}

VirtualDisplayLaw VirtualDisplayLaw::lut(const std::string& csv_path) {
    const std::vector<display::Measurement> ms = display::read_calibration_csv(csv_path);
    std::map<double, std::pair<double, int>> grey;  // level -> (sum, n): repeated levels are averaged
    for (const display::Measurement& m : ms)
        if (m.channel == display::Channel::grey) {
            auto& [sum, n] = grey[m.level];
            sum += m.luminance_cd_m2;
            ++n;
        }
    if (grey.size() < 2 || grey.begin()->first != 0.0 || grey.rbegin()->first != 1.0)
        throw InputError(
            SourceLocation{csv_path, 0, 0, "--virtual-lut"},
            "the display law needs grey readings at level 0 (black) and level 1 (white), and any between.");
    VirtualDisplayLaw l;
    for (const auto& [level, s] : grey) l.lut_.emplace_back(level, s.first / s.second);
    l.lut_file_ = csv_path;
    l.peak_ = l.lut_.back().second;
    l.black_ = l.lut_.front().second;
    if (!(l.peak_ > 0.0))
        throw InputError(SourceLocation{csv_path, 0, 0, "--virtual-lut"}, "white must be brighter than 0 cd/m².");
    return l;
}

double VirtualDisplayLaw::grey_cd_m2(double v) const {
    v = std::clamp(v, 0.0, 1.0);
    if (lut_.empty()) return black_ + (peak_ - black_) * std::pow(v, gamma_);
    const auto hi = std::lower_bound(lut_.begin(), lut_.end(), v,
                                     [](const std::pair<double, double>& p, double x) { return p.first < x; });
    if (hi == lut_.begin()) return hi->second;
    const auto lo = hi - 1;
    const double t = (v - lo->first) / (hi->first - lo->first);
    return lo->second + t * (hi->second - lo->second);
}

glm::dvec3 VirtualDisplayLaw::xyz_cd_m2(const glm::dvec3& drive) const {
    glm::dvec3 xyz{0.0};
    for (int c = 0; c < 3; ++c) {
        const double f = peak_ > 0.0 ? grey_cd_m2(drive[c]) / peak_ : 0.0;
        for (int row = 0; row < 3; ++row) xyz[row] += peak_ * kSrgbToXyz[row][c] * f;
    }
    return xyz;
}

std::string VirtualDisplayLaw::description() const {
    if (!lut_.empty())
        return fmt::format("display whose grey law is {} ({} levels, {:.4g} to {:.4g} cd/m²)", lut_file_, lut_.size(),
                           black_, peak_);
    return fmt::format("GOG display, black {:.4g} cd/m², peak {:.4g} cd/m², gamma {:.4g}", black_, peak_, gamma_);
}

std::unique_ptr<Instrument> open_virtual_instrument(const InstrumentOptions& o) {
    VirtualDisplayLaw law = o.virtual_lut.empty()
                                ? VirtualDisplayLaw::gog(o.virtual_peak_cd_m2, o.virtual_black_cd_m2, o.virtual_gamma)
                                : VirtualDisplayLaw::lut(o.virtual_lut);
    return std::make_unique<Virtual>(std::move(law), o.virtual_noise, o.virtual_seed);
}

}  // namespace atonlab::runner
