#include "spotread_instrument.h"

#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "patch_screen.h"
#include "pty_process.h"
#include "spotread_output.h"

namespace atonlab::runner {
namespace {

using Clock = std::chrono::steady_clock;

bool on_path(const std::string& program) {
    const char* path = std::getenv("PATH");
    std::istringstream dirs(path ? path : "");
    std::string dir;
    while (std::getline(dirs, dir, ':')) {
        const std::filesystem::path p = std::filesystem::path(dir.empty() ? "." : dir) / program;
        if (access(p.c_str(), X_OK) == 0) return true;
    }
    return false;
}

std::vector<std::string> split_args(const std::string& s) {
    std::vector<std::string> out;
    std::istringstream in(s);
    std::string a;
    while (in >> a) out.push_back(a);
    return out;
}

/// The last non-empty line of spotread's output, for "its last words".
std::string last_line(const std::string& out) {
    std::istringstream in(out);
    std::string line, last;
    while (std::getline(in, line))
        if (line.find_first_not_of(" \t") != std::string::npos) last = line;
    return last.substr(last.find_first_not_of(" \t"));
}

class Spotread final : public Instrument {
public:
    explicit Spotread(const InstrumentOptions& o) : o_(o) {
        if (!on_path("spotread"))
            throw InstrumentError(
                "spotread is not on PATH: install ArgyllCMS (Debian package argyll) or put its bin folder on PATH");
        std::vector<std::string> argv = {"spotread", "-e", "-x"};
        for (std::string& a : split_args(o.instrument_args)) argv.push_back(std::move(a));
        for (const std::string& a : argv) command_ += (command_.empty() ? "" : " ") + a;
        try {
            process_ = std::make_unique<PtyProcess>(argv);
        } catch (const std::exception& e) {
            throw InstrumentError(fmt::format("spotread cannot be started: {}", e.what()));
        }
        wait_until_ready(nullptr, "to start");
    }

    ~Spotread() override {
        if (process_) {
            process_->send("q");  // "Hit ESC or Q to exit"
            process_->finish(std::chrono::milliseconds(2000));
        }
    }

    std::string description() const override { return fmt::format("`{}` (ArgyllCMS)", command_); }

    InstrumentReading read(PatchScreen& screen) override {
        wait_until_ready(&screen, "to take a reading");
        process_->send(" ");  // "any other key to take a reading"
        const spotread::Scan s = wait_for_event(&screen, "to give a reading");
        if (s.state != spotread::State::result) fail(s, "to give a reading");
        InstrumentReading r;
        r.transcript = prompt_ + process_->output().substr(0, s.end);
        while (!r.transcript.empty() && r.transcript.front() == '\n') r.transcript.erase(0, 1);
        const auto xyz = spotread::parse_result(s.line);
        if (!xyz)
            throw InstrumentError(
                fmt::format("spotread's result line \"{}\" does not hold three numbers X Y Z", s.line));
        r.xyz_cd_m2 = *xyz;
        process_->consume(s.end);
        ready_ = false;
        return r;
    }

private:
    /// The next event of spotread's output, pumping the window while waiting;
    /// a timeout or spotread's exit end the run.
    spotread::Scan wait_for_event(PatchScreen* screen, const char* doing) {
        const auto deadline =
            Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(o_.timeout_s));
        auto event = [](const std::string& out) { return spotread::scan(out).state != spotread::State::busy; };
        for (;;) {
            const auto slice = std::min(deadline, Clock::now() + std::chrono::milliseconds(50));
            const PtyProcess::Wait w = process_->read_until(event, slice);
            if (w == PtyProcess::Wait::matched) return spotread::scan(process_->output());
            if (w == PtyProcess::Wait::exited) {
                const int status = process_->finish(std::chrono::milliseconds(1000));
                const std::string words = last_line(process_->output());
                if (status == 127 && words.empty())
                    throw InstrumentError(fmt::format("`{}` could not be run", command_));
                throw InstrumentError(fmt::format("spotread ended (exit status {}) before it was ready {}{}", status,
                                                  doing,
                                                  words.empty() ? "" : fmt::format("; it last said \"{}\"", words)));
            }
            if (Clock::now() >= deadline)
                throw InstrumentError(
                    fmt::format("spotread did not answer within {} s (--instrument-timeout-s; is the instrument "
                                "connected and lying "
                                "on the screen?) when asked {}",
                                o_.timeout_s, doing));
            if (screen) screen->pump();
        }
    }

    /// Until spotread asks for the key that takes a reading; a calibration
    /// request is relayed to the operator (once per run is what instruments ask).
    void wait_until_ready(PatchScreen* screen, const char* doing) {
        while (!ready_) {
            const spotread::Scan s = wait_for_event(screen, doing);
            if (s.state == spotread::State::ready) {
                prompt_ = process_->output().substr(0, s.end);  // the reading's transcript starts with it
                process_->consume(s.end);
                ready_ = true;
            } else if (s.state == spotread::State::calibration) {
                calibrate(s);
            } else {
                fail(s, doing);
            }
        }
    }

    void calibrate(const spotread::Scan& s) {
        const std::string what = spotread::calibration_instruction(process_->output());
        if (!isatty(STDIN_FILENO))
            throw InstrumentError(fmt::format(
                "the instrument needs calibrating before it can measure (spotread: \"{}\") and there is no terminal to "
                "ask: run `atonlab calibrate` from a terminal, where you are asked once, or calibrate it with "
                "`spotread "
                "-e` and run again with --instrument-args \"-N\" (no calibration at start)",
                what));
        std::printf("\nthe instrument needs calibrating: %s.\n  Do it, then press Enter (q then Enter gives up): ",
                    what.c_str());
        std::fflush(stdout);
        std::string answer;
        if (!std::getline(std::cin, answer) || answer == "q" || answer == "Q")
            throw InstrumentError("the instrument's calibration was given up");
        process_->consume(s.end);
        process_->send(" ");  // "and then hit any key to continue"
        std::printf("  calibrating ...\n");
        std::fflush(stdout);
    }

    [[noreturn]] void fail(const spotread::Scan& s, const char* doing) {
        const std::string& line = s.line;
        auto has = [&](std::string_view w) { return line.find(w) != std::string::npos; };
        if (has("No instrument") || has("no instrument"))
            throw InstrumentError(fmt::format(
                "no instrument was found (spotread: \"{}\"): connect the colorimeter or spectroradiometer, check that "
                "`spotread -?` lists it under -c, and choose it with --instrument-args \"-c N\"",
                line));
        if (s.state == spotread::State::result || s.state == spotread::State::ready)
            throw InstrumentError(fmt::format("spotread said \"{}\" when asked {}", line, doing));
        throw InstrumentError(fmt::format("spotread reported an error when asked {}: \"{}\"", doing, line));
    }

    InstrumentOptions o_;
    std::string command_;
    std::unique_ptr<PtyProcess> process_;
    bool ready_ = false;
    std::string prompt_;
};

}  // namespace

std::unique_ptr<Instrument> open_spotread(const InstrumentOptions& options) {
    return std::make_unique<Spotread>(options);
}

}  // namespace atonlab::runner
