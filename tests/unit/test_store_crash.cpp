// Crash safety: a writer killed with SIGKILL at a random moment, 20 times in a
// row on one study file. Each child resumes the session, continues the trial
// numbering from what is stored, and writes trials as fast as it can, telling
// the parent through a pipe after each record_trial returns. After each kill the
// parent checks that SQLite finds the file sound and that the trials are exactly
// 0..k-1, each as written, with k covering every trial the child reported
// committed (and at most the one it was killed before reporting).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <random>
#include <string>
#include <thread>

#include "../store/store_test_support.h"
#include "atonlab/store/store.h"

namespace atonlab::store {
namespace {

using test_support::expect_same_trial;
using test_support::make_start;
using test_support::make_trial;
using test_support::RawDb;
using test_support::TempDir;

constexpr std::size_t pad = 700;  // ~1 KB rows: commits span several pages, so a kill can tear a frame

// The child: open (creating the file on the first run), resume or begin the
// session, then append trials until killed. Writes each committed index to `fd`
// (8 bytes: one atomic pipe write). Never returns.
[[noreturn]] void writer_child(const std::filesystem::path& path, int fd) {
    try {
        Store s = Store::create_or_open(path);
        const auto sessions = s.sessions();
        SessionId id{};
        std::int64_t next = 0;
        if (sessions.empty()) {
            id = s.begin_session(make_start("KILL9"));
        } else {
            id = sessions[0].id;
            next = s.resume_session(id).next_trial_index;  // left 'running' by the killed child
        }
        for (std::int64_t i = next;; ++i) {
            s.record_trial(id, make_trial(i, "kill", pad));
            if (write(fd, &i, sizeof i) != static_cast<ssize_t>(sizeof i)) _exit(3);
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "writer child failed: %s\n", e.what());
        _exit(2);
    }
}

TEST(StoreCrash, SigkillTwentyTimesLosesNoCommittedTrial) {
    TempDir dir;
    const auto path = dir / "study.db";
    const unsigned seed = 20240501;
    std::mt19937 rng(seed);
    // Mostly kills mid-stream; now and then one right after start, during open,
    // schema creation or resume.
    std::uniform_int_distribution<int> delay_us(0, 250000);
    std::bernoulli_distribution early(0.2);
    std::printf("  seed %u\n", seed);

    std::int64_t committed = 0;  // every trial any child reported: must all be there
    for (int round = 0; round < 20; ++round) {
        SCOPED_TRACE("round " + std::to_string(round) + ", seed " + std::to_string(seed));
        int fds[2];
        ASSERT_EQ(pipe(fds), 0);
        const pid_t pid = fork();
        ASSERT_GE(pid, 0);
        if (pid == 0) {
            close(fds[0]);
            writer_child(path, fds[1]);
        }
        close(fds[1]);
        const int wait_us = early(rng) ? delay_us(rng) / 100 : delay_us(rng);
        std::this_thread::sleep_for(std::chrono::microseconds(wait_us));
        ASSERT_EQ(kill(pid, SIGKILL), 0);
        int status = 0;
        ASSERT_EQ(waitpid(pid, &status, 0), pid);
        ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL)
            << "the writer stopped by itself (exit " << (WIFEXITED(status) ? WEXITSTATUS(status) : -1) << ")";

        std::int64_t reported = -1;  // the last index the child reported committed
        std::int64_t value = 0;
        ssize_t got = 0;
        while ((got = read(fds[0], &value, sizeof value)) == static_cast<ssize_t>(sizeof value)) reported = value;
        close(fds[0]);
        ASSERT_EQ(got, 0) << "a torn pipe message";  // writes of 8 bytes are atomic
        if (reported >= 0) committed = reported + 1;

        // Killed before the schema existed: only allowed while nothing was reported.
        bool is_study = false;
        {
            RawDb raw(path, SQLITE_OPEN_READWRITE);  // read-write: runs WAL recovery like any next writer
            ASSERT_EQ(raw.text("PRAGMA integrity_check"), "ok");
            is_study = raw.integer("PRAGMA user_version") > 0;
        }
        if (!is_study) {
            ASSERT_EQ(committed, 0);
            continue;
        }
        Store reader = Store::open_read_only(path);
        const auto sessions = reader.sessions();
        if (sessions.empty()) {
            ASSERT_EQ(committed, 0);
            continue;
        }
        ASSERT_EQ(sessions.size(), 1u);
        const auto trials = reader.trials(sessions[0].id);
        const auto k = static_cast<std::int64_t>(trials.size());
        ASSERT_GE(k, committed) << "a trial the writer reported committed is missing";
        ASSERT_LE(k, committed + 1) << "more trials than the writer can have committed";
        for (std::int64_t i = 0; i < k; ++i) {
            ASSERT_EQ(trials[static_cast<std::size_t>(i)].trial_index, i) << "gap";
            expect_same_trial(trials[static_cast<std::size_t>(i)], make_trial(i, "kill", pad));
        }
        committed = k;  // the unreported last one is committed too: later rounds must keep it
        std::printf("  round %2d: killed after %5d us, %4lld trials stored\n", round, wait_us,
                    static_cast<long long>(k));
    }
    EXPECT_GT(committed, 20) << "the writers hardly wrote anything; the test proves little";
}

}  // namespace
}  // namespace atonlab::store
