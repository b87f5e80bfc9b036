#pragma once
// Display calibration: photometer readings (CSV or ArgyllCMS .ti3), their
// checks, gain-offset-gamma fits and the DisplayModel they define
// (docs/display-calibration.md). Luminance in cd/m²; drive levels in [0, 1].
#include <filesystem>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/display/display_model.h"

namespace atonlab::display {

/// Which drive channels a patch lit: one primary, all three equally (grey,
/// including black and white), or anything else.
enum class Channel { red, green, blue, grey, other };

const char* channel_name(Channel c);

/// One photometer reading.
struct Measurement {
    double level;            ///< drive of the lit channel(s), [0, 1]; for `other`, the largest of R, G, B
    Channel channel;         ///< level 0 of any ramp is black: every ramp shares it
    double luminance_cd_m2;  ///< measured luminance Y, cd/m²
    int line;                ///< 1-based line in the file it came from (0 if none)
    glm::dvec3 rgb{};        ///< the patch's drive levels in [0, 1] (R, G, B)
    std::string file{};      ///< the file it came from, for error messages
    /// CIE 1931 XYZ on the absolute scale of luminance_cd_m2 (Y = luminance), when
    /// the file has them (a .ti3 with XYZ_X and XYZ_Z); none for a CSV.
    std::optional<glm::dvec3> xyz_cd_m2{};
};

// ---------------------------------------------------------------------------
// Readers. Errors are InputError with the file, the line and the column or
// field name (SourceLocation::key).

/// How a CSV file's drive levels are written: fractions in [0, 1], 8-bit codes
/// 0..255 (level = code / 255) or 10-bit codes 0..1023 (level = code / 1023).
enum class DriveScale { fraction, bits8, bits10 };

/// "fraction", "8bit", "10bit" (the words of `--drive-scale` and docs/calibration.md).
const char* drive_scale_name(DriveScale scale);
/// The inverse of drive_scale_name; std::nullopt for any other word.
std::optional<DriveScale> drive_scale_from_name(std::string_view name);

struct CalibrationFileOptions {
    /// The scale of a CSV `level` column (`--drive-scale`); unset: fraction. A
    /// column named level_fraction, level_8bit or level_10bit names its own
    /// scale, and a different one here is refused.
    std::optional<DriveScale> drive_scale;
};

/// CSV with a header naming, in any order: the drive level (`level`, or
/// `level_fraction`, `level_8bit`, `level_10bit` naming the scale), `channel`,
/// and the reading: `cd_m2`, `fL` (foot-lamberts, 1 fL = 3.426259 cd/m²) or
/// `X,Y,Z` (CIE 1931 XYZ in cd/m²; Y is the luminance, X and Z are kept).
/// channel is red, green, blue, grey, white (= grey at full drive) or black (=
/// grey at level 0); readings >= 0. `#` starts a comment; blank lines are skipped.
std::vector<Measurement> parse_calibration_csv(std::string_view text, const std::string& file_name,
                                               const CalibrationFileOptions& options = {});
std::vector<Measurement> read_calibration_csv(const std::filesystem::path& path,
                                              const CalibrationFileOptions& options = {});

/// ArgyllCMS .ti3 (CGATS text, identifier CTI3) as written by dispread: fields
/// RGB_R RGB_G RGB_B (0..100) and XYZ_Y. If NORMALIZED_TO_Y_100 is YES the XYZ
/// are relative to white Y = 100 and LUMINANCE_XYZ_CDM2 (absolute XYZ of white,
/// cd/m²) scales them; otherwise XYZ_Y is taken as cd/m². Only the first table
/// is read (dispread appends a CAL table after it). Patches are classified as
/// grey (R = G = B), a single-channel ramp, or other.
std::vector<Measurement> parse_argyll_ti3(std::string_view text, const std::string& file_name);
std::vector<Measurement> read_argyll_ti3(const std::filesystem::path& path);

/// Reads a .csv or .ti3 file, choosing by extension.
/// options.drive_scale applies to a CSV only (a .ti3 gives RGB in percent).
std::vector<Measurement> read_calibration_file(const std::filesystem::path& path,
                                               const CalibrationFileOptions& options = {});

// ---------------------------------------------------------------------------
// Checks and fits.

/// Throws InputError naming the file and line of the first measurement that
/// breaks monotonicity: within each ramp (red, green, blue, grey; black counts
/// in every ramp) ordered by level, a reading more than `relative_tolerance`
/// below the brightest reading at any lower level. The default tolerance (5 %)
/// absorbs photometer noise where neighbouring levels differ by less than the
/// noise (near black): with 1 % noise per reading, the difference of two equal
/// readings has sd 1.4 %, so 5 % is 3.5 sd. Also rejects negative or
/// non-finite luminance and levels outside [0, 1].
void check_monotonic(const std::vector<Measurement>& measurements, double relative_tolerance = 0.05);

/// A GOG fit L(V) = a + (b + k V)^gamma (b + kV > 0, else a), cd/m², as in GogParams.
struct GogFit {
    double a = 0.0, b = 0.0, k = 0.0, gamma = 0.0;
    double rmse_log10 = 0.0;  ///< RMS of log10(measured) - log10(fitted), over the n readings
    int n = 0;                ///< readings used (black included)
};

double gog_luminance_cd_m2(const GogFit& fit, double level);
GogParams gog_params(const GogFit& fit);

/// Least squares in log10 luminance, NLopt BOBYQA within bounds, started from
/// the straight line through log10(L - black) against log10 V (V >= 0.1).
/// `ramp` holds one channel's readings including black (level 0). Throws
/// InputError if it has fewer than 4 distinct levels or does not rise.
GogFit fit_gog(const std::vector<Measurement>& ramp);

/// The slope of log10(L(V) - L(0)) against log10 V over V in [0.1, 1] of the
/// fitted curve (least squares over 46 log-spaced levels): what a display
/// data sheet calls its gamma.
double effective_gamma(const GogFit& fit);

/// One fitted ramp.
struct RampReport {
    Channel channel = Channel::grey;
    GogFit fit;
    double effective_gamma = 0.0;
    double black_cd_m2 = 0.0;  ///< fitted L(0)
    double white_cd_m2 = 0.0;  ///< fitted L(1)
    int levels = 0;            ///< distinct levels measured
};

struct CalibrationReport {
    std::vector<RampReport> ramps;  ///< red, green, blue, grey: those with >= 4 distinct levels
    double black_cd_m2 = 0.0;       ///< measured: mean of the level-0 readings
    double white_cd_m2 = 0.0;       ///< measured: mean grey level-1 reading, else R + G + B at 1 minus 2 black
    double contrast_ratio = 0.0;    ///< white / black (infinite for a zero black)
    int n_measurements = 0;
    int n_other = 0;                 ///< readings of mixed patches: kept, not fitted
    std::vector<std::string> notes;  ///< ramps skipped and why

    const RampReport* ramp(Channel c) const;  ///< nullptr if not fitted
};

/// Checks (check_monotonic) and fits every ramp. Throws InputError when there
/// is no black reading, no white (grey at 1, or all three primaries at 1), or
/// no fittable ramp.
CalibrationReport fit_calibration(const std::vector<Measurement>& measurements);

/// A GOG DisplayModel from the fits: the red, green and blue ramps when all
/// three were fitted (each ramp's reading includes the other two channels'
/// black, so channel c keeps black · w_c of it, w_c its Rec.709 weight, and the
/// channels add up to the measured black), else the grey ramp split into
/// channels by Rec.709 weight. The result is validated.
DisplayModel display_from_calibration(const CalibrationReport& report, std::string name);

}  // namespace atonlab::display
