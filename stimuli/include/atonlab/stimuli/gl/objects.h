#pragma once
// Move-only RAII owners for every GL object (after magnum's GL/Buffer.h): copy
// deleted, noexcept move, the destructor deletes, and a default-constructed
// object is empty and needs no context. Public signatures speak atonlab's own
// enums; the GL enum mapping lives in src/gl_enums.h.
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace atonlab::gl {

/// Shared move-only handle logic. Deleter is a function `void(std::uint32_t)`.
template <void (*Delete)(std::uint32_t)>
class Object {
public:
    Object() = default;
    explicit Object(std::uint32_t id) : id_(id) {}
    ~Object() { reset(); }
    Object(const Object&) = delete;
    Object& operator=(const Object&) = delete;
    Object(Object&& o) noexcept : id_(std::exchange(o.id_, 0)) {}
    Object& operator=(Object&& o) noexcept {
        if (this != &o) {
            reset();
            id_ = std::exchange(o.id_, 0);
        }
        return *this;
    }
    std::uint32_t id() const noexcept { return id_; }
    explicit operator bool() const noexcept { return id_ != 0; }
    void reset() noexcept {
        if (id_ != 0) Delete(id_);
        id_ = 0;
    }

private:
    std::uint32_t id_ = 0;
};

namespace detail {
void delete_buffer(std::uint32_t);
void delete_texture(std::uint32_t);
void delete_framebuffer(std::uint32_t);
void delete_vertex_array(std::uint32_t);
void delete_program(std::uint32_t);
void delete_query(std::uint32_t);
}  // namespace detail

enum class BufferUsage : std::uint8_t { static_draw, dynamic_draw, stream_draw, dynamic_read };

/// A buffer object (immutable size; use as SSBO, UBO or vertex data).
class Buffer : public Object<detail::delete_buffer> {
public:
    Buffer() = default;
    Buffer(std::size_t size_bytes, const void* data, BufferUsage usage);
    std::size_t size() const { return size_; }
    void upload(std::size_t offset, std::size_t bytes, const void* data);
    void download(std::size_t offset, std::size_t bytes, void* out) const;
    void bind_storage(std::uint32_t binding) const;  ///< GL_SHADER_STORAGE_BUFFER
    void bind_uniform(std::uint32_t binding) const;  ///< GL_UNIFORM_BUFFER

    template <class T>
    static Buffer from(std::span<const T> data, BufferUsage usage = BufferUsage::static_draw) {
        return Buffer(data.size_bytes(), data.data(), usage);
    }

private:
    std::size_t size_ = 0;
};

enum class PixelFormat : std::uint8_t { rgba32f, rgba16f, r32f, rg32f, rgba8, depth32f };

enum class Filter : std::uint8_t { nearest, linear };

/// A 2D texture with immutable storage (one mip level unless levels > 1).
class Texture2D : public Object<detail::delete_texture> {
public:
    Texture2D() = default;
    Texture2D(int width, int height, PixelFormat format, int levels = 1);
    int width() const { return width_; }
    int height() const { return height_; }
    PixelFormat format() const { return format_; }
    void set_filter(Filter min, Filter mag);
    /// Uploads level 0 from floats (RGBA, R, RG per the format's channel count).
    void upload(const float* data);
    /// Reads level 0 as floats; rows bottom-up as GL stores them.
    std::vector<float> download_floats() const;
    /// The same into `out`, resized, its memory reused: a frame's worth of
    /// fresh pages costs more than the read (1920×1080 RGBA32F, 33 MB: about
    /// 90 ms of page faults against 2–4 ms for the read on the 2-core VM).
    void download_floats(std::vector<float>& out) const;
    void bind(std::uint32_t unit) const;
    void bind_image(std::uint32_t unit, bool read, bool write) const;
    int channels() const;

private:
    int width_ = 0, height_ = 0;
    PixelFormat format_ = PixelFormat::rgba32f;
};

/// A framebuffer object; attachments are borrowed (the textures must outlive it).
class Framebuffer : public Object<detail::delete_framebuffer> {
public:
    Framebuffer() = default;
    using Object::Object;
    static Framebuffer create();
    void attach_colour(const Texture2D& texture, int index = 0);
    void attach_depth(const Texture2D& texture);
    /// Throws gl::Error naming the status when incomplete.
    void check_complete(std::string_view what) const;
    void bind() const;
};

class VertexArray : public Object<detail::delete_vertex_array> {
public:
    VertexArray() = default;
    using Object::Object;
    static VertexArray create();
    void bind() const;
};

enum class ShaderStage : std::uint8_t { vertex, geometry, fragment, compute };

/// One stage of a program: a shader file embedded at build time (by name,
/// e.g. "light_disc.vert"). `#include "file.glsl"` lines are resolved from the
/// embedded files too.
struct ShaderFile {
    ShaderStage stage;
    std::string_view name;
};

/// A linked program. Variants are made by prepending #defines after #version
/// (never by copying a shader). A compile or link failure throws gl::Error
/// with the file name, the stage and the driver log with line numbers; a
/// non-empty log on success (warnings) is printed to stderr.
class Program : public Object<detail::delete_program> {
public:
    Program() = default;
    using Object::Object;
    static Program build(std::initializer_list<ShaderFile> files,
                         std::initializer_list<std::string_view> defines = {});
    void use() const;
    int uniform_location(std::string_view name) const;  ///< -1 if absent (optimised out)
    void set(std::string_view name, float v) const;
    void set(std::string_view name, double v) const;  ///< a `double` uniform (GL 4.0+)
    void set(std::string_view name, int v) const;
    void set(std::string_view name, unsigned v) const;
    void set(std::string_view name, float x, float y) const;
    void set(std::string_view name, int x, int y) const;  ///< ivec2
    void set(std::string_view name, float x, float y, float z) const;
    void set(std::string_view name, float x, float y, float z, float w) const;
    void set_mat3(std::string_view name, const float* column_major) const;
    void set_mat4(std::string_view name, const float* column_major) const;
};

/// Source text of an embedded shader file; throws gl::Error if unknown.
std::string_view shader_source(std::string_view name);
/// Makes a further table of (file name, text) shaders known to shader_source
/// and Program::build, searched after the library's own: the test suite's
/// shaders (tests/shaders/) live there, not in the shipped library. The table
/// must outlive every use; not thread-safe (call before building programs).
void add_shader_table(std::span<const std::pair<std::string_view, std::string_view>> table);
/// The text handed to the driver: #version first, then the defines, then the
/// file with #include lines expanded (and #line directives so logs name lines).
std::string preprocess_shader(std::string_view name, std::initializer_list<std::string_view> defines);

/// GPU timer (GL_TIME_ELAPSED), for benchmarks. Nested timers are not allowed by GL.
class GpuTimer : public Object<detail::delete_query> {
public:
    GpuTimer() = default;
    using Object::Object;
    static GpuTimer create();
    void begin();
    void end();
    /// Elapsed GPU time in milliseconds; waits for the result when wait, else nullopt if not ready.
    std::optional<double> elapsed_ms(bool wait = true) const;
};

/// Waits for all submitted GL work (glFinish).
void finish();

}  // namespace atonlab::gl
