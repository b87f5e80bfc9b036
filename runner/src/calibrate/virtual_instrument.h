#pragma once
// The virtual instrument (docs/calibration.md, "The virtual instrument"): it
// reads back the patch the screen actually shows (glReadPixels of the
// presented frame, a 32 x 32 pixel "aperture" at the centre) and returns the
// XYZ a display law you give predicts for those code values, with optional
// seeded noise. For tests and demos of the whole calibration loop.
#include <glm/vec3.hpp>
#include <memory>
#include <vector>

#include "instrument.h"

namespace atonlab::runner {

/// A display law: drive V in [0, 1] per channel to absolute CIE 1931 XYZ.
/// Each channel c gives f(V_c) = L(V_c) / L(1) of the grey law L, times its
/// sRGB primary (IEC 61966-2-1: Rec. 709 primaries, D65 white), so a grey of
/// drive V has Y = L(V) and chromaticity D65.
class VirtualDisplayLaw {
public:
    /// L(V) = black + (peak − black) V^gamma, cd/m².
    static VirtualDisplayLaw gog(double peak_cd_m2, double black_cd_m2, double gamma);
    /// L(V) linear between the grey readings (black and white included) of a
    /// level,channel,cd_m2 CSV. Throws InputError naming the file.
    static VirtualDisplayLaw lut(const std::string& csv_path);

    /// The grey law L(V), cd/m².
    double grey_cd_m2(double v) const;
    /// XYZ, cd/m², for drive levels (R, G, B) in [0, 1].
    glm::dvec3 xyz_cd_m2(const glm::dvec3& drive) const;
    std::string description() const;

private:
    double peak_ = 0.0, black_ = 0.0, gamma_ = 0.0;
    std::vector<std::pair<double, double>> lut_;  ///< (V, cd/m²), V rising; empty: GOG
    std::string lut_file_;
};

std::unique_ptr<Instrument> open_virtual_instrument(const InstrumentOptions& options);

}  // namespace atonlab::runner
