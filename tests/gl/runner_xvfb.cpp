// The full-screen runner as a person uses it, under Xvfb (CTest GL.runner.*,
// run by tests/gl/run_under_xvfb.sh --framebuffer-file on a 640x360 screen
// whose pixels Xvfb keeps in a file). `atonlab run` opens full screen on the virtual
// monitor, paced by --software-vsync 60 (Xvfb has no vertical blank); keys
// are real X key events sent through the XTEST extension by xdotool, each
// sent when the runner's --trace says it waits for one (no sleeps).
//
//  - Keyboard: a scripted key sequence through instructions, a break, a
//    skipped adaptation and the end screen gives the stored answers the
//    protocol's key bindings say ("1" is Left, "j" is Yes); the adjustment
//    keys step the level by the protocol's coarse and fine steps.
//  - Pause and quit: Escape, Escape leaves the session "quit" (exit status 6);
//    --resume-last completes it (with a pause and "go on" on the way) with the
//    trial sequence the uninterrupted schedule gives.
//  - Timing: the refresh period is measured at start; a display whose rate is
//    not the protocol's refuses with exit status 5, and one of another size
//    than the protocol's with 2, both before the study file is created (an
//    existing one is left byte for byte); an injected stall of 6 refreshes marks
//    its trial (missed_deadline, dropped_frames >= 5) and, with repeat_missed,
//    the trial is shown again and the procedure sees one answer.
//  - The screen (Xvfb's framebuffer, read from its -fbdir file) shows, code for
//    code, the frame `atonlab render` makes headless from the same overrides,
//    and the frame the same session run headless captures.
#include <fcntl.h>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "../store/store_test_support.h"
#include "../support/child_process.h"
#include "atonlab/protocols/protocol_file.h"
#include "atonlab/protocols/protocol_schedule.h"
#include "atonlab/stimuli/image_io.h"
#include "atonlab/store/json.h"
#include "atonlab/store/store.h"
#include "../support/skip.h"

#ifndef ATONLAB_BINARY
#error "ATONLAB_BINARY (the atonlab executable) must be defined by the build"
#endif

namespace atonlab {
namespace {

namespace fs = std::filesystem;
using store::Store;
using store::TrialRecord;
using store::test_support::file_bytes;
using store::test_support::RawDb;
using store::test_support::TempDir;

const fs::path kData = fs::path(ATONLAB_SOURCE_DIR) / "tests/data/runner";

bool have_display() {
    return std::getenv("DISPLAY") != nullptr;
}

using test::status_code;

/// A child process, stdout and stderr to files.
struct Child {
    pid_t pid = -1;
    fs::path out, err;
};

Child spawn(const std::vector<std::string>& args, const fs::path& out, const fs::path& err) {
    Child c{-1, out, err};
    c.pid = fork();
    if (c.pid == 0) {
        const int o = open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        const int e = open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (o < 0 || e < 0 || dup2(o, 1) < 0 || dup2(e, 2) < 0) _exit(120);
        std::vector<std::string> argv = args;
        std::vector<char*> cargs;
        for (std::string& a : argv) cargs.push_back(a.data());
        cargs.push_back(nullptr);
        execvp(cargs[0], cargs.data());
        _exit(122);
    }
    return c;
}

/// Waits for the child (killing it after `limit_s`); its exit status. The
/// limit only ends a hang: a run here takes at most ~15 s on the 2-core
/// development VM, and 600 s holds on a machine ten times slower or loaded
/// (scripts/test-under-load.sh); nothing passes or fails by its speed.
int finish(const Child& c, double limit_s = 600.0) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(limit_s);
    int status = 0;
    while (waitpid(c.pid, &status, WNOHANG) == 0) {
        if (std::chrono::steady_clock::now() > until) {
            kill(c.pid, SIGKILL);
            waitpid(c.pid, &status, 0);
            ADD_FAILURE() << "the runner did not finish within " << limit_s << " s";
            return -1;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return status_code(status);
}

std::size_t count_of(const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

/// Waits until the child's stdout holds `line` `times` times (the runner
/// traces what each screen waits for); false if it exits first or after 300 s
/// (a hang: each screen comes within seconds, ten times that on a loaded machine).
bool wait_for(const Child& c, const std::string& line, std::size_t times = 1) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(300);
    while (std::chrono::steady_clock::now() < until) {
        if (count_of(file_bytes(c.out), line) >= times) return true;
        int status = 0;
        if (waitpid(c.pid, &status, WNOHANG) == c.pid) {
            ADD_FAILURE() << "the runner exited (" << status_code(status) << ") before \"" << line << "\"\n"
                          << file_bytes(c.out) << file_bytes(c.err);
            return false;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ADD_FAILURE() << "no \"" << line << "\" within 300 s\n" << file_bytes(c.out) << file_bytes(c.err);
    return false;
}

/// One key press and release through XTEST (xdotool), as a keyboard gives it.
void press(const std::string& keysym) {
    const pid_t pid = fork();
    if (pid == 0) {
        execlp("xdotool", "xdotool", "key", keysym.c_str(), static_cast<char*>(nullptr));
        _exit(122);
    }
    int status = 0;
    waitpid(pid, &status, 0);
    ASSERT_EQ(status_code(status), 0) << "xdotool key " << keysym;
}

class runner : public ::testing::Test {
protected:
    void SetUp() override {
        if (!have_display()) ATONLAB_SKIP_NO_GPU() << "no display server (DISPLAY unset); CTest runs this under Xvfb";
    }
    fs::path db() const { return dir_.path() / "study.db"; }
    Child start(const fs::path& protocol, const std::vector<std::string>& extra, const std::string& tag = "a") {
        std::vector<std::string> args{ATONLAB_BINARY,     "run", protocol.string(),  "--db",    db().string(),
                                      "--software-vsync", "60",  "--skip-sync-test", "--trace", "--no-true-pse"};
        args.insert(args.end(), extra.begin(), extra.end());
        return spawn(args, dir_.path() / (tag + ".out"), dir_.path() / (tag + ".err"));
    }
    TempDir dir_;
};

std::string state_field(const TrialRecord& t, const std::string& key) {
    const std::string tag = "\"" + key + "\":\"";
    const auto at = t.procedure_state_json.find(tag);
    if (at == std::string::npos) return {};
    const auto end = t.procedure_state_json.find('"', at + tag.size());
    return t.procedure_state_json.substr(at + tag.size(), end - at - tag.size());
}

/// The trials the schedule proposes for these answers, checked against the
/// stored ones; `complete`: they finish the schedule (else a prefix of it).
void expect_schedule(const fs::path& protocol_file, std::uint64_t seed, const std::vector<TrialRecord>& trials,
                     bool complete = true) {
    const protocols::Protocol protocol = protocols::load_protocol(protocol_file);
    protocols::Schedule schedule(protocol, seed);
    for (const TrialRecord& t : trials) {
        SCOPED_TRACE("trial " + std::to_string(t.trial_index));
        const auto next = schedule.next();
        ASSERT_TRUE(next.has_value());
        EXPECT_EQ(t.condition_id, next->condition_id);
        EXPECT_EQ(t.procedure_id, next->procedure_id);
        EXPECT_EQ(t.level, next->proposal.level);
        EXPECT_EQ(t.test_on_left, next->proposal.test_on_left);
        if (t.response == "missed" || t.response == "timeout") continue;
        const std::map<std::string, protocols::Response> words{{"left", protocols::Response::Left},
                                                               {"right", protocols::Response::Right},
                                                               {"yes", protocols::Response::Yes},
                                                               {"no", protocols::Response::No}};
        ASSERT_TRUE(words.count(t.response)) << t.response;
        schedule.record(words.at(t.response));
    }
    EXPECT_EQ(schedule.finished(), complete);
}

/// "measured 16.6535 ms ± 0.1234 ms": the period and SD the runner reported, ms (defined below).
std::pair<double, double> measured(const std::string& out);

// --- Keys ----------------------------------------------------------------------

TEST_F(runner, KeyboardAnswersReachTheProcedureWithTheProtocolsMapping) {
    const fs::path protocol = kData / "screen_keys.toml";
    const Child c = start(protocol, {"--observer", "P01"});
    ASSERT_TRUE(wait_for(c, "waiting for continue (instructions)"));
    press("space");
    ASSERT_TRUE(wait_for(c, "trial 1: waiting for an answer"));
    press("1");  // bound to Left by [responses.keys]
    ASSERT_TRUE(wait_for(c, "trial 2: waiting for an answer"));
    press("Right");
    ASSERT_TRUE(wait_for(c, "waiting for continue (break)"));
    press("Return");
    ASSERT_TRUE(wait_for(c, "adapting for 60 s"));
    press("space");  // adaptation_skippable
    ASSERT_TRUE(wait_for(c, "trial 3: waiting for an answer"));
    press("j");  // bound to Yes
    ASSERT_TRUE(wait_for(c, "trial 4: waiting for an answer"));
    press("n");
    ASSERT_TRUE(wait_for(c, "waiting for continue (end)"));
    press("space");
    ASSERT_EQ(finish(c), 0) << file_bytes(c.out) << file_bytes(c.err);
    const double period_ms = measured(file_bytes(c.out)).first;
    ASSERT_GT(period_ms, 0.0) << file_bytes(c.out);
    const long n_stim = std::max(1L, std::lround(100.0 / period_ms)), n_isi = std::lround(50.0 / period_ms);

    Store s = Store::open_read_only(db());
    const auto sessions = s.sessions();
    ASSERT_EQ(sessions.size(), 1u);
    EXPECT_EQ(sessions[0].status, store::SessionStatus::completed);
    EXPECT_EQ(sessions[0].observer_code, "P01");
    const auto trials = s.trials(sessions[0].id);
    ASSERT_EQ(trials.size(), 4u);
    const std::vector<std::string> responses{"left", "right", "yes", "no"};
    const std::vector<std::string> inputs{"1", "right", "j", "n"};
    double last_onset = -1.0;
    for (std::size_t i = 0; i < 4; ++i) {
        SCOPED_TRACE(i);
        EXPECT_EQ(trials[i].response, responses[i]);
        EXPECT_EQ(state_field(trials[i], "input"), inputs[i]);
        EXPECT_EQ(state_field(trials[i], "observer"), "person");
        // Onset to the key press: after the stimulus began, within the 300 s the test waits for a screen (a hang's bound).
        EXPECT_GT(trials[i].response_time_s, 0.0);
        EXPECT_LT(trials[i].response_time_s, 300.0);
        EXPECT_GT(trials[i].onset_time_s, last_onset);
        last_onset = trials[i].onset_time_s;
        // 0.1 s intervals are 6 frames at the measured ~60 Hz, the 0.05 s blank 3:
        // whole refreshes at the period the runner measured (on a loaded
        // machine the software vsync's period measures longer, and so fewer).
        EXPECT_NE(trials[i].stimulus_json.find(fmt::format("\"stimulus_frames\":{}", n_stim)), std::string::npos)
            << trials[i].stimulus_json;
    }
    EXPECT_NE(trials[0].stimulus_json.find(fmt::format("\"inter_stimulus_frames\":{}", n_isi)), std::string::npos);
    // A 2AFC answer comes after the second interval's onset: at least 6 + 3 frames after the first.
    EXPECT_GT(trials[0].response_time_s, static_cast<double>(n_stim + n_isi) * period_ms * 1e-3 * 60.0 / 61.0);
    expect_schedule(protocol, 11, trials);
}

TEST_F(runner, EscapeThenConfirmQuitsAndResumeCompletesTheSameSequence) {
    const fs::path protocol = kData / "screen_keys.toml";
    {
        const Child c = start(protocol, {"--observer", "P02"});
        ASSERT_TRUE(wait_for(c, "waiting for continue (instructions)"));
        press("space");
        ASSERT_TRUE(wait_for(c, "trial 1: waiting for an answer"));
        press("Left");
        ASSERT_TRUE(wait_for(c, "trial 2: waiting for an answer"));
        press("Escape");
        ASSERT_TRUE(wait_for(c, "trace: pause"));
        press("Escape");  // confirm
        ASSERT_EQ(finish(c), 6) << file_bytes(c.out) << file_bytes(c.err);
        EXPECT_NE(file_bytes(c.out).find("continue with --resume"), std::string::npos) << file_bytes(c.out);
    }
    {
        Store s = Store::open_read_only(db());
        ASSERT_EQ(s.sessions().size(), 1u);
        EXPECT_EQ(s.sessions()[0].status, store::SessionStatus::quit);
        const auto trials = s.trials(s.sessions()[0].id);
        ASSERT_EQ(trials.size(), 1u) << "the paused trial is not stored";
        EXPECT_EQ(trials[0].response, "left");
    }
    {
        const Child c = start(protocol, {"--observer", "P02", "--resume-last"}, "b");
        ASSERT_TRUE(wait_for(c, "waiting for continue (instructions)"));
        press("space");
        ASSERT_TRUE(wait_for(c, "trial 2: waiting for an answer"));
        press("Right");
        ASSERT_TRUE(wait_for(c, "waiting for continue (break)"));
        press("space");
        ASSERT_TRUE(wait_for(c, "adapting for 60 s"));
        press("space");
        ASSERT_TRUE(wait_for(c, "trial 3: waiting for an answer"));
        press("Escape");  // pause, then go on: the trial is shown again
        ASSERT_TRUE(wait_for(c, "trace: pause"));
        press("space");
        ASSERT_TRUE(wait_for(c, "trial 3: waiting for an answer", 2));
        press("y");
        ASSERT_TRUE(wait_for(c, "trial 4: waiting for an answer"));
        press("n");
        ASSERT_TRUE(wait_for(c, "waiting for continue (end)"));
        press("space");
        ASSERT_EQ(finish(c), 0) << file_bytes(c.out) << file_bytes(c.err);
    }
    Store s = Store::open_read_only(db());
    EXPECT_EQ(s.integrity_check(), "ok");
    const auto sessions = s.sessions();
    ASSERT_EQ(sessions.size(), 1u);
    EXPECT_EQ(sessions[0].status, store::SessionStatus::completed);
    EXPECT_EQ(sessions[0].resume_count, 1);
    const auto trials = s.trials(sessions[0].id);
    ASSERT_EQ(trials.size(), 4u);
    EXPECT_EQ(trials[0].response, "left");
    EXPECT_EQ(trials[1].response, "right");
    EXPECT_EQ(trials[2].response, "yes");
    EXPECT_EQ(trials[3].response, "no");
    // The same sequence an uninterrupted session gives for these answers.
    expect_schedule(protocol, 11, trials);
}

TEST_F(runner, AdjustmentKeysStepTheLevelWhileTheIntervalsAlternate) {
    const fs::path protocol = kData / "screen_adjust.toml";
    const Child c = start(protocol, {"--observer", "P03"});
    // Each action is one stored trial; the stimulus repeats until the key.
    ASSERT_TRUE(wait_for(c, "trial 1: presenting"));
    press("Up");  // coarse up
    ASSERT_TRUE(wait_for(c, "trial 2: presenting"));
    press("Left");  // fine down
    ASSERT_TRUE(wait_for(c, "trial 3: presenting"));
    press("Return");  // confirm
    ASSERT_EQ(finish(c), 0) << file_bytes(c.out) << file_bytes(c.err);
    Store s = Store::open_read_only(db());
    const auto trials = s.trials(s.sessions()[0].id);
    ASSERT_EQ(trials.size(), 3u);
    EXPECT_EQ(trials[0].response, "coarse_up");
    EXPECT_EQ(trials[1].response, "fine_down");
    EXPECT_EQ(trials[2].response, "confirm");
    // The protocol's steps: +0.1, then −0.01 log10 cd; the match is the level confirmed.
    EXPECT_NEAR(trials[1].level - trials[0].level, 0.1, 1e-9);
    EXPECT_NEAR(trials[2].level - trials[1].level, -0.01, 1e-9);
    ASSERT_TRUE(trials[2].response_value.has_value());
    EXPECT_NEAR(*trials[2].response_value, std::pow(10.0, trials[2].level), 1e-9 * *trials[2].response_value);
    for (const TrialRecord& t : trials) EXPECT_GT(t.response_time_s, 0.0);
}

// --- Timing --------------------------------------------------------------------

std::pair<double, double> measured(const std::string& out) {
    const auto at = out.find("measured ");
    if (at == std::string::npos) return {0.0, 0.0};
    const double period = std::atof(out.c_str() + at + 9);
    const auto pm = out.find("± ", at);
    const double sd = pm == std::string::npos ? 0.0 : std::atof(out.c_str() + pm + 3);
    return {period, sd};
}

TEST_F(runner, AStalledTrialIsMarkedAndRepeatedAndThePeriodIsMeasured) {
    const fs::path protocol = kData / "screen_stall.toml";
    const Child c = start(protocol, {"--model-observer", "--inject-stall-frames", "6", "--inject-stall-at-trial", "1"});
    // 0: completed. 7: on a loaded machine (scripts/test-under-load.sh) other
    // presentations missed too and the run stopped at the protocol's bound
    // (default: more than ceil(10 % of 4) = 1 missed), as it should (issue 41).
    const int code = finish(c);
    ASSERT_TRUE(code == 0 || code == 7) << code << "\n" << file_bytes(c.out) << file_bytes(c.err);
    const auto [period_ms, sd_ms] = measured(file_bytes(c.out));
    std::printf("measured under Xvfb (software vsync 60 Hz): %.4f ms ± %.4f ms\n", period_ms, sd_ms);
    // The software vsync ticks every 1/60 s; where its flips were regular (the
    // SD under the 1 ms the sync test asks for: this test skips that test), the
    // mean of the kept intervals is that. On a loaded machine its timer wakes
    // late, the intervals are irregular and the mean is not the tick (a real
    // session would be refused, exit 5): not checked then, the load being no
    // error of the program (the estimate itself is tested on synthetic
    // timestamps, unit.RefreshEstimate.*).
    if (sd_ms < 1.0)
        EXPECT_NEAR(period_ms, 1000.0 / 60.0, 0.5) << file_bytes(c.out);
    else
        std::printf("loaded machine: flips irregular (SD %.3f ms), the period is not checked\n", sd_ms);

    Store s = Store::open_read_only(db());
    const store::SessionRecord session = s.sessions()[0];
    const auto trials = s.trials(session.id);
    ASSERT_GE(trials.size(), 2u) << "the stalled trial is stored";
    const TrialRecord& stalled = trials[1];
    EXPECT_TRUE(stalled.missed_deadline);
    EXPECT_GE(stalled.dropped_frames, 5);
    EXPECT_EQ(stalled.response, "missed") << "repeat_missed: the procedure does not see it";
    EXPECT_FALSE(state_field(stalled, "answer").empty()) << "the answer given is kept";
    // Every missed trial (the stalled one; on a busy machine maybe others) is
    // followed by the same proposal, shown again.
    for (std::size_t i = 0; i + 1 < trials.size(); ++i)
        if (trials[i].response == "missed") {
            EXPECT_EQ(trials[i + 1].procedure_id, trials[i].procedure_id) << i;
            EXPECT_EQ(trials[i + 1].level, trials[i].level) << i;
            EXPECT_EQ(trials[i + 1].test_on_left, trials[i].test_on_left) << i;
        }
    const auto missed = std::count_if(trials.begin(), trials.end(), [](const TrialRecord& t) { return t.response == "missed"; });
    std::printf("exit status %d: %zu trials stored, %ld missed\n", code, trials.size(), static_cast<long>(missed));
    if (code == 7) {
        EXPECT_EQ(session.status, store::SessionStatus::quit);
        ASSERT_TRUE(session.stop_json.has_value());
        EXPECT_NE(session.stop_json->find("\"reason\":\"missed_"), std::string::npos) << *session.stop_json;
        EXPECT_LE(missed, 2) << "at most one missed is allowed: the second stops the run";
        expect_schedule(protocol, 5, trials, false);
        return;
    }
    EXPECT_EQ(static_cast<long>(trials.size()) - missed, 4);
    expect_schedule(protocol, 5, trials);
}

/// The presentation margin displayability_json stored ("presentation"), parsed.
nlohmann::json stored_margin(const fs::path& db) {
    Store s = Store::open_read_only(db);
    const auto j = store::parse_json(s.sessions().at(0).displayability_json.value_or("{}"));
    return j.contains("presentation") ? j.at("presentation") : nlohmann::json();
}

TEST_F(runner, ThePresentationMarginIsMeasuredStoredAndShown) {
    const fs::path protocol = kData / "screen_stall.toml";
    const Child c = start(protocol, {"--model-observer"});
    const int code = finish(c);
    ASSERT_TRUE(code == 0 || code == 7) << code << "\n" << file_bytes(c.out) << file_bytes(c.err);
    const std::string out = file_bytes(c.out);
    EXPECT_NE(out.find("presentation margin"), std::string::npos) << out;
    const nlohmann::json m = stored_margin(db());
    ASSERT_TRUE(m.is_object()) << "on screen the margin is stored with the session";
    EXPECT_EQ(m.at("condition"), "pair");
    EXPECT_EQ(m.at("animated"), false);
    EXPECT_EQ(m.at("times"), 30);
    // The period is the start-up measurement's (printed to 4 decimals in ms).
    EXPECT_NEAR(m.at("period_s").get<double>() * 1e3, measured(out).first, 1e-4);
    const double show = m.at("show_s").get<double>(), period = m.at("period_s").get<double>();
    EXPECT_GT(show, 0.0);
    EXPECT_GT(m.at("draw_s").get<double>(), 0.0);
    EXPECT_GE(m.at("upload_s").get<double>(), 0.0);
    EXPECT_GE(m.at("worst_show_s").get<double>(), show);
    EXPECT_DOUBLE_EQ(m.at("margin").get<double>(), 1.0 - show / period);
    // analyze shows it, rounded to a whole per cent.
    const Child an = spawn({ATONLAB_BINARY, "analyze", db().string(), "--out", (dir_.path() / "rep").string(),
                            "--bootstrap", "0"},
                           dir_.path() / "an.out", dir_.path() / "an.err");
    ASSERT_EQ(finish(an), 0) << file_bytes(an.err);
    const std::string shown = fmt::format("presentation margin {:.0f} %", m.at("margin").get<double>() * 100.0);
    EXPECT_NE(file_bytes(an.out).find(shown), std::string::npos) << shown << "\n" << file_bytes(an.out);
    EXPECT_NE(file_bytes(dir_.path() / "rep" / "report.html").find("presentation margin"), std::string::npos);
}

TEST_F(runner, ASlowFrameIsWarnedAboutAndRefusedUnderStrictTiming) {
    const fs::path protocol = kData / "screen_stall.toml";
    // 12 ms added to each timed frame: it takes at least 12 of the 16.7 ms
    // refresh, a margin of at most 28 %, on any machine (load only adds to it).
    const Child c = start(protocol, {"--model-observer", "--inject-frame-cost-ms", "12"});
    const int code = finish(c);
    ASSERT_TRUE(code == 0 || code == 7) << code << "\n" << file_bytes(c.out) << file_bytes(c.err);
    EXPECT_NE(file_bytes(c.err).find("warning: presentation margin"), std::string::npos) << file_bytes(c.err);
    EXPECT_LE(stored_margin(db()).at("margin").get<double>(), 1.0 - 12.0 / 16.7);
    // 40 ms: longer than a refresh. --strict-timing refuses before the study file is created.
    fs::remove(db());
    const Child strict = start(protocol, {"--model-observer", "--inject-frame-cost-ms", "40", "--strict-timing"}, "s");
    ASSERT_EQ(finish(strict), 5) << file_bytes(strict.out) << file_bytes(strict.err);
    EXPECT_NE(file_bytes(strict.err).find("under --strict-timing the session is not started"), std::string::npos)
        << file_bytes(strict.err);
    EXPECT_FALSE(fs::exists(db()));
}

TEST_F(runner, WithoutRepeatMissedTheStalledTrialIsMarkedAndCounted) {
    // The same protocol without repeat_missed (the scene path made absolute).
    std::string text = file_bytes(kData / "screen_stall.toml");
    text.replace(text.find("repeat_missed = true"), 20, "repeat_missed = false");
    text.replace(text.find("\"screen.scene.toml\""), 19, "\"" + (kData / "screen.scene.toml").string() + "\"");
    const fs::path protocol = dir_.path() / "no_repeat.toml";
    std::ofstream(protocol) << text;
    const Child c = start(protocol, {"--model-observer", "--inject-stall-frames", "6", "--inject-stall-at-trial", "2"});
    ASSERT_EQ(finish(c), 0) << file_bytes(c.out) << file_bytes(c.err);
    Store s = Store::open_read_only(db());
    const auto trials = s.trials(s.sessions()[0].id);
    ASSERT_EQ(trials.size(), 4u);
    EXPECT_TRUE(trials[2].missed_deadline);
    EXPECT_GE(trials[2].dropped_frames, 5);
    EXPECT_TRUE(trials[2].response == "left" || trials[2].response == "right") << trials[2].response;
    expect_schedule(protocol, 5, trials);
}

TEST_F(runner, ADisplayAtAnotherRateThanTheProtocolsRefusesToStart) {
    // screen_stall.toml is written for 60 Hz ([timing] refresh_hz); the
    // display ticks at 50 Hz (17 % off, more than the 2 % allowed). The SD
    // criterion is relaxed so that the rate is what refuses, whatever the load.
    std::vector<std::string> args{ATONLAB_BINARY,
                                  "run",
                                  (kData / "screen_stall.toml").string(),
                                  "--db",
                                  db().string(),
                                  "--model-observer",
                                  "--software-vsync",
                                  "50",
                                  "--sync-sd-max-ms",
                                  "50"};
    const Child c = spawn(args, dir_.path() / "r.out", dir_.path() / "r.err");
    ASSERT_EQ(finish(c), 5) << file_bytes(c.out) << file_bytes(c.err);
    // One sentence on one line (other lines may note other things, e.g. the calibration).
    const std::string err = file_bytes(c.err);
    const auto at = err.find("atonlab: monitor 0");
    ASSERT_NE(at, std::string::npos) << err;
    const std::string line = err.substr(at, err.find('\n', at) - at);
    // The protocol's rate refuses it. On a loaded machine the software vsync's
    // flips come late (its timer wakes late) and the measurement may refuse
    // first, by its own rules (the rate against the display's 50 Hz, too few
    // regular flips): a refusal all the same, before anything is written.
    const bool by_protocol = line.find("written for 60 Hz") != std::string::npos;
    const bool by_measurement = line.find("the measured refresh rate") != std::string::npos ||
                                line.find("of the flip intervals in") != std::string::npos;
    EXPECT_TRUE(by_protocol || by_measurement) << line;
    if (!by_protocol) std::printf("loaded machine: refused by the measurement itself: %s\n", line.c_str());
    EXPECT_NE(line.find("not started"), std::string::npos) << line;
    EXPECT_FALSE(fs::exists(db())) << "the screen is refused before the study file is created";

    // An existing study file: refused the same way, and left byte for byte as it was.
    {
        Store s = Store::create_or_open(db());
        store::SessionStart start;
        start.observer_code = "P01";
        start.protocol_name = "other.toml";
        start.protocol_text = "[protocol]\n";
        s.begin_session(start);
    }
    const std::string before = file_bytes(db());
    const Child again = spawn(args, dir_.path() / "r2.out", dir_.path() / "r2.err");
    ASSERT_EQ(finish(again), 5) << file_bytes(again.err);
    EXPECT_EQ(file_bytes(db()), before);
}

TEST_F(runner, AScreenOfAnotherSizeThanTheProtocolsLeavesNoStudyFile) {
    // small_2afc.toml is written for 320 x 180 px; the Xvfb screen is 640 x 360.
    std::vector<std::string> args{ATONLAB_BINARY,
                                  "run",
                                  (fs::path(ATONLAB_SOURCE_DIR) / "tests/data/run/small_2afc.toml").string(),
                                  "--db",
                                  db().string(),
                                  "--model-observer",
                                  "--software-vsync",
                                  "60",
                                  "--skip-sync-test"};
    const Child c = spawn(args, dir_.path() / "r.out", dir_.path() / "r.err");
    ASSERT_EQ(finish(c), 2) << file_bytes(c.out) << file_bytes(c.err);
    EXPECT_NE(file_bytes(c.err).find("320×180"), std::string::npos) << file_bytes(c.err);
    EXPECT_FALSE(fs::exists(db())) << "the screen is refused before the study file is created";
}

// --- The screen's pixels ----------------------------------------------------------

/// An XWD file (X Window Dump, X11's xwd format): 8-bit RGB, row 0 at the top.
struct Xwd {
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgb;
};

Xwd read_xwd(const fs::path& path) {
    const std::string d = file_bytes(path);
    auto be32 = [&](std::size_t i) {
        const auto* b = reinterpret_cast<const unsigned char*>(d.data()) + 4 * i;
        return (std::uint32_t{b[0]} << 24) | (std::uint32_t{b[1]} << 16) | (std::uint32_t{b[2]} << 8) | b[3];
    };
    Xwd x;
    if (d.size() < 100) return x;
    const std::uint32_t header = be32(0), format = be32(2), bpp = be32(11), bpl = be32(12), ncolors = be32(19);
    const std::uint32_t order = be32(7), red = be32(14), green = be32(15), blue = be32(16);
    EXPECT_EQ(format, 2u) << "ZPixmap";
    EXPECT_EQ(bpp, 32u);
    x.width = static_cast<int>(be32(4));
    x.height = static_cast<int>(be32(5));
    const std::size_t off = header + 12 * ncolors;
    if (d.size() < off + static_cast<std::size_t>(bpl) * x.height) return Xwd{};
    auto channel = [](std::uint32_t v, std::uint32_t mask) {
        int shift = 0;
        while (mask && !(mask & 1u)) {
            mask >>= 1;
            ++shift;
        }
        return static_cast<std::uint8_t>((v >> shift) & mask);
    };
    for (int y = 0; y < x.height; ++y)
        for (int i = 0; i < x.width; ++i) {
            const auto* b = reinterpret_cast<const unsigned char*>(d.data()) + off + static_cast<std::size_t>(y) * bpl +
                            4 * static_cast<std::size_t>(i);
            const std::uint32_t v =
                order == 0
                    ? (std::uint32_t{b[3]} << 24) | (std::uint32_t{b[2]} << 16) | (std::uint32_t{b[1]} << 8) | b[0]
                    : (std::uint32_t{b[0]} << 24) | (std::uint32_t{b[1]} << 16) | (std::uint32_t{b[2]} << 8) | b[3];
            x.rgb.push_back(channel(v, red));
            x.rgb.push_back(channel(v, green));
            x.rgb.push_back(channel(v, blue));
        }
    return x;
}

TEST_F(runner, TheScreenShowsTheCodesTheHeadlessRendererMakes) {
    const char* screen_file = std::getenv("ATONLAB_XVFB_SCREEN_FILE");
    if (!screen_file) ATONLAB_SKIP_NOT_APPLICABLE() << "ATONLAB_XVFB_SCREEN_FILE unset (run_under_xvfb.sh --framebuffer-file sets it)";
    const fs::path protocol = kData / "screen_stall.toml";
    const fs::path shots = dir_.path() / "shots";
    // Trial 0 is all this needs: a script with one answer ends both runs after
    // it (exit status 2, "the script ran out", the session left open).
    const fs::path one = dir_.path() / "one.txt";
    std::ofstream(one) << "left\n";
    const Child c = start(protocol, {"--script", one.string(), "--capture-trial", "0", "--capture-dir", shots.string(),
                                     "--capture-screen-file", screen_file});
    ASSERT_EQ(finish(c), 2) << file_bytes(c.out) << file_bytes(c.err);
    // The same session headless: its capture of trial 0 is the frame's code values.
    const fs::path headless_shots = dir_.path() / "headless-shots";
    const Child headless =
        spawn({ATONLAB_BINARY, "run", protocol.string(), "--db", (dir_.path() / "headless.db").string(), "--script",
               one.string(), "--headless", "--quiet", "--capture-trial", "0", "--capture-dir", headless_shots.string()},
              dir_.path() / "h.out", dir_.path() / "h.err");
    ASSERT_EQ(finish(headless), 2) << file_bytes(headless.err);
    RawDb raw(db(), SQLITE_OPEN_READONLY);
    for (int f = 0; f < 2; ++f) {
        SCOPED_TRACE("frame " + std::to_string(f));
        // The frame, as X shows it.
        const Xwd screen = read_xwd(shots / ("trial0-frame" + std::to_string(f) + ".xwd"));
        ASSERT_EQ(screen.width, 640);
        ASSERT_EQ(screen.height, 360);
        // The same frame rendered headless by `atonlab render` from the stored overrides.
        const std::string overrides = raw.text("SELECT value FROM trials, json_each(trials.stimulus_json, '$.frames[" +
                                               std::to_string(f) + "].overrides') WHERE trial_index = 0");
        std::vector<std::string> args{ATONLAB_BINARY,
                                      "render",
                                      (kData / "screen.scene.toml").string(),
                                      "-o",
                                      (dir_.path() / "f.exr").string(),
                                      "--png",
                                      (dir_.path() / "f.png").string()};
        std::size_t at = 0;
        while (at <= overrides.size()) {
            const std::size_t end = std::min(overrides.find('\n', at), overrides.size());
            args.push_back("--set");
            args.push_back(overrides.substr(at, end - at));
            at = end + 1;
        }
        const Child r = spawn(args, dir_.path() / "render.out", dir_.path() / "render.err");
        ASSERT_EQ(finish(r), 0) << file_bytes(r.err);
        int w = 0, h = 0;
        const std::vector<float> png = stimuli::read_png_rgb(dir_.path() / "f.png", w, h);
        ASSERT_EQ(w, 640);
        ASSERT_EQ(h, 360);
        std::size_t differing = 0, lit = 0;
        for (std::size_t i = 0; i < png.size(); ++i) {
            const auto code = static_cast<int>(std::lround(png[i] * 255.0f));
            if (code != screen.rgb[i]) ++differing;
            if (screen.rgb[i] != screen.rgb[i % 3]) ++lit;  // differs from the top-left pixel: the light
        }
        EXPECT_EQ(differing, 0u) << "pixels the screen shows differently from the headless render";
        EXPECT_GT(lit, 30u) << "the frame shows a light, not only the uniform field";
        const std::vector<float> session =
            stimuli::read_png_rgb(headless_shots / ("trial0-frame" + std::to_string(f) + ".png"), w, h);
        ASSERT_EQ(session.size(), screen.rgb.size());
        std::size_t differing_session = 0;
        for (std::size_t i = 0; i < session.size(); ++i)
            if (static_cast<int>(std::lround(session[i] * 255.0f)) != screen.rgb[i]) ++differing_session;
        EXPECT_EQ(differing_session, 0u) << "pixels the screen shows differently from the headless session's frame";
    }
}

}  // namespace
}  // namespace atonlab
