// Shader programs from embedded files (magnum Shaders/, bgfx .sc -> .bin.h).
#include <epoxy/gl.h>

#include <cstdio>
#include <span>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "atonlab/display/display_encodings.h"
#include "atonlab/display/gamut.h"
#include "atonlab/stimuli/gl/context.h"
#include "atonlab/stimuli/gl/objects.h"
#include "gl_enums.h"

namespace atonlab::gl {
namespace detail {
extern const std::pair<std::string_view, std::string_view> embedded_shaders[];
extern const std::size_t embedded_shaders_count;
}  // namespace detail

namespace {
/// Tables added by add_shader_table (the tests' own shaders), searched after the library's.
std::vector<std::span<const std::pair<std::string_view, std::string_view>>>& extra_tables() {
    static std::vector<std::span<const std::pair<std::string_view, std::string_view>>> tables;
    return tables;
}
}  // namespace

void add_shader_table(std::span<const std::pair<std::string_view, std::string_view>> table) {
    extra_tables().push_back(table);
}

std::string_view shader_source(std::string_view name) {
    // Made from a registry rather than written: the GPU's dispatch over the display encodings.
    if (name == "display_encodings.glsl") {
        static const std::string generated = display::display_encodings_glsl();
        return generated;
    }
    // Made from gamut.cpp's tables: the signal-colour areas of display.out_of_gamut.
    if (name == "signal_colour_areas.glsl") {
        static const std::string generated = display::signal_colour_areas_glsl();
        return generated;
    }
    for (std::size_t i = 0; i < detail::embedded_shaders_count; ++i)
        if (detail::embedded_shaders[i].first == name) return detail::embedded_shaders[i].second;
    for (const auto& table : extra_tables())
        for (const auto& [file, text] : table)
            if (file == name) return text;
    throw Error(fmt::format("no embedded shader named '{}'", name));
}

namespace {

// Source-string numbers for #line: 0 is the file itself, includes get 1, 2, ...
// in order; the log legend printed on failure maps them back to names.
void expand(std::string_view name, std::string& out, std::vector<std::string>& files, int depth) {
    if (depth > 8) throw Error(fmt::format("shader '{}': #include nested too deeply", name));
    const int file_no = static_cast<int>(files.size());
    files.emplace_back(name);
    const std::string_view src = shader_source(name);
    int line_no = 0;
    std::size_t pos = 0;
    while (pos <= src.size()) {
        std::size_t end = src.find('\n', pos);
        if (end == std::string_view::npos) end = src.size();
        const std::string_view line = src.substr(pos, end - pos);
        ++line_no;
        const auto first = line.find_first_not_of(" \t");
        const std::string_view trimmed = first == std::string_view::npos ? std::string_view{} : line.substr(first);
        if (trimmed.starts_with("#version")) {
            // The version is emitted once by preprocess_shader; drop it here.
            out += '\n';
        } else if (trimmed.starts_with("#include")) {
            const auto q0 = trimmed.find('"');
            const auto q1 = trimmed.find('"', q0 + 1);
            if (q0 == std::string_view::npos || q1 == std::string_view::npos)
                throw Error(fmt::format("{}:{}: malformed #include", name, line_no));
            const int child = static_cast<int>(files.size());
            out += fmt::format("#line 1 {}\n", child);
            expand(trimmed.substr(q0 + 1, q1 - q0 - 1), out, files, depth + 1);
            out += fmt::format("#line {} {}\n", line_no + 1, file_no);
        } else {
            out.append(line);
            out += '\n';
        }
        if (end == src.size()) break;
        pos = end + 1;
    }
}

std::string build_source(std::string_view name, std::initializer_list<std::string_view> defines,
                         std::vector<std::string>& files) {
    std::string out = "#version 450 core\n";
    for (auto d : defines) out += fmt::format("#define {}\n", d);
    out += "#line 1 0\n";
    expand(name, out, files, 0);
    return out;
}

std::string legend(const std::vector<std::string>& files) {
    std::string s;
    for (std::size_t i = 0; i < files.size(); ++i) s += fmt::format("  source {} = {}\n", i, files[i]);
    return s;
}

std::string shader_log(GLuint shader) {
    GLint len = 0;
    glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &len);
    std::string log(static_cast<std::size_t>(len > 0 ? len : 0), '\0');
    if (len > 0) glGetShaderInfoLog(shader, len, nullptr, log.data());
    while (!log.empty() && (log.back() == '\0' || log.back() == '\n')) log.pop_back();
    return log;
}

std::string program_log(GLuint program) {
    GLint len = 0;
    glGetProgramiv(program, GL_INFO_LOG_LENGTH, &len);
    std::string log(static_cast<std::size_t>(len > 0 ? len : 0), '\0');
    if (len > 0) glGetProgramInfoLog(program, len, nullptr, log.data());
    while (!log.empty() && (log.back() == '\0' || log.back() == '\n')) log.pop_back();
    return log;
}

}  // namespace

std::string preprocess_shader(std::string_view name, std::initializer_list<std::string_view> defines) {
    std::vector<std::string> files;
    return build_source(name, defines, files);
}

Program Program::build(std::initializer_list<ShaderFile> stages, std::initializer_list<std::string_view> defines) {
    Program program{glCreateProgram()};
    std::vector<GLuint> shaders;
    std::string names;
    for (const ShaderFile& sf : stages) {
        std::vector<std::string> files;
        const std::string src = build_source(sf.name, defines, files);
        const GLuint sh = glCreateShader(detail::stage(sf.stage));
        const char* text = src.c_str();
        glShaderSource(sh, 1, &text, nullptr);
        glCompileShader(sh);
        GLint ok = 0;
        glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
        const std::string log = shader_log(sh);
        if (!ok) {
            glDeleteShader(sh);
            for (GLuint s : shaders) glDeleteShader(s);
            throw Error(fmt::format("{} shader '{}' failed to compile:\n{}\n{}", detail::stage_name(sf.stage), sf.name,
                                    log, legend(files)));
        }
        if (!log.empty())
            std::fprintf(stderr, "atonlab: %s shader '%.*s' compiled with warnings:\n%s\n%s",
                         detail::stage_name(sf.stage), static_cast<int>(sf.name.size()), sf.name.data(), log.c_str(),
                         legend(files).c_str());
        glAttachShader(program.id(), sh);
        shaders.push_back(sh);
        names += names.empty() ? "" : " + ";
        names += sf.name;
    }
    glLinkProgram(program.id());
    for (GLuint s : shaders) {
        glDetachShader(program.id(), s);
        glDeleteShader(s);
    }
    GLint linked = 0;
    glGetProgramiv(program.id(), GL_LINK_STATUS, &linked);
    const std::string log = program_log(program.id());
    if (!linked) throw Error(fmt::format("program '{}' failed to link:\n{}", names, log));
    if (!log.empty()) std::fprintf(stderr, "atonlab: program '%s' linked with warnings:\n%s\n", names.c_str(), log.c_str());
    return program;
}

void Program::use() const { ATONLAB_GL_CHECK(glUseProgram(id())); }

int Program::uniform_location(std::string_view name) const {
    const std::string n(name);
    return glGetUniformLocation(id(), n.c_str());
}

void Program::set(std::string_view n, float v) const { glProgramUniform1f(id(), uniform_location(n), v); }
void Program::set(std::string_view n, double v) const { glProgramUniform1d(id(), uniform_location(n), v); }
void Program::set(std::string_view n, int v) const { glProgramUniform1i(id(), uniform_location(n), v); }
void Program::set(std::string_view n, unsigned v) const { glProgramUniform1ui(id(), uniform_location(n), v); }
void Program::set(std::string_view n, int x, int y) const { glProgramUniform2i(id(), uniform_location(n), x, y); }
void Program::set(std::string_view n, float x, float y) const { glProgramUniform2f(id(), uniform_location(n), x, y); }
void Program::set(std::string_view n, float x, float y, float z) const {
    glProgramUniform3f(id(), uniform_location(n), x, y, z);
}
void Program::set(std::string_view n, float x, float y, float z, float w) const {
    glProgramUniform4f(id(), uniform_location(n), x, y, z, w);
}
void Program::set_mat3(std::string_view n, const float* m) const {
    glProgramUniformMatrix3fv(id(), uniform_location(n), 1, GL_FALSE, m);
}
void Program::set_mat4(std::string_view n, const float* m) const {
    glProgramUniformMatrix4fv(id(), uniform_location(n), 1, GL_FALSE, m);
}

}  // namespace atonlab::gl
