// `atonlab run` end to end: the binary (ATONLAB_BINARY, set by
// tests/e2e/CMakeLists.txt) runs tests/data/run/small_2afc.toml (24 trials on a
// 320 x 180 display) with the model observer, headless, and these tests read
// the study file back through the store (read-only) and through SQLite itself.
//
//  - the stored trials are the schedule's, step by step (Schedule replayed
//    with the stored answers), every override in the stimulus JSON, a
//    snapshot per condition;
//  - SIGKILL at random moments, 8 times (20 with ATONLAB_LONG_TESTS=1): after each kill integrity_check is
//    ok, the trials are a prefix of an uninterrupted run's and cover every
//    trial the child reported committed; --resume-last continues and the
//    finished sessions equal the uninterrupted run, trial for trial;
//  - SIGTERM between trials: status "quit", exit status 143, resumable;
//  - a full disk (--db-max-bytes), a write-protected file, a newer schema:
//    exit status 4, one sentence, nothing stored lost (bytes unchanged where
//    nothing may be written).
// Skips where the binary finds no GL 4.5 context (exit status 3).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "../store/store_test_support.h"
#include "../support/child_process.h"
#include "../support/long_tests.h"
#include "atonlab/protocols/protocol_file.h"
#include "atonlab/protocols/protocol_schedule.h"
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

const fs::path kProtocol = fs::path(ATONLAB_SOURCE_DIR) / "tests/data/run/small_2afc.toml";
constexpr int kTrials = 24;

using test::status_code;
using test::wait_for;

pid_t spawn(const fs::path& db, const std::vector<std::string>& args, const fs::path& out, const fs::path& err,
            bool drop_root = false) {
    std::vector<std::string> argv{ATONLAB_BINARY, "run", kProtocol.string(), "--db", db.string(), "--headless"};
    if (std::find(args.begin(), args.end(), "--script") == args.end()) argv.push_back("--model-observer");
    argv.insert(argv.end(), args.begin(), args.end());
    return test::spawn_to_files(std::move(argv), out, err, false, drop_root);
}

std::string text_of(const fs::path& p) {
    return file_bytes(p);
}

/// The largest "trial N" the child's progress lines reported (0 if none).
long last_reported(const fs::path& out) {
    // (Not std::regex: GCC 12's <regex> trips -Wmaybe-uninitialized under the sanitizers.)
    const std::string text = text_of(out);
    const std::string tag = "trial ";
    long last = 0;
    for (auto at = text.find(tag); at != std::string::npos; at = text.find(tag, at + 1)) {
        long n = 0;
        bool digits = false;
        for (std::size_t i = at + tag.size(); i < text.size() && text[i] >= '0' && text[i] <= '9'; ++i) {
            n = n * 10 + (text[i] - '0');
            digits = true;
        }
        if (digits) last = std::max(last, n);
    }
    return last;
}

std::vector<TrialRecord> trials_of(const fs::path& db, store::SessionId session) {
    return Store::open_read_only(db).trials(session);
}

/// Same trial, as far as the schedule and the observer go: every field but
/// recorded_at; response and onset times within 1e-9 (they come from a
/// rendering, which a GPU need not reproduce to the last bit).
void expect_same_trial(const TrialRecord& got, const TrialRecord& want) {
    SCOPED_TRACE("trial " + std::to_string(want.trial_index));
    EXPECT_EQ(got.trial_index, want.trial_index);
    EXPECT_EQ(got.block, want.block);
    EXPECT_EQ(got.condition_id, want.condition_id);
    EXPECT_EQ(got.procedure_id, want.procedure_id);
    EXPECT_EQ(got.level, want.level);
    EXPECT_EQ(got.test_on_left, want.test_on_left);
    EXPECT_EQ(got.response, want.response);
    EXPECT_EQ(got.response_value, want.response_value);
    EXPECT_EQ(got.stimulus_json, want.stimulus_json);
    EXPECT_NEAR(got.response_time_s, want.response_time_s, 1e-9);
    EXPECT_NEAR(got.onset_time_s, want.onset_time_s, 1e-9);
    EXPECT_EQ(got.dropped_frames, 0);
}

void expect_prefix(const std::vector<TrialRecord>& got, const std::vector<TrialRecord>& reference) {
    ASSERT_LE(got.size(), reference.size());
    for (std::size_t i = 0; i < got.size(); ++i) expect_same_trial(got[i], reference[i]);
}

std::string json_escaped(const std::string& s) {
    std::string out;
    for (const char c : s) {
        if (c == '"' || c == '\\') out += '\\';
        out += c;
    }
    return out;
}

// Lower case, unlike the other suites, so that `ctest -R run` selects these
// with the e2e.run.* tests (CTest names: GL.run.<Test>).
class run : public ::testing::Test {
protected:
    /// One uninterrupted run, shared by the tests: the sequence every other run must reproduce.
    static void SetUpTestSuite() {
        ref_dir_ = new TempDir;
        const fs::path db = ref_dir_->path() / "reference.db";
        const auto started = std::chrono::steady_clock::now();
        const int code = wait_for(spawn(db, {"--quiet"}, ref_dir_->path() / "out", ref_dir_->path() / "err"));
        ref_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started).count();
        if (code == 3) {
            skip_ = "no GL 4.5 context: " + text_of(ref_dir_->path() / "err");
            return;
        }
        ref_code_ = code;
        ref_err_ = text_of(ref_dir_->path() / "err");
        if (code == 0) reference_ = trials_of(db, store::SessionId{1});
    }
    static void TearDownTestSuite() {
        delete ref_dir_;
        ref_dir_ = nullptr;
    }
    void SetUp() override {
        if (!skip_.empty()) ATONLAB_SKIP_NO_GPU() << skip_;
        ASSERT_EQ(ref_code_, 0) << ref_err_;
        ASSERT_EQ(reference_.size(), static_cast<std::size_t>(kTrials));
    }

    int run_study(const std::vector<std::string>& args, bool drop_root = false) {
        return wait_for(spawn(db(), args, out(), err(), drop_root));
    }
    fs::path db() const { return dir_.path() / "study.db"; }
    fs::path out() const { return dir_.path() / "stdout"; }
    fs::path err() const { return dir_.path() / "stderr"; }

    TempDir dir_;
    static inline TempDir* ref_dir_ = nullptr;
    static inline std::string skip_;
    static inline int ref_code_ = -1;
    static inline double ref_ms_ = 0.0;  ///< wall time of the uninterrupted run, ms
    static inline std::string ref_err_;
    static inline std::vector<TrialRecord> reference_;
};

TEST_F(run, TrialsAreTheSchedulesAndEachIsStoredWithItsStimulus) {
    ASSERT_EQ(run_study({"--quiet"}), 0) << text_of(err());
    EXPECT_EQ(text_of(out()), "") << "--quiet prints nothing";
    Store s = Store::open_read_only(db());
    EXPECT_EQ(s.integrity_check(), "ok");
    const auto sessions = s.sessions();
    ASSERT_EQ(sessions.size(), 1u);
    EXPECT_EQ(sessions[0].status, store::SessionStatus::completed);
    EXPECT_EQ(sessions[0].observer_code, "model");
    EXPECT_EQ(sessions[0].seed, 7u);
    EXPECT_TRUE(sessions[0].calibration.has_value()) << "the display is recorded";
    EXPECT_EQ(s.protocol_text(sessions[0].id), text_of(kProtocol));

    // Replay the stored answers through a fresh schedule: each stored trial is
    // what the schedule proposed at that step.
    const protocols::Protocol protocol = protocols::load_protocol(kProtocol);
    protocols::Schedule schedule(protocol, 7);
    const std::vector<TrialRecord> trials = s.trials(sessions[0].id);
    ASSERT_EQ(trials.size(), static_cast<std::size_t>(kTrials));
    double last_onset = -1.0;
    for (const TrialRecord& t : trials) {
        SCOPED_TRACE("trial " + std::to_string(t.trial_index));
        const auto next = schedule.next();
        ASSERT_TRUE(next.has_value());
        EXPECT_EQ(t.trial_index, static_cast<std::int64_t>(next->step));
        EXPECT_EQ(t.block, static_cast<int>(next->block));
        EXPECT_EQ(t.condition_id, next->condition_id);
        EXPECT_EQ(t.procedure_id, next->procedure_id);
        EXPECT_EQ(t.level, next->proposal.level);
        EXPECT_EQ(t.test_on_left, next->proposal.test_on_left);
        for (const auto& frame : next->stimulus.frames)
            for (const std::string& o : frame.override_texts())
                EXPECT_NE(t.stimulus_json.find("\"" + json_escaped(o) + "\""), std::string::npos) << o;
        // Where each frame's glare ran: the default two-scale eye's PSF on the
        // CPU on every driver; the bloom frame has no PSF; no `cie` veil.
        EXPECT_NE(t.stimulus_json.find(R"("placement":{"veil":"none","psf_fft":"cpu"})"), std::string::npos);
        EXPECT_NE(t.stimulus_json.find(R"("placement":{"veil":"none","psf_fft":"none"})"), std::string::npos);
        EXPECT_TRUE(t.response == "left" || t.response == "right") << t.response;
        // Two intervals of 0.5 s with 0.5 s between, then the model's answer.
        EXPECT_GE(t.response_time_s, 1.5);
        EXPECT_GT(t.onset_time_s, last_onset);
        last_onset = t.onset_time_s;
        EXPECT_EQ(t.dropped_frames, 0);
        EXPECT_NE(t.procedure_state_json.find("\"observer_seed\":"), std::string::npos);
        schedule.record(t.response == "left" ? protocols::Response::Left : protocols::Response::Right);
    }
    EXPECT_TRUE(schedule.finished());
    // The first block adapts 30 s (simulated), then the 0.8 s fixation: refresh 1848 at 60 Hz.
    EXPECT_DOUBLE_EQ(trials.front().onset_time_s, 30.8);
    // Both answers occur: the staircases reverse.
    EXPECT_NE(std::count_if(trials.begin(), trials.end(), [](const auto& t) { return t.response == "left"; }), 0);
    EXPECT_NE(std::count_if(trials.begin(), trials.end(), [](const auto& t) { return t.response == "right"; }), 0);

    // One scene-referred EXR per condition.
    for (const char* condition : {"dark-empirical", "dusk-perceptual"}) {
        const auto snap = s.get_snapshot(sessions[0].id, condition);
        ASSERT_TRUE(snap.has_value()) << condition;
        EXPECT_EQ(snap->format, "exr");
        ASSERT_GE(snap->data.size(), 4u);
        EXPECT_EQ(std::to_integer<int>(snap->data[0]), 0x76);  // OpenEXR magic 76 2f 31 01
        EXPECT_EQ(std::to_integer<int>(snap->data[1]), 0x2f);
    }
    // The same seeds give the same session.
    for (std::size_t i = 0; i < trials.size(); ++i) expect_same_trial(trials[i], reference_[i]);
}

TEST_F(run, KilledRepeatedlyEachResumeContinuesTheUninterruptedSequence) {
    // Kills between 0.3 and 0.9 of the time a whole run takes, so that most
    // land while a run is going on (a run first checks the protocol's
    // displayability, rendering frames before the study file is created: a
    // fixed 0.3-1.5 s killed every run before it on llvmpipe).
    std::mt19937 rng(20240611);
    std::uniform_int_distribution<int> delay_ms(static_cast<int>(0.3 * ref_ms_), static_cast<int>(0.9 * ref_ms_));
    // 8 kills in the suite's bounded form, 20 in the long form (tests/support/long_tests.h).
    const int wanted_kills = test::long_tests() ? 20 : 8;
    int kills = 0, runs = 0, mid_session = 0;
    std::size_t stored_before = 0;
    while (kills < wanted_kills) {
        ASSERT_LT(++runs, 400) << "the runs finish before they can be killed";
        // Continue the unfinished session if there is one, else begin one.
        bool unfinished = false;
        std::size_t sessions_before = 0;
        if (fs::exists(db())) {
            const auto before = Store::open_read_only(db()).sessions();
            sessions_before = before.size();
            for (const auto& r : before) unfinished = unfinished || r.status != store::SessionStatus::completed;
        }
        std::vector<std::string> args{"--progress-every", "1", "--no-true-pse"};
        if (unfinished) args.push_back("--resume-last");
        const pid_t pid = spawn(db(), args, out(), err());
        std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms(rng)));
        kill(pid, SIGKILL);
        const int code = wait_for(pid);
        if (code == 128 + SIGKILL) {
            ++kills;
        } else {
            ASSERT_EQ(code, 0) << text_of(err());
        }
        if (!fs::exists(db())) continue;  // killed before the study file was created
        // After each run: the file is sound, and each session is a prefix of
        // the uninterrupted run covering every trial the child reported.
        Store s = Store::open_read_only(db());
        ASSERT_EQ(s.integrity_check(), "ok");
        const auto sessions = s.sessions();
        for (const auto& r : sessions) {
            const auto trials = s.trials(r.id);
            expect_prefix(trials, reference_);
            if (r.status == store::SessionStatus::completed) {
                EXPECT_EQ(trials.size(), static_cast<std::size_t>(kTrials));
            } else {
                EXPECT_EQ(r.status, store::SessionStatus::running) << "a killed session stays running";
            }
        }
        // A fresh run killed while it still checked the protocol (before it
        // began its session) left the sessions as they were.
        const bool began = unfinished || sessions.size() > sessions_before;
        if (began && !sessions.empty() && code == 128 + SIGKILL) {
            const auto n = static_cast<long>(s.trials(sessions.back().id).size());
            const bool committed = static_cast<std::size_t>(n) > stored_before;
            if (committed) ++mid_session;  // it had committed trials when killed
            stored_before = static_cast<std::size_t>(n);
            const long reported = last_reported(out());
            EXPECT_GE(n, reported) << "a trial reported committed is missing";
            // (A resumed run killed while it still checked the protocol
            // committed and reported nothing of its own.)
            if (committed) {
                EXPECT_LE(n, reported + 1) << "at most the trial being reported when killed";
            }
        }
        if (code == 0 || (!sessions.empty() && sessions.back().status == store::SessionStatus::completed))
            stored_before = 0;  // a new session begins next (a run may be killed after completing, in its summary)
        if (testing::Test::HasFailure()) return;
    }
    // Finish the last session.
    ASSERT_TRUE(fs::exists(db())) << "every run was killed before it created the study file";
    bool unfinished = false;
    for (const auto& r : Store::open_read_only(db()).sessions())
        unfinished = unfinished || r.status != store::SessionStatus::completed;
    if (unfinished) {
        ASSERT_EQ(run_study({"--resume-last", "--quiet"}), 0) << text_of(err());
    }
    Store s = Store::open_read_only(db());
    const auto completed = s.sessions().size();
    ASSERT_GE(completed, 1u);
    EXPECT_EQ(s.integrity_check(), "ok");
    for (const auto& r : s.sessions()) {
        SCOPED_TRACE("session " + std::to_string(r.id.value));
        EXPECT_EQ(r.status, store::SessionStatus::completed);
        const auto trials = s.trials(r.id);
        ASSERT_EQ(trials.size(), static_cast<std::size_t>(kTrials));
        for (std::size_t i = 0; i < trials.size(); ++i) expect_same_trial(trials[i], reference_[i]);
    }
    std::printf(
        "[ run ] %d kills over %d runs (%d after the run had committed trials); %zu sessions completed, each "
        "equal to the uninterrupted run\n",
        kills, runs, mid_session, completed);
}

TEST_F(run, SigtermQuitsBetweenTrialsAndTheSessionContinues) {
    const pid_t pid = spawn(db(), {"--progress-every", "1"}, out(), err());
    // Up to 600 s for the third trial (a hang's bound, not a speed test): an
    // ASan build on 2 busy cores takes over 6 s to begin (the load-time checks
    // render every condition), and a machine ten times slower or loaded more.
    for (int i = 0; i < 60000 && last_reported(out()) < 3; ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    kill(pid, SIGTERM);
    const int code = wait_for(pid);
    if (code == 0) ATONLAB_SKIP_NOT_APPLICABLE() << "the session finished before SIGTERM arrived";
    ASSERT_EQ(code, 128 + SIGTERM) << text_of(err());
    {
        Store s = Store::open_read_only(db());
        const auto sessions = s.sessions();
        ASSERT_EQ(sessions.size(), 1u);
        EXPECT_EQ(sessions[0].status, store::SessionStatus::quit);
        const auto trials = s.trials(sessions[0].id);
        EXPECT_GE(trials.size(), 3u);
        expect_prefix(trials, reference_);
        EXPECT_NE(text_of(out()).find("--resume 1"), std::string::npos) << "says how to continue";
    }
    ASSERT_EQ(run_study({"--resume", "1", "--quiet"}), 0) << text_of(err());
    Store s = Store::open_read_only(db());
    const auto sessions = s.sessions();
    ASSERT_EQ(sessions.size(), 1u);
    EXPECT_EQ(sessions[0].status, store::SessionStatus::completed);
    EXPECT_EQ(sessions[0].resume_count, 1);
    const auto trials = s.trials(sessions[0].id);
    ASSERT_EQ(trials.size(), static_cast<std::size_t>(kTrials));
    for (std::size_t i = 0; i < trials.size(); ++i) expect_same_trial(trials[i], reference_[i]);
}

TEST_F(run, DiskFullStopsWithStatus4AndLosesNothing) {
    // Session 1 completes; session 2 may grow the file by the first
    // condition's snapshot and a few pages, and hits the limit.
    ASSERT_EQ(run_study({"--quiet"}), 0) << text_of(err());
    std::int64_t logical = 0, snapshot = 0;
    {
        RawDb raw(db());
        logical = raw.integer("PRAGMA page_count") * raw.integer("PRAGMA page_size");
        snapshot = raw.integer("SELECT length(data) FROM snapshots WHERE condition_id = 'dark-empirical'");
    }
    const std::vector<TrialRecord> first = trials_of(db(), store::SessionId{1});
    const std::int64_t limit = logical + snapshot + 24 * 1024;
    ASSERT_EQ(run_study({"--quiet", "--db-max-bytes", std::to_string(limit)}), 4) << text_of(err());
    const std::string message = text_of(err());
    EXPECT_EQ(std::count(message.begin(), message.end(), '\n'), 1) << message;
    EXPECT_NE(message.find("full"), std::string::npos) << message;
    EXPECT_NE(message.find("--resume 2"), std::string::npos) << message;
    std::size_t stored = 0;
    {
        Store s = Store::open_read_only(db());
        EXPECT_EQ(s.integrity_check(), "ok");
        const auto sessions = s.sessions();
        ASSERT_EQ(sessions.size(), 2u);
        EXPECT_EQ(sessions[0].status, store::SessionStatus::completed);
        EXPECT_EQ(sessions[1].status, store::SessionStatus::running);
        const auto again = s.trials(sessions[0].id);
        ASSERT_EQ(again.size(), first.size());
        for (std::size_t i = 0; i < first.size(); ++i) expect_same_trial(again[i], first[i]);
        const auto partial = s.trials(sessions[1].id);
        stored = partial.size();
        EXPECT_LT(partial.size(), static_cast<std::size_t>(kTrials));
        expect_prefix(partial, reference_);
    }
    // With room again, the session continues where it stopped.
    ASSERT_EQ(run_study({"--quiet", "--resume-last"}), 0) << text_of(err());
    const auto trials = trials_of(db(), store::SessionId{2});
    ASSERT_EQ(trials.size(), static_cast<std::size_t>(kTrials));
    for (std::size_t i = 0; i < trials.size(); ++i) expect_same_trial(trials[i], reference_[i]);
    std::printf("[ run ] limit %lld bytes: %zu trials stored before the file was full; message: %s",
                static_cast<long long>(limit), stored, message.c_str());
}

TEST_F(run, WriteProtectedFileStopsWithStatus4AndIsUnchanged) {
    ASSERT_EQ(run_study({"--quiet"}), 0) << text_of(err());
    const std::string before = file_bytes(db());
    ASSERT_EQ(chmod(db().c_str(), 0444), 0);
    // "nobody" must reach the directory (not write it) to be told the file is protected.
    ASSERT_EQ(chmod(dir_.path().c_str(), 0755), 0);
    const int code = run_study({"--quiet"}, /*drop_root=*/true);
    if (code == 121) ATONLAB_SKIP_NOT_APPLICABLE() << "running as root and cannot drop to nobody, for whom permissions apply";
    if (code == 123)
        ATONLAB_SKIP_NOT_APPLICABLE() << "nobody may not run " << ATONLAB_BINARY
                                      << ": a directory above it is not searchable by others (a mktemp -d checkout)";
    EXPECT_EQ(code, 4) << text_of(err());
    const std::string message = text_of(err());
    EXPECT_EQ(std::count(message.begin(), message.end(), '\n'), 1) << message;
    EXPECT_NE(message.find("write-protected"), std::string::npos) << message;
    EXPECT_EQ(file_bytes(db()), before) << "a write-protected study file is not changed";
    Store s = Store::open_read_only(db());
    ASSERT_EQ(s.sessions().size(), 1u);
    EXPECT_EQ(s.trials(store::SessionId{1}).size(), static_cast<std::size_t>(kTrials));
}

TEST_F(run, NewerSchemaStopsWithStatus4AndIsUnchanged) {
    ASSERT_EQ(run_study({"--quiet"}), 0) << text_of(err());
    {
        RawDb raw(db());
        ASSERT_EQ(raw.exec("PRAGMA user_version = 99"), "");
    }
    const std::string before = file_bytes(db());
    EXPECT_EQ(run_study({"--quiet"}), 4) << text_of(err());
    const std::string message = text_of(err());
    EXPECT_EQ(std::count(message.begin(), message.end(), '\n'), 1) << message;
    EXPECT_NE(message.find("newer atonlab"), std::string::npos) << message;
    EXPECT_EQ(file_bytes(db()), before);
    RawDb raw(db());
    EXPECT_EQ(raw.integer("SELECT count(*) FROM trials"), kTrials);
}

TEST_F(run, ScriptedObserverAnswersFromItsFile) {
    {
        std::ofstream script(dir_.path() / "answers.txt");
        script << "# the first interval, always\n";
        for (int i = 0; i < kTrials; ++i) script << "left 0.5\n";
    }
    ASSERT_EQ(run_study({"--quiet", "--script", (dir_.path() / "answers.txt").string(), "--observer", "S01"}), 0)
        << text_of(err());
    Store s = Store::open_read_only(db());
    const auto sessions = s.sessions();
    ASSERT_EQ(sessions.size(), 1u);
    EXPECT_EQ(sessions[0].observer_code, "S01");
    const auto trials = s.trials(sessions[0].id);
    ASSERT_EQ(trials.size(), static_cast<std::size_t>(kTrials));
    for (const auto& t : trials) {
        EXPECT_EQ(t.response, "left");
        EXPECT_DOUBLE_EQ(t.response_time_s, 1.5 + 0.5);
    }
}

TEST_F(run, ScriptRunningOutLeavesTheSessionToContinue) {
    const fs::path script = dir_.path() / "answers.txt";
    {
        std::ofstream f(script);
        for (int i = 0; i < 5; ++i) f << "right\n";
    }
    EXPECT_EQ(run_study({"--quiet", "--script", script.string()}), 2);
    const std::string message = text_of(err());
    EXPECT_NE(message.find("answers.txt"), std::string::npos) << message;
    EXPECT_NE(message.find("used up"), std::string::npos) << message;
    EXPECT_EQ(trials_of(db(), store::SessionId{1}).size(), 5u);
}

}  // namespace
}  // namespace atonlab
