#include "patch_session.h"

#include <fmt/format.h>
#include <poll.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <utility>

namespace atonlab::runner {
namespace {

constexpr const char* kHelp =
    "  type the photometer's reading of the patch on the screen:\n"
    "    21.9            the luminance Y in cd/m² (\"21.9 cd/m2\" too; \"6.39 fL\" is converted from foot-lamberts)\n"
    "    20.8 21.9 23.7  X Y Z (cd/m²) when the meter gives them\n"
    "    r               show the patch again (after moving the meter, a warm-up, ...)\n"
    "    b               go back one patch and measure it again\n"
    "    q               give up: nothing is stored\n";

/// Lines from the terminal (stdin) or from the patch window, whichever
/// completes one first, while the window is kept alive.
class LineInput {
public:
    enum class Status { line, end_of_input, quit };

    Status read(PatchScreen& screen, std::string& out) {
        for (;;) {
            for (const char c : screen.take_typed()) {
                if (c == '\n') {
                    std::fputc('\n', stdout);
                    std::fflush(stdout);
                    out = std::exchange(window_line_, std::string());
                    return Status::line;
                }
                if (c == '\b') {
                    if (!window_line_.empty()) {
                        window_line_.pop_back();
                        std::fputs("\b \b", stdout);
                    }
                } else {
                    window_line_ += c;
                    std::fputc(c, stdout);
                }
                std::fflush(stdout);
            }
            if (screen.quit_requested()) return Status::quit;
            if (const auto nl = stdin_buffer_.find('\n'); nl != std::string::npos) {
                out = stdin_buffer_.substr(0, nl);
                stdin_buffer_.erase(0, nl + 1);
                echo(out);
                return Status::line;
            }
            if (stdin_open_) {
                pollfd p{STDIN_FILENO, POLLIN, 0};
                if (poll(&p, 1, 10) > 0) {
                    char buf[256];
                    const ssize_t n = ::read(STDIN_FILENO, buf, sizeof buf);
                    if (n > 0) {
                        stdin_buffer_.append(buf, static_cast<std::size_t>(n));
                        continue;
                    }
                    stdin_open_ = false;
                    if (!stdin_buffer_.empty()) {  // a last line without a newline
                        out = std::exchange(stdin_buffer_, std::string());
                        echo(out);
                        return Status::line;
                    }
                }
            }
            if (!stdin_open_) return Status::end_of_input;
            screen.pump();
        }
    }

private:
    /// A terminal echoes what is typed; piped input is echoed here, so that a
    /// log reads as a terminal would have shown it.
    void echo(const std::string& line) const {
        if (isatty(STDIN_FILENO)) return;
        std::printf("%s\n", line.c_str());
        std::fflush(stdout);
    }

    std::string window_line_;
    std::string stdin_buffer_;
    bool stdin_open_ = true;
};

/// The brightest earlier reading of the same ramp at a lower level (black is
/// in every ramp), and its patch; nullptr when there is none.
const Patch* brighter_lower(const std::vector<Patch>& patches, const std::vector<PhotometerReading>& readings,
                            const Patch& p, double& luminance) {
    const Patch* found = nullptr;
    for (std::size_t i = 0; i < readings.size(); ++i) {
        const Patch& q = patches[i];
        const bool same_ramp = q.channel == p.channel || q.code == 0;
        if (same_ramp && q.code < p.code && (!found || readings[i].luminance_cd_m2 > luminance)) {
            found = &q;
            luminance = readings[i].luminance_cd_m2;
        }
    }
    return found;
}

std::string reading_text(const PhotometerReading& r) {
    if (r.xyz_cd_m2)
        return fmt::format("X {:.5g} Y {:.5g} Z {:.5g} cd/m²", r.xyz_cd_m2->x, r.xyz_cd_m2->y, r.xyz_cd_m2->z);
    return fmt::format("{:.5g} cd/m²", r.luminance_cd_m2);
}

}  // namespace

std::optional<std::vector<PhotometerReading>> collect_readings(const std::vector<Patch>& patches, PatchScreen& screen,
                                                               const PatchSessionOptions& o) {
    const std::size_t n = patches.size();
    std::vector<PhotometerReading> readings;
    if (o.scripted) {
        for (std::size_t i = 0; i < n; ++i) {
            screen.show(patches[i]);
            const auto until =
                std::chrono::steady_clock::now() + std::chrono::duration<double>(std::max(0.0, o.patch_seconds));
            while (std::chrono::steady_clock::now() < until && !screen.quit_requested()) screen.pump();
            if (screen.quit_requested()) return std::nullopt;
            readings.push_back((*o.scripted)[i]);
            if (!o.quiet)
                std::printf("  %2zu/%zu %-28s %s\n", i + 1, n, patches[i].description().c_str(),
                            reading_text(readings.back()).c_str());
        }
        return readings;
    }

    LineInput input;
    std::printf("%s  The patches fill the screen; type each reading here or into the patch window.\n", kHelp);
    double pending = -1.0;  // a suspicious value typed once, waiting to be typed again (< 0: none)
    for (std::size_t i = 0; i < n;) {
        const Patch& p = patches[i];
        screen.show(p);
        std::printf("patch %zu/%zu: %s. Reading in cd/m² (r again, b back, q quit, ? help): ", i + 1, n,
                    p.description().c_str());
        std::fflush(stdout);
        bool next = false;
        while (!next) {
            std::string line;
            const LineInput::Status s = input.read(screen, line);
            if (s == LineInput::Status::quit) return std::nullopt;
            if (s == LineInput::Status::end_of_input) {
                std::printf("\n  the terminal's input ended before patch %zu had a reading.\n", i + 1);
                return std::nullopt;
            }
            const OperatorLine typed = parse_operator_line(line);
            if (const auto* why = std::get_if<std::string>(&typed)) {
                std::printf("  not a reading (%s); type the luminance in cd/m², e.g. 21.9: ", why->c_str());
            } else if (const auto* cmd = std::get_if<OperatorCommand>(&typed)) {
                switch (*cmd) {
                    case OperatorCommand::quit:
                        return std::nullopt;
                    case OperatorCommand::help:
                        std::printf("%s  patch %zu/%zu: %s: ", kHelp, i + 1, n, p.description().c_str());
                        break;
                    case OperatorCommand::repeat:
                        screen.show(p);
                        std::printf("  %s is shown again; reading in cd/m²: ", p.name.c_str());
                        break;
                    case OperatorCommand::back:
                        if (i == 0) {
                            std::printf("  this is the first patch; reading in cd/m²: ");
                        } else {
                            readings.pop_back();
                            --i;
                            pending = -1.0;
                            next = true;  // shows patch i again
                        }
                        break;
                }
            } else {
                const PhotometerReading r = std::get<TypedReading>(typed).reading;
                double lower_cd = 0.0;
                const Patch* lower = brighter_lower(patches, readings, p, lower_cd);
                if (lower && r.luminance_cd_m2 < lower_cd * (1.0 - o.typo_tolerance) && r.luminance_cd_m2 != pending) {
                    pending = r.luminance_cd_m2;
                    std::printf(
                        "  %.5g cd/m² is below the %.5g cd/m² of %s, a lower level of the same ramp: a typo? "
                        "Type it again to keep it, or type the right value: ",
                        r.luminance_cd_m2, lower_cd, lower->name.c_str());
                } else {
                    pending = -1.0;
                    readings.push_back(r);
                    std::printf("  %s: %s\n", p.name.c_str(), reading_text(r).c_str());
                    ++i;
                    next = true;
                }
            }
            std::fflush(stdout);
        }
    }
    return readings;
}

}  // namespace atonlab::runner
