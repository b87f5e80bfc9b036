// Images in and out (image_io.h): OpenEXR for scene-referred data, PNG for
// display-encoded frames. Every writer goes through AtomicFile so that a
// failure never leaves a partial file at the destination (docs/architecture.md "Errors and what is kept").
#include "atonlab/stimuli/image_io.h"

#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfDoubleAttribute.h>
#include <OpenEXR/ImfFloatAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <fmt/format.h>
#include <png.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <exception>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "atonlab/common/atomic_file.h"
#include "atonlab/stimuli/error.h"

namespace atonlab::stimuli {
namespace {

namespace fs = std::filesystem;

// Header attribute names (docs/architecture.md "Units and colour").
constexpr const char* kUnits = "units";
constexpr const char* kDegreesPerPixel = "degreesPerPixel";
constexpr const char* kAdaptation = "adaptationLuminance";
constexpr const char* kWavelength = "wavelength";

[[noreturn]] void fail(const fs::path& path, const std::string& reason) {
    throw InputError(SourceLocation{path.string(), 0, 0, ""}, reason);
}

std::string errno_text(int err) {
    return std::error_code(err, std::generic_category()).message();
}

/// common's AtomicFile, whose failures become this library's InputError
/// naming the file.
class AtomicFile {
public:
    explicit AtomicFile(const fs::path& destination) try : file_(destination) {
    } catch (const files::WriteError& e) {
        fail(e.path(), e.reason());
    }
    const fs::path& temp_path() const { return file_.temp_path(); }
    int release_fd() { return file_.release_fd(); }
    void close_fd() { file_.close_fd(); }
    void commit() {
        try {
            file_.commit();
        } catch (const files::WriteError& e) {
            fail(e.path(), e.reason());
        }
    }

private:
    files::AtomicFile file_;
};

bool is_reserved_exr_attribute(const std::string& name) {
    static const char* const reserved[] = {
        kUnits,       kDegreesPerPixel, kAdaptation, kWavelength,        "channels",           "compression",
        "dataWindow", "displayWindow",  "lineOrder", "pixelAspectRatio", "screenWindowCenter", "screenWindowWidth",
        "tiles",      "type",           "name",      "version",          "chunkCount"};
    return std::any_of(std::begin(reserved), std::end(reserved), [&](const char* r) { return name == r; });
}

void check_image(const ImageRGBA32F& image) {
    if (image.width <= 0 || image.height <= 0)
        throw std::invalid_argument(fmt::format("image size {}x{} is empty", image.width, image.height));
    if (image.rgba.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 4)
        throw std::invalid_argument(fmt::format("image of {}x{} has {} floats, not width*height*4", image.width,
                                                image.height, image.rgba.size()));
}

// ---------------------------------------------------------------------------
// libpng reports errors by longjmp. A longjmp may not skip a C++ destructor, so
// the functions that call setjmp below own nothing with one: buffers are
// allocated by their callers and passed in as raw pointers, and the png structs
// are destroyed by a guard in the caller's frame.

struct PngJob {
    png_structp png = nullptr;
    png_infop info = nullptr;
    char error[256] = {};
};

void png_error_to_job(png_structp png, png_const_charp message) {
    auto* job = static_cast<PngJob*>(png_get_error_ptr(png));
    std::snprintf(job->error, sizeof job->error, "%s", message != nullptr ? message : "unknown libpng error");
    png_longjmp(png, 1);
}

void png_ignore_warning(png_structp /*png*/, png_const_charp /*message*/) {}

bool png_write_rgb8(PngJob& job, std::FILE* fp, png_uint_32 width, png_uint_32 height, png_bytepp rows) {
    if (setjmp(png_jmpbuf(job.png))) return false;
    png_init_io(job.png, fp);
    png_set_IHDR(job.png, job.info, width, height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(job.png, job.info);
    png_write_image(job.png, rows);
    png_write_end(job.png, nullptr);
    return true;
}

struct PngShape {
    png_uint_32 width = 0;
    png_uint_32 height = 0;
    int bit_depth = 0;
    int channels = 0;
    std::size_t row_bytes = 0;
};

/// Reads the header and sets the transforms that turn any PNG into RGB with 8-
/// or 16-bit samples: palette and low-bit grey expanded, grey copied to R=G=B,
/// alpha dropped. No gamma transform: the codes are returned as stored.
bool png_read_shape(PngJob& job, std::FILE* fp, PngShape* shape) {
    if (setjmp(png_jmpbuf(job.png))) return false;
    png_init_io(job.png, fp);
    png_read_info(job.png, job.info);
    png_set_expand(job.png);
    png_set_strip_alpha(job.png);
    png_set_gray_to_rgb(job.png);
    png_set_interlace_handling(job.png);
    png_read_update_info(job.png, job.info);
    shape->width = png_get_image_width(job.png, job.info);
    shape->height = png_get_image_height(job.png, job.info);
    shape->bit_depth = png_get_bit_depth(job.png, job.info);
    shape->channels = png_get_channels(job.png, job.info);
    shape->row_bytes = png_get_rowbytes(job.png, job.info);
    return true;
}

bool png_read_rows(PngJob& job, png_bytepp rows) {
    if (setjmp(png_jmpbuf(job.png))) return false;
    png_read_image(job.png, rows);
    png_read_end(job.png, nullptr);
    return true;
}

struct FileCloser {
    void operator()(std::FILE* f) const {
        if (f != nullptr) std::fclose(f);
    }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

}  // namespace

// ---------------------------------------------------------------------------
// OpenEXR

void write_exr(const std::filesystem::path& path, const ImageRGBA32F& image, const ExrMetadata& meta, ExrPixelType type,
               bool write_alpha) {
    check_image(image);
    for (const auto& [name, value] : meta.strings) {
        if (name.empty() || is_reserved_exr_attribute(name))
            throw std::invalid_argument(fmt::format("EXR string attribute name '{}' is empty or reserved", name));
    }

    const int channels = write_alpha ? 4 : 3;
    const char* const names[] = {"R", "G", "B", "A"};
    const std::size_t pixels = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);

    // Half images are converted once into a planar-interleaved copy; float
    // images are written straight from the caller's buffer.
    std::vector<Imath::half> halves;
    if (type == ExrPixelType::half) {
        halves.resize(pixels * 4);
        for (std::size_t i = 0; i < halves.size(); ++i) halves[i] = Imath::half(image.rgba[i]);
    }

    AtomicFile file(path);
    file.close_fd();  // OpenEXR opens the temporary by name
    try {
        Imf::Header header(image.width, image.height);
        header.compression() = Imf::ZIP_COMPRESSION;  // lossless
        const Imf::PixelType pixel_type = type == ExrPixelType::half ? Imf::HALF : Imf::FLOAT;
        for (int c = 0; c < channels; ++c) header.channels().insert(names[c], Imf::Channel(pixel_type));

        header.insert(kUnits, Imf::StringAttribute(meta.units));
        header.insert(kDegreesPerPixel, Imf::FloatAttribute(static_cast<float>(meta.degrees_per_pixel)));
        if (meta.adaptation_cd_m2)
            header.insert(kAdaptation, Imf::FloatAttribute(static_cast<float>(*meta.adaptation_cd_m2)));
        if (meta.wavelength_nm)
            header.insert(kWavelength, Imf::FloatAttribute(static_cast<float>(*meta.wavelength_nm)));
        for (const auto& [name, value] : meta.strings) header.insert(name, Imf::StringAttribute(value));

        Imf::FrameBuffer frame;
        const Imath::Box2i window = header.dataWindow();
        for (int c = 0; c < channels; ++c) {
            if (type == ExrPixelType::half) {
                frame.insert(names[c], Imf::Slice::Make(Imf::HALF, &halves[static_cast<std::size_t>(c)], window,
                                                        4 * sizeof(Imath::half)));
            } else {
                frame.insert(names[c], Imf::Slice::Make(Imf::FLOAT, &image.rgba[static_cast<std::size_t>(c)], window,
                                                        4 * sizeof(float)));
            }
        }
        Imf::OutputFile out(file.temp_path().c_str(), header);
        out.setFrameBuffer(frame);
        out.writePixels(image.height);
    } catch (const std::exception& e) {
        fail(path, fmt::format("cannot write the EXR image: {}", e.what()));
    }
    file.commit();
}

ExrImage read_exr(const std::filesystem::path& path) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) {
        fail(path, fs::exists(path, ec) ? "cannot read the EXR image: it is not a regular file"
                                        : "cannot read the EXR image: the file does not exist");
    }
    ExrImage result;
    try {
        Imf::InputFile in(path.c_str());
        const Imf::Header& header = in.header();
        const Imath::Box2i window = header.dataWindow();
        const int width = window.max.x - window.min.x + 1;
        const int height = window.max.y - window.min.y + 1;
        if (width <= 0 || height <= 0) fail(path, "the EXR image has an empty data window");

        const Imf::ChannelList& channels = header.channels();
        for (auto it = channels.begin(); it != channels.end(); ++it) {
            if (it.channel().xSampling != 1 || it.channel().ySampling != 1)
                fail(path, fmt::format("channel '{}' of the EXR image is subsampled, which atonlab does not read",
                                       it.name()));
        }
        const bool has_rgb = channels.findChannel("R") || channels.findChannel("G") || channels.findChannel("B");
        const bool has_y = channels.findChannel("Y") != nullptr;
        if (!has_rgb && !has_y) fail(path, "the EXR image has no R, G, B or Y channel");

        ImageRGBA32F& image = result.image;
        image.width = width;
        image.height = height;
        image.rgba.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4, 0.0f);

        // Every pixel type is converted to float by the library; absent channels
        // take the fill value (0 for colour, 1 for alpha).
        Imf::FrameBuffer frame;
        const auto slice = [&](std::size_t offset, double fill) {
            return Imf::Slice::Make(Imf::FLOAT, &image.rgba[offset], window, 4 * sizeof(float), 0, 1, 1, fill);
        };
        if (has_rgb) {
            frame.insert("R", slice(0, 0.0));
            frame.insert("G", slice(1, 0.0));
            frame.insert("B", slice(2, 0.0));
        } else {
            frame.insert("Y", slice(0, 0.0));  // luminance-only: Y into R, copied to G and B below
        }
        frame.insert("A", slice(3, 1.0));
        result.has_alpha = channels.findChannel("A") != nullptr;
        in.setFrameBuffer(frame);
        in.readPixels(window.min.y, window.max.y);
        if (!has_rgb) {
            for (std::size_t i = 0; i < image.rgba.size(); i += 4)
                image.rgba[i + 1] = image.rgba[i + 2] = image.rgba[i];
        }

        ExrMetadata& meta = result.meta;
        meta.units.clear();  // a file that does not say its units has none
        for (auto it = header.begin(); it != header.end(); ++it) {
            const std::string name = it.name();
            const Imf::Attribute& attribute = it.attribute();
            const auto* as_string = dynamic_cast<const Imf::StringAttribute*>(&attribute);
            const auto* as_float = dynamic_cast<const Imf::FloatAttribute*>(&attribute);
            const auto* as_double = dynamic_cast<const Imf::DoubleAttribute*>(&attribute);
            std::optional<double> number;
            if (as_float) number = static_cast<double>(as_float->value());
            if (as_double) number = as_double->value();

            if (name == kUnits && as_string) {
                meta.units = as_string->value();
            } else if (name == kDegreesPerPixel && number) {
                meta.degrees_per_pixel = *number;
            } else if (name == kAdaptation && number) {
                meta.adaptation_cd_m2 = number;
            } else if (name == kWavelength && number) {
                meta.wavelength_nm = number;
            } else if (as_string) {
                meta.strings[name] = as_string->value();
            }
        }
    } catch (const InputError&) {
        throw;
    } catch (const std::exception& e) {
        fail(path, fmt::format("cannot read the EXR image: {}", e.what()));
    }
    return result;
}

// ---------------------------------------------------------------------------
// PNG

void write_png_rgb8(const std::filesystem::path& path, int width, int height, const std::vector<float>& rgb_encoded) {
    if (width <= 0 || height <= 0) throw std::invalid_argument(fmt::format("PNG size {}x{} is empty", width, height));
    const std::size_t w = static_cast<std::size_t>(width);
    const std::size_t h = static_cast<std::size_t>(height);
    if (rgb_encoded.size() != w * h * 3)
        throw std::invalid_argument(
            fmt::format("PNG of {}x{} given {} values, not width*height*3", width, height, rgb_encoded.size()));

    std::vector<png_byte> bytes(rgb_encoded.size());
    for (std::size_t i = 0; i < bytes.size(); ++i) {
        const float v = rgb_encoded[i];
        // NaN -> 0; the rest clamped to [0, 1] and rounded to the nearest code.
        const float clamped = std::isnan(v) ? 0.0f : std::clamp(v, 0.0f, 1.0f);
        bytes[i] = static_cast<png_byte>(std::lround(clamped * 255.0f));
    }
    std::vector<png_bytep> rows(h);
    for (std::size_t y = 0; y < h; ++y) rows[y] = &bytes[y * w * 3];

    AtomicFile file(path);
    FilePtr fp(::fdopen(file.release_fd(), "wb"));
    if (!fp) fail(path, fmt::format("cannot open the temporary file for writing: {}", errno_text(errno)));

    PngJob job;
    job.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &job, png_error_to_job, png_ignore_warning);
    if (job.png != nullptr) job.info = png_create_info_struct(job.png);
    const bool ok = job.info != nullptr && png_write_rgb8(job, fp.get(), static_cast<png_uint_32>(width),
                                                          static_cast<png_uint_32>(height), rows.data());
    png_destroy_write_struct(job.png != nullptr ? &job.png : nullptr, job.info != nullptr ? &job.info : nullptr);
    if (!ok) fail(path, fmt::format("cannot write the PNG image: {}", job.error[0] ? job.error : "out of memory"));

    const int flushed = std::fflush(fp.get());
    const int closed = std::fclose(fp.release());
    if (flushed != 0 || closed != 0) fail(path, fmt::format("cannot write the PNG image: {}", errno_text(errno)));
    file.commit();
}

std::vector<float> read_png_rgb(const std::filesystem::path& path, int& width, int& height) {
    FilePtr fp(std::fopen(path.c_str(), "rb"));
    if (!fp) fail(path, fmt::format("cannot open the PNG image: {}", errno_text(errno)));
    png_byte signature[8] = {};
    if (std::fread(signature, 1, sizeof signature, fp.get()) != sizeof signature ||
        png_sig_cmp(signature, 0, sizeof signature) != 0)
        fail(path, "the file is not a PNG image (its signature is wrong)");

    PngJob job;
    job.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &job, png_error_to_job, png_ignore_warning);
    if (job.png != nullptr) job.info = png_create_info_struct(job.png);
    struct Guard {
        PngJob& job;
        ~Guard() {
            png_destroy_read_struct(job.png != nullptr ? &job.png : nullptr, job.info != nullptr ? &job.info : nullptr,
                                    nullptr);
        }
    } guard{job};
    if (job.info == nullptr) fail(path, "cannot read the PNG image: out of memory");
    png_set_sig_bytes(job.png, sizeof signature);

    PngShape shape;
    if (!png_read_shape(job, fp.get(), &shape)) fail(path, fmt::format("cannot read the PNG image: {}", job.error));
    if (shape.channels != 3 || (shape.bit_depth != 8 && shape.bit_depth != 16))
        fail(path, fmt::format("cannot read the PNG image: unexpected {} channels of {} bits after conversion",
                               shape.channels, shape.bit_depth));

    const std::size_t w = shape.width;
    const std::size_t h = shape.height;
    std::vector<png_byte> bytes(shape.row_bytes * h);
    std::vector<png_bytep> rows(h);
    for (std::size_t y = 0; y < h; ++y) rows[y] = &bytes[y * shape.row_bytes];
    if (!png_read_rows(job, rows.data())) fail(path, fmt::format("cannot read the PNG image: {}", job.error));

    std::vector<float> rgb(w * h * 3);
    if (shape.bit_depth == 8) {
        for (std::size_t y = 0; y < h; ++y)
            for (std::size_t i = 0; i < w * 3; ++i) rgb[y * w * 3 + i] = static_cast<float>(rows[y][i]) / 255.0f;
    } else {
        for (std::size_t y = 0; y < h; ++y)
            for (std::size_t i = 0; i < w * 3; ++i) {
                // PNG stores 16-bit samples big-endian.
                const unsigned code = (unsigned{rows[y][2 * i]} << 8) | unsigned{rows[y][2 * i + 1]};
                rgb[y * w * 3 + i] = static_cast<float>(code) / 65535.0f;
            }
    }
    width = static_cast<int>(shape.width);
    height = static_cast<int>(shape.height);
    return rgb;
}

std::vector<float> read_pfm_rgb(const std::filesystem::path& path, int& width, int& height) {
    std::ifstream in(path, std::ios::binary);
    if (!in) fail(path, fmt::format("cannot open the PFM image: {}", errno_text(errno)));
    std::string magic;
    int w = 0, h = 0;
    double scale = 0;
    in >> magic >> w >> h >> scale;
    in.get();  // the one whitespace character after the scale
    if (!in || magic != "PF" || w <= 0 || h <= 0)
        fail(path, "the file is not a colour PFM image (\"PF\", width, height, scale)");
    if (!(scale < 0)) fail(path, "the PFM image is big-endian (a positive scale); only little-endian is read");
    std::vector<float> bottom_up(static_cast<std::size_t>(w) * h * 3);
    in.read(reinterpret_cast<char*>(bottom_up.data()), static_cast<std::streamsize>(bottom_up.size() * 4));
    if (in.gcount() != static_cast<std::streamsize>(bottom_up.size() * 4))
        fail(path, fmt::format("the PFM image is shorter than its {}x{} pixels", w, h));
    std::vector<float> top_down(bottom_up.size());
    for (int y = 0; y < h; ++y)
        std::copy_n(&bottom_up[static_cast<std::size_t>(h - 1 - y) * w * 3], w * 3,
                    &top_down[static_cast<std::size_t>(y) * w * 3]);
    width = w;
    height = h;
    return top_down;
}

}  // namespace atonlab::stimuli
