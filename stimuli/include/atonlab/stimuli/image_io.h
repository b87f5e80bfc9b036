#pragma once
// Images in and out: OpenEXR for scene-referred (absolute cd/m²) and PSF data,
// PNG for display-encoded output.
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace atonlab::stimuli {

/// An RGBA float image, row 0 at the top, pixels interleaved RGBA.
struct ImageRGBA32F {
    int width = 0;
    int height = 0;
    std::vector<float> rgba;  ///< width * height * 4

    float* pixel(int x, int y) { return &rgba[(static_cast<std::size_t>(y) * width + x) * 4]; }
    const float* pixel(int x, int y) const { return &rgba[(static_cast<std::size_t>(y) * width + x) * 4]; }
};

/// EXR header attributes atonlab writes and reads (docs/architecture.md "Units and colour").
struct ExrMetadata {
    std::string units = "cd/m2";           ///< "cd/m2" for scene-referred images, "relative" for PSFs
    double degrees_per_pixel = 0.0;        ///< visual angle of one pixel at the image centre
    std::optional<double> adaptation_cd_m2;
    std::optional<double> wavelength_nm;   ///< for monochromatic PSFs
    std::map<std::string, std::string> strings;  ///< extra string attributes (e.g. "camera", "scene")
};

enum class ExrPixelType : std::uint8_t { half, float32 };

/// Writes RGBA (A optional: written when write_alpha) with the metadata as header
/// attributes: string "units", float/double "degreesPerPixel", "adaptationLuminance"
/// (cd/m²), "wavelength" (nm), and each extra string. Writes to a temporary file
/// in the same directory and renames it, so a failure leaves no partial file.
/// Throws InputError with the path on failure.
void write_exr(const std::filesystem::path& path, const ImageRGBA32F& image, const ExrMetadata& meta,
               ExrPixelType type = ExrPixelType::float32, bool write_alpha = false);

struct ExrImage {
    ImageRGBA32F image;
    ExrMetadata meta;
    bool has_alpha = false;  ///< the file has an A channel (else A reads as 1)
};
/// Reads R, G, B (and A if present, else 1) of any pixel type, and the attributes above.
ExrImage read_exr(const std::filesystem::path& path);

/// Writes an 8-bit RGB PNG from display-encoded values in [0, 1] (already
/// through the transfer function), rounding to nearest; atomically like write_exr.
void write_png_rgb8(const std::filesystem::path& path, int width, int height,
                    const std::vector<float>& rgb_encoded);
/// Reads an 8-bit or 16-bit PNG as RGB in [0, 1] (for tests and obstacle images).
std::vector<float> read_png_rgb(const std::filesystem::path& path, int& width, int& height);

/// Reads a colour PFM ("PF", W H, a negative scale: little-endian floats, rows
/// bottom first, as pfstools' pfsoutpfm writes it) as linear RGB, top row
/// first, values as stored (no scale applied). Throws InputError with the path
/// when the file is not such a PFM or is shorter than its header says.
std::vector<float> read_pfm_rgb(const std::filesystem::path& path, int& width, int& height);

}  // namespace atonlab::stimuli
