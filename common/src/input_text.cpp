#include "atonlab/common/input_text.h"

// echo() and one_line() also escape every byte that is not part of well-formed
// UTF-8 (as \xNN), so every message is one line of valid UTF-8 whatever it
// quotes (a damaged record, a file name): docs/fuzzing.md, "Echoed values".

#include <fmt/format.h>

#include <cerrno>
#include <cstdio>
#include <system_error>

namespace atonlab::text {
namespace {

/// Bytes of the well-formed UTF-8 sequence that starts at `s[i]`, or 0 when
/// the bytes there are not one (a stray continuation byte, a lead byte cut
/// short, an overlong form, a surrogate, past U+10FFFF): the table of
/// well-formed byte sequences in RFC 3629 section 4 (Unicode 15, table 3-7).
std::size_t utf8_sequence(std::string_view s, std::size_t i) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c < 0x80) return 1;
    std::size_t n = 0;
    unsigned char low = 0x80, high = 0xbf;  // the second byte's range; later ones are 80..BF
    if (c >= 0xc2 && c <= 0xdf) {
        n = 2;
    } else if (c >= 0xe0 && c <= 0xef) {
        n = 3;
        if (c == 0xe0) low = 0xa0;   // not overlong
        if (c == 0xed) high = 0x9f;  // not a surrogate
    } else if (c >= 0xf0 && c <= 0xf4) {
        n = 4;
        if (c == 0xf0) low = 0x90;   // not overlong
        if (c == 0xf4) high = 0x8f;  // at most U+10FFFF
    } else {
        return 0;
    }
    if (s.size() - i < n) return 0;
    for (std::size_t k = 1; k < n; ++k) {
        const auto b = static_cast<unsigned char>(s[i + k]);
        if (k == 1 ? (b < low || b > high) : (b < 0x80 || b > 0xbf)) return 0;
    }
    return n;
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

// The character at `s[i]` as a message shows it: a control character or a
// byte that is not part of well-formed UTF-8 escaped (\n, \x1B, \xB0), so
// every message is one line of valid UTF-8. Returns where the next starts.
std::size_t append_character(std::string& out, std::string_view s, std::size_t i) {
    const auto c = static_cast<unsigned char>(s[i]);
    const std::size_t n = is_control(c) ? 0 : utf8_sequence(s, i);
    if (n == 0) {
        append_escaped(out, c);
        return i + 1;
    }
    out.append(s.substr(i, n));
    return i + n;
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
        i = append_character(out, value, i);
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
        i = append_character(out, message, i);
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
