// How `atonlab simulate` cuts a simulation into tasks for a cluster
// (runner/src/simulate/cluster_tasks.h; docs/simulate-cluster.md): the shares,
// sbatch's time formats, MaxArraySize, the --array list, squeue's and sacct's
// lines. Against a real Slurm: tests/e2e/simulate_slurm.sh.
#include <gtest/gtest.h>

#include <set>

#include "simulate/cluster_tasks.h"

namespace {

using namespace atonlab::runner;

TEST(SimulateCluster, SharesCoverEverySessionOnce) {
    for (const std::size_t n : {1u, 9u, 10u, 11u, 200u, 1001u})
        for (const std::size_t k : {1u, 3u, 10u, 100u, 5000u}) {
            std::multiset<std::size_t> seen;
            const std::vector<TaskShare> shares = task_shares(n, k);
            EXPECT_EQ(shares.size(), (n + k - 1) / k) << n << " sessions, " << k << " a task";
            for (const TaskShare& s : shares) {
                EXPECT_GE(s.count, 1u);
                EXPECT_LE(s.count, k);
                for (std::size_t i = s.first; i < s.first + s.count; ++i) seen.insert(i);
            }
            ASSERT_EQ(seen.size(), n);
            for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(seen.count(i), 1u) << "session " << i;
        }
}

TEST(SimulateCluster, DefaultSessionsPerTaskFitsTheArray) {
    EXPECT_EQ(default_sessions_per_task(50, 1001), 50u);     // one task: fewer sessions than 100
    EXPECT_EQ(default_sessions_per_task(2000, 1001), 100u);  // 20 tasks of 100
    // 1,000,000 sessions: at most 1000 tasks, so 1000 a task.
    EXPECT_EQ(default_sessions_per_task(1000000, 1001), 1000u);
    EXPECT_EQ(task_shares(1000000, default_sessions_per_task(1000000, 1001)).size(), 1000u);
    // A cluster that allows 101 task ids: ⌈1,000,000 / 101⌉ a task.
    EXPECT_EQ(default_sessions_per_task(1000000, 101), 9901u);
    EXPECT_LE(task_shares(1000000, 9901).size(), 101u);
}

TEST(SimulateCluster, TimeFormatsSbatchAccepts) {
    for (const char* ok :
         {"30", "30:15", "2:00:00", "100:00:00", "1-12", "1-12:30", "7-00:00:01", "UNLIMITED", "infinite"})
        EXPECT_EQ(slurm_time_problem(ok), "") << ok;
    for (const char* bad :
         {"", "1h", "1:2:3:4", "1-", "-5", "1-2-3", "1:60", "1:00:75", "1-24", "0", "00:00", "1.5", " 30"})
        EXPECT_NE(slurm_time_problem(bad), "") << bad;
}

TEST(SimulateCluster, MaxArraySizeFromScontrol) {
    EXPECT_EQ(parse_max_array_size("JobCompType = jobcomp/none\nMaxArraySize            = 4001\nMaxJobCount = 10000\n"),
              4001u);
    EXPECT_FALSE(parse_max_array_size("MaxJobCount = 10000\n").has_value());
}

TEST(SimulateCluster, ArrayListsRuns) {
    EXPECT_EQ(array_spec({}), "");
    EXPECT_EQ(array_spec({5}), "5");
    EXPECT_EQ(array_spec({0, 1, 2, 3, 7, 9, 10}), "0-3,7,9-10");
}

TEST(SimulateCluster, SqueueLinesOfThisFoldersJobsOnly) {
    const auto live =
        live_tasks("41 3 RUNNING\n41 4 PENDING\n52 7 RUNNING\n41 N/A RUNNING\n60 2 RUNNING\n", {"41", "52"});
    ASSERT_EQ(live.size(), 3u);
    EXPECT_EQ(live.at(3), "RUNNING");
    EXPECT_EQ(live.at(4), "PENDING");
    EXPECT_EQ(live.at(7), "RUNNING");
    EXPECT_EQ(live.count(2), 0u);  // job 60 is another folder's
}

TEST(SimulateCluster, SacctLaterJobWins) {
    const auto a =
        accounted_tasks("41_3|CANCELLED by 0\n41_4|COMPLETED\n52_3|COMPLETED\n41_[5-9]|PENDING\n", {"41", "52"});
    EXPECT_EQ(a.at(3), "COMPLETED");
    EXPECT_EQ(a.at(4), "COMPLETED");
    EXPECT_EQ(a.count(5), 0u);
}

TEST(SimulateCluster, ShellQuoting) {
    EXPECT_EQ(shell_quote("/a/b-c.toml"), "/a/b-c.toml");
    EXPECT_EQ(shell_quote("max_trials=20,40"), "max_trials=20,40");
    EXPECT_EQ(shell_quote("a b"), "'a b'");
    EXPECT_EQ(shell_quote("it's"), "'it'\\''s'");
    EXPECT_EQ(shell_quote(""), "''");
}

}  // namespace
