#include <epoxy/gl.h>

#include <fmt/format.h>

#include "atonlab/stimuli/gl/context.h"
#include "atonlab/stimuli/gl/objects.h"
#include "gl_enums.h"

namespace atonlab::gl {
namespace detail {

void check_gl_error(const char* call, const char* file, int line) {
    const GLenum e = glGetError();
    if (e != GL_NO_ERROR) throw Error(fmt::format("{}:{}: {} failed with GL error 0x{:04x}", file, line, call, e));
}

void delete_buffer(std::uint32_t id) { glDeleteBuffers(1, &id); }
void delete_texture(std::uint32_t id) { glDeleteTextures(1, &id); }
void delete_framebuffer(std::uint32_t id) { glDeleteFramebuffers(1, &id); }
void delete_vertex_array(std::uint32_t id) { glDeleteVertexArrays(1, &id); }
void delete_program(std::uint32_t id) { glDeleteProgram(id); }
void delete_query(std::uint32_t id) { glDeleteQueries(1, &id); }

}  // namespace detail

namespace {
GLuint create_named(void (*create)(GLsizei, GLuint*)) {
    GLuint id = 0;
    create(1, &id);
    return id;
}
}  // namespace

// --- Buffer ------------------------------------------------------------------

Buffer::Buffer(std::size_t size_bytes, const void* data, BufferUsage usage)
    : Object(create_named(glCreateBuffers)), size_(size_bytes) {
    // Zero-sized buffers are legal in atonlab (an empty scene); GL needs >= 1 byte.
    const auto bytes = static_cast<GLsizeiptr>(size_bytes > 0 ? size_bytes : 4);
    ATONLAB_GL_CHECK(glNamedBufferData(id(), bytes, size_bytes > 0 ? data : nullptr, detail::usage(usage)));
}

void Buffer::upload(std::size_t offset, std::size_t bytes, const void* data) {
    if (bytes == 0) return;
    ATONLAB_GL_CHECK(glNamedBufferSubData(id(), static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes), data));
}

void Buffer::download(std::size_t offset, std::size_t bytes, void* out) const {
    if (bytes == 0) return;
    ATONLAB_GL_CHECK(
        glGetNamedBufferSubData(id(), static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes), out));
}

void Buffer::bind_storage(std::uint32_t binding) const {
    ATONLAB_GL_CHECK(glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, id()));
}
void Buffer::bind_uniform(std::uint32_t binding) const {
    ATONLAB_GL_CHECK(glBindBufferBase(GL_UNIFORM_BUFFER, binding, id()));
}

// --- Texture2D -----------------------------------------------------------------

Texture2D::Texture2D(int width, int height, PixelFormat format, int levels)
    : Object([] {
          GLuint t = 0;
          glCreateTextures(GL_TEXTURE_2D, 1, &t);
          return t;
      }()),
      width_(width), height_(height), format_(format) {
    const auto fi = detail::format_info(format);
    ATONLAB_GL_CHECK(glTextureStorage2D(id(), levels, fi.internal, width, height));
    set_filter(Filter::nearest, Filter::nearest);
    glTextureParameteri(id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

int Texture2D::channels() const { return detail::format_info(format_).channels; }

void Texture2D::set_filter(Filter min, Filter mag) {
    glTextureParameteri(id(), GL_TEXTURE_MIN_FILTER, min == Filter::linear ? GL_LINEAR : GL_NEAREST);
    glTextureParameteri(id(), GL_TEXTURE_MAG_FILTER, mag == Filter::linear ? GL_LINEAR : GL_NEAREST);
}

void Texture2D::upload(const float* data) {
    const auto fi = detail::format_info(format_);
    ATONLAB_GL_CHECK(glTextureSubImage2D(id(), 0, 0, 0, width_, height_, fi.format, GL_FLOAT, data));
}

std::vector<float> Texture2D::download_floats() const {
    std::vector<float> out;
    download_floats(out);
    return out;
}

void Texture2D::download_floats(std::vector<float>& out) const {
    const auto fi = detail::format_info(format_);
    out.resize(static_cast<std::size_t>(width_) * height_ * fi.channels);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    ATONLAB_GL_CHECK(glGetTextureImage(id(), 0, fi.format, GL_FLOAT, static_cast<GLsizei>(out.size() * sizeof(float)),
                                       out.data()));
}

void Texture2D::bind(std::uint32_t unit) const { ATONLAB_GL_CHECK(glBindTextureUnit(unit, id())); }

void Texture2D::bind_image(std::uint32_t unit, bool read, bool write) const {
    const GLenum access = read && write ? GL_READ_WRITE : (write ? GL_WRITE_ONLY : GL_READ_ONLY);
    ATONLAB_GL_CHECK(glBindImageTexture(unit, id(), 0, GL_FALSE, 0, access, detail::format_info(format_).internal));
}

// --- Framebuffer ---------------------------------------------------------------

Framebuffer Framebuffer::create() { return Framebuffer{create_named(glCreateFramebuffers)}; }

void Framebuffer::attach_colour(const Texture2D& texture, int index) {
    ATONLAB_GL_CHECK(glNamedFramebufferTexture(id(), GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(index), texture.id(), 0));
    // Draw to every attached colour buffer in order.
    std::vector<GLenum> bufs;
    for (int i = 0; i <= index; ++i) bufs.push_back(GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(i));
    glNamedFramebufferDrawBuffers(id(), static_cast<GLsizei>(bufs.size()), bufs.data());
}

void Framebuffer::attach_depth(const Texture2D& texture) {
    ATONLAB_GL_CHECK(glNamedFramebufferTexture(id(), GL_DEPTH_ATTACHMENT, texture.id(), 0));
}

void Framebuffer::check_complete(std::string_view what) const {
    const GLenum s = glCheckNamedFramebufferStatus(id(), GL_FRAMEBUFFER);
    if (s != GL_FRAMEBUFFER_COMPLETE) throw Error(fmt::format("framebuffer '{}' is incomplete (status 0x{:04x})", what, s));
}

void Framebuffer::bind() const { ATONLAB_GL_CHECK(glBindFramebuffer(GL_FRAMEBUFFER, id())); }

// --- VertexArray -----------------------------------------------------------------

VertexArray VertexArray::create() { return VertexArray{create_named(glCreateVertexArrays)}; }
void VertexArray::bind() const { ATONLAB_GL_CHECK(glBindVertexArray(id())); }

// --- GpuTimer --------------------------------------------------------------------

GpuTimer GpuTimer::create() {
    GLuint q = 0;
    glCreateQueries(GL_TIME_ELAPSED, 1, &q);
    return GpuTimer{q};
}
void GpuTimer::begin() { ATONLAB_GL_CHECK(glBeginQuery(GL_TIME_ELAPSED, id())); }
void GpuTimer::end() { ATONLAB_GL_CHECK(glEndQuery(GL_TIME_ELAPSED)); }
std::optional<double> GpuTimer::elapsed_ms(bool wait) const {
    GLint available = 0;
    if (!wait) {
        glGetQueryObjectiv(id(), GL_QUERY_RESULT_AVAILABLE, &available);
        if (!available) return std::nullopt;
    }
    GLuint64 ns = 0;
    glGetQueryObjectui64v(id(), GL_QUERY_RESULT, &ns);
    return static_cast<double>(ns) * 1e-6;
}

void finish() { glFinish(); }

}  // namespace atonlab::gl
