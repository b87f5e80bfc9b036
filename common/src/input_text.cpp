#include "atonlab/common/input_text.h"

#include <fmt/format.h>

#include <cerrno>
#include <cstdio>
#include <system_error>

namespace atonlab::text {
namespace {

/// Bytes of the UTF-8 sequence that starts with `lead` (1 for a stray byte).
std::size_t utf8_length(unsigned char lead) {
    if (lead >= 0xf0 && lead <= 0xf7) return 4;
    if (lead >= 0xe0) return lead <= 0xef ? 3 : 1;
    if (lead >= 0xc0) return 2;
    return 1;
}

void append_escaped(std::string& out, unsigned char c) {
    switch (c) {
        case '\n':
            out += "\\n";
            break;
        case '\r':
            out += "\\r";
            break;
        case '\t':
            out += "\\t";
            break;
        default:
            out += fmt::format("\\x{:02X}", static_cast<unsigned>(c));
    }
}

bool is_control(unsigned char c) {
    return c < 0x20 || c == 0x7f;
}

std::string size_text(std::uintmax_t bytes) {
    if (bytes >= (1u << 20)) return fmt::format("{:.1f} MiB", static_cast<double>(bytes) / (1u << 20));
    if (bytes >= (1u << 10)) return fmt::format("{:.1f} KiB", static_cast<double>(bytes) / (1u << 10));
    return fmt::format("{} bytes", bytes);
}

}  // namespace

std::string echo(std::string_view value, std::size_t max) {
    std::string out;
    std::size_t chars = 0;
    std::size_t i = 0;
    while (i < value.size()) {
        if (chars == max) {
            out += fmt::format("… ({} bytes in all)", value.size());
            return out;
        }
        const auto c = static_cast<unsigned char>(value[i]);
        if (is_control(c)) {
            append_escaped(out, c);
            ++i;
        } else {
            const std::size_t n = std::min(utf8_length(c), value.size() - i);
            out.append(value.substr(i, n));
            i += n;
        }
        ++chars;
    }
    return out;
}

std::string one_line(std::string_view message) {
    std::string out;
    out.reserve(std::min(message.size(), kMessageMax) + 8);
    for (std::size_t i = 0; i < message.size();) {
        if (out.size() >= kMessageMax) {
            out += "…";
            break;
        }
        const auto c = static_cast<unsigned char>(message[i]);
        if (is_control(c)) {
            append_escaped(out, c);
            ++i;
        } else {
            const std::size_t n = std::min(utf8_length(c), message.size() - i);
            out.append(message.substr(i, n));
            i += n;
        }
    }
    return out;
}

FileText read_text_file(const std::filesystem::path& file, std::uintmax_t max_bytes) {
    FileText r;
    std::error_code ec;
    if (std::filesystem::is_directory(file, ec)) {
        r.error = "it is a directory";
        return r;
    }
    std::FILE* f = std::fopen(file.c_str(), "rb");
    if (f == nullptr) {
        r.error = std::error_code(errno, std::generic_category()).message();
        return r;
    }
    r.opened = true;
    // Read in pieces and stop one byte past the limit: the size a file says
    // it has is not trusted (/dev/zero, a pipe, a file still growing).
    char buffer[65536];
    std::size_t n = 0;
    bool too_large = false;
    while ((n = std::fread(buffer, 1, sizeof buffer, f)) > 0) {
        if (r.text.size() + n > max_bytes) {
            too_large = true;
            break;
        }
        r.text.append(buffer, n);
    }
    const bool failed = !too_large && std::ferror(f) != 0;
    const int read_errno = errno;
    std::fclose(f);
    if (too_large) {
        r.text.clear();
        r.error = fmt::format("it is larger than {}, the most an input file may be", size_text(max_bytes));
    } else if (failed) {
        r.text.clear();
        r.error =
            fmt::format("a read error occurred ({})", std::error_code(read_errno, std::generic_category()).message());
    }
    return r;
}

}  // namespace atonlab::text
