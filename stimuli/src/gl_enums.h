#pragma once
// The one place where atonlab's GL-facing enums meet GL's (after filament's GLUtils.h).
#include <epoxy/gl.h>

#include "atonlab/stimuli/gl/objects.h"

namespace atonlab::gl::detail {

struct FormatInfo {
    GLenum internal, format, type;
    int channels;
};

inline FormatInfo format_info(PixelFormat f) {
    switch (f) {
    case PixelFormat::rgba32f: return {GL_RGBA32F, GL_RGBA, GL_FLOAT, 4};
    case PixelFormat::rgba16f: return {GL_RGBA16F, GL_RGBA, GL_FLOAT, 4};
    case PixelFormat::r32f: return {GL_R32F, GL_RED, GL_FLOAT, 1};
    case PixelFormat::rg32f: return {GL_RG32F, GL_RG, GL_FLOAT, 2};
    case PixelFormat::rgba8: return {GL_RGBA8, GL_RGBA, GL_FLOAT, 4};
    case PixelFormat::depth32f: return {GL_DEPTH_COMPONENT32F, GL_DEPTH_COMPONENT, GL_FLOAT, 1};
    }
    return {GL_RGBA32F, GL_RGBA, GL_FLOAT, 4};
}

inline GLenum usage(BufferUsage u) {
    switch (u) {
    case BufferUsage::static_draw: return GL_STATIC_DRAW;
    case BufferUsage::dynamic_draw: return GL_DYNAMIC_DRAW;
    case BufferUsage::stream_draw: return GL_STREAM_DRAW;
    case BufferUsage::dynamic_read: return GL_DYNAMIC_READ;
    }
    return GL_STATIC_DRAW;
}

inline GLenum stage(ShaderStage s) {
    switch (s) {
    case ShaderStage::vertex: return GL_VERTEX_SHADER;
    case ShaderStage::geometry: return GL_GEOMETRY_SHADER;
    case ShaderStage::fragment: return GL_FRAGMENT_SHADER;
    case ShaderStage::compute: return GL_COMPUTE_SHADER;
    }
    return GL_VERTEX_SHADER;
}

inline const char* stage_name(ShaderStage s) {
    switch (s) {
    case ShaderStage::vertex: return "vertex";
    case ShaderStage::geometry: return "geometry";
    case ShaderStage::fragment: return "fragment";
    case ShaderStage::compute: return "compute";
    }
    return "?";
}

/// Checks glGetError after a call in debug builds (after bgfx's GL_CHECK).
void check_gl_error(const char* call, const char* file, int line);

}  // namespace atonlab::gl::detail

#ifndef NDEBUG
#define ATONLAB_GL_CHECK(call)                                               \
    do {                                                                     \
        call;                                                                \
        ::atonlab::gl::detail::check_gl_error(#call, __FILE__, __LINE__);    \
    } while (0)
#else
#define ATONLAB_GL_CHECK(call) call
#endif
