#pragma once
// The display model and the display encoder: the last stage of the pipeline
// (docs/architecture.md "The pipeline, one frame" step 6). Input is display-referred *linear* Rec.709 RGB
// relative to the display's white (1 = the channel's full-drive luminance; the
// tone mapper produces it); output is the integer code values that make a
// calibrated display emit the intended luminance, dithered to the frame
// buffer's bit depth. docs/display-calibration.md describes the models, the
// dither and the GPU twin (stimuli/shaders/display_encode.glsl).
//
// Units: luminance in cd/m²; drive levels V in [0, 1] (code / (2^bits − 1)).
#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/common/input_error.h"
#include "atonlab/display/gamut.h"

namespace atonlab::display {

struct DisplayEncoding;  // display_encodings.h: a law a channel follows, and its parameters
/// sRGB's encoding (display/src/encodings/srgb.cpp), a channel's unless set.
const DisplayEncoding& display_encoding_srgb();

/// The most parameters an encoding has of its own (ChannelEncoding::parameter).
inline constexpr std::size_t kEncodingParameters = 6;

/// GOG with black offset: L(V) = a + (b + k·V)^gamma where b + k·V > 0, else a.
/// a is in cd/m²; b and k are in (cd/m²)^(1/gamma), so (b + k)^gamma is the
/// channel's full-drive luminance above the offset.
struct GogParams {
    double a = 0.0;
    double b = 0.0;
    double k = 1.0;
    double gamma = 2.2;
};

struct ChannelEncoding;
/// A gog channel's parameters (ChannelEncoding::parameter, in this order).
GogParams gog_params_of(const ChannelEncoding& channel);

/// One measured point of a LUT channel.
struct LutPoint {
    double drive;  ///< V in [0, 1]
    double cd_m2;  ///< the channel's luminance at that drive
};

/// How one channel (red, green or blue) turns a drive level V in [0, 1] into
/// luminance (cd/m²): its encoding (the law) and the law's parameters. A channel is
/// self-contained: it knows its own black and white luminance.
struct ChannelEncoding {
    const DisplayEncoding* encoding = &display_encoding_srgb();
    /// The laws a black and a white define (srgb, pq): the channel's luminance at V = 0
    /// (its share of the display's black), cd/m².
    double black_cd_m2 = 0.0;
    /// ...and at V = 1 (its share of the display's peak), cd/m².
    double white_cd_m2 = 0.0;
    /// The encoding's own parameters, in the order its declaration lists them
    /// (DisplayEncoding::parameters): gog's a, b, k, gamma (GogParams); pq's weight,
    /// the channel's share of an achromatic stimulus: L(V) = clamp(weight · EOTF(V), black, white).
    std::array<double, kEncodingParameters> parameter{};
    std::vector<LutPoint>
        lut;  ///< the knots of a law that has them (lut): drive strictly increasing from 0 to 1, cd/m² non-decreasing

    /// L(V) in cd/m². V is clamped to [0, 1]; NaN is taken as 0.
    double luminance_cd_m2(double drive) const;
    /// The smallest drive V in [0, 1] whose luminance is L (clamped to the
    /// channel's range first). Closed form for srgb, gog and pq; for lut the
    /// exact inverse of the monotone cubic (a safeguarded Newton solve, ~1e-14).
    double drive_for(double L_cd_m2) const;
    double min_cd_m2() const;  ///< L(0)
    double max_cd_m2() const;  ///< L(1)
    /// Whether the channel follows the encoding of that name.
    bool follows(std::string_view encoding_name) const;
};

/// A display: per-channel encodings and the whole-screen peak and
/// black (R = G = B = 1 and 0). The channels add: what the screen emits for a
/// code triple is the sum of the three channels' luminances.
struct DisplayModel {
    std::string name = "sRGB";
    double peak_cd_m2 = 100.0;  ///< luminance of full white (all channels at V = 1), cd/m²
    double black_cd_m2 = 0.0;   ///< luminance of black (all channels at V = 0), cd/m²
    std::array<ChannelEncoding, 3> channels;

    /// An sRGB display: each channel follows IEC 61966-2-1 scaled between its
    /// Rec.709 share (0.2126 / 0.7152 / 0.0722) of black and of peak.
    static DisplayModel srgb(double peak_cd_m2, double black_cd_m2, std::string name = "sRGB");
    /// An HDR display driven with SMPTE ST 2084 (PQ) code values, absolute: a
    /// code means the same cd/m² on every PQ display, clipped to this one's black
    /// and peak (peak <= 10000 cd/m²).
    static DisplayModel pq(double peak_cd_m2, double black_cd_m2 = 0.0, std::string name = "PQ");
    /// A GOG display (encodings/gog.cpp); peak and black are the sums of the channels' L(1) and L(0).
    static DisplayModel gog(const std::array<GogParams, 3>& channels, std::string name = "GOG");
    /// A measured-LUT display; peak and black are the sums of the channels' L(1) and L(0).
    static DisplayModel lut(const std::array<std::vector<LutPoint>, 3>& channels, std::string name = "LUT");

    /// Sets peak and black to the sums of the channels' L(1) and L(0) (a fitted display's).
    void sum_channels();

    /// Throws InputError for a display that cannot be encoded for: peak not
    /// positive, black negative or not below peak, a LUT that is not strictly
    /// increasing in drive or decreases in luminance (naming the entry), GOG
    /// parameters giving a NaN, flat or decreasing curve. `where` (file, line,
    /// key prefix) says where the display was defined; keys name the field,
    /// e.g. "black_cd_m2", "green.lut[3].cd_m2", "red.gog.gamma".
    void validate(const SourceLocation& where = {}) const;

    /// Channel c's luminance (cd/m²) at drive V.
    double channel_luminance_cd_m2(int channel, double drive) const;
    /// The drive (clamped to [0, 1]) that makes channel c emit L cd/m².
    double drive_for_luminance(int channel, double L_cd_m2) const;
};

// ---------------------------------------------------------------------------
// SMPTE ST 2084:2014 (PQ), absolute: signal N in [0, 1] <-> luminance 0..10000 cd/m².

/// EOTF: signal -> cd/m². Inputs are clamped to [0, 1].
double pq_eotf_cd_m2(double signal);
/// Inverse EOTF: cd/m² -> signal in [0, 1]. Inputs are clamped to [0, 10000].
double pq_inverse_eotf(double L_cd_m2);

// ---------------------------------------------------------------------------
// The encoder.

enum class Dither {
    none,            ///< round to nearest
    spatiotemporal,  ///< 64×64 Bayer tile shifted per frame by the golden ratio (docs/display-calibration.md)
};

struct EncodeSettings {
    int bits = 8;  ///< frame buffer bits per channel, 1..16 (8 or 10 in practice)
    Dither dither = Dither::spatiotemporal;
    std::uint32_t seed = 0;  ///< decorrelates the pattern between runs and channels
    /// display.out_of_gamut: what a colour the display cannot show gives up (gamut.h).
    OutOfGamut out_of_gamut = OutOfGamut::keep_luminance;
};

/// Encodes one pixel. relative_rgb is linear Rec.709 relative to the display's
/// white: channel c should emit relative_rgb[c] · channel c's L(1). A colour the
/// display cannot show is brought into the gamut by settings.out_of_gamut
/// (fit_to_gamut with channel_weights(display)); under the default, keep_luminance,
/// it gives up chroma and keeps its luminance: NaN and negative channels are black,
/// a colour with a channel above 1 moves towards the grey of its luminance, and one
/// at or above white luminance is white. Each channel's
/// target is then clipped to [L(0), L(1)], inverted through its encoding's law
/// and quantised to `bits` with the dither offset. Codes are always in
/// [0, 2^bits − 1]. Throws InputError for bits outside 1..16.
/// The display's channel weights: each channel's white luminance L(1) over the sum of
/// the three (they sum to 1). Rec.709's (0.2126, 0.7152, 0.0722) for srgb() and pq().
glm::dvec3 channel_weights(const DisplayModel& display);

glm::ivec3 encode_pixel(const DisplayModel& display, glm::dvec3 relative_rgb, glm::ivec2 pixel, std::uint32_t frame,
                        const EncodeSettings& settings);

/// The dither threshold for (pixel, frame, channel, seed), in [0, 1) with 24-bit
/// resolution: code = floor(V · (2^bits − 1) + threshold). Dither::none uses 0.5.
/// Integer arithmetic only, identical to display_dither_threshold() in display_encode.glsl.
double dither_threshold(glm::ivec2 pixel, std::uint32_t frame, int channel, std::uint32_t seed);

/// What the screen emits per channel (cd/m²) for a code triple at `bits`
/// (codes clamped to [0, 2^bits − 1]).
glm::dvec3 displayed_luminance_rgb(const DisplayModel& display, glm::ivec3 code, int bits);
/// The sum of displayed_luminance_rgb: the luminance of the pixel, cd/m².
double displayed_luminance_cd_m2(const DisplayModel& display, glm::ivec3 code, int bits);

// ---------------------------------------------------------------------------
// The GPU twin's parameters. These structs have the layout of the GLSL
// `DisplayParams` in stimuli/shaders/display_encode.glsl under both std140 (UBO) and
// std430 (SSBO) rules: upload them byte for byte.
// Plain data without GL: they stay next to the laws they pack (gpu_display_lut
// holds the CPU model's own PCHIP slopes); stimuli's display pipeline uploads them.

struct GpuDisplayChannel {
    double black_cd_m2;   ///< L(0), as min_cd_m2()
    double white_cd_m2;   ///< L(1), as max_cd_m2()
    double parameter[6];  ///< p0 … p5: the encoding's parameters as it packs them (DisplayEncoding::gpu_parameters)
    std::int32_t kind;    ///< the encoding's place in display_encodings() (display_encoding_index)
    std::int32_t lut_first;  ///< index of this channel's first knot in the knots buffer (gpu_display_lut)
    std::int32_t lut_count;  ///< number of knots
    std::int32_t pad;
};
static_assert(sizeof(GpuDisplayChannel) == 80);

struct GpuDisplayParams {
    GpuDisplayChannel channel[3];
    std::int32_t bits;
    std::int32_t dither;  ///< Dither as an int
    std::uint32_t seed;
    std::uint32_t out_of_gamut;  ///< OutOfGamut as a uint
};
static_assert(sizeof(GpuDisplayParams) == 256);

/// The encoder's parameters for the GPU (validates the display and the bits).
GpuDisplayParams gpu_display_params(const DisplayModel& display, const EncodeSettings& settings);
/// The knots of all channels whose encoding has them, for the SSBO at
/// DISPLAY_LUT_BINDING: three doubles per knot as the encoding packs them (lut:
/// drive, cd/m², PCHIP slope dL/dV), channels in order, indexed by
/// GpuDisplayChannel::lut_first. Never empty (one dummy knot when no channel has
/// knots) so that a buffer can always be bound.
std::vector<double> gpu_display_lut(const DisplayModel& display);

}  // namespace atonlab::display
