// The binary refuses what it must not write to, and writes nothing when it
// refuses (docs/running.md "Before the session", docs/store.md "Opening"):
//
//  - damaged or foreign study files (garbage, cut to 1 byte and to half,
//    another application's SQLite file, a newer schema, bytes overwritten in
//    the header and in the trials table's pages): `run` and `calibrate import`
//    exit 4 with one sentence naming the file and leave it byte for byte as it
//    was; `analyze` refuses a damaged one (exit 4) and a foreign one (exit 2,
//    docs/analysis.md), and with --salvage reads what is left and says so in
//    the first lines of report.html and summary.json;
//  - a schema altered by hand: refused by the same commands (exit 4) naming
//    the difference, unchanged; --salvage says the schema was altered;
//  - each headless refusal path of `run` (exit 2: a billboard too wide for the
//    display, a session to resume in a file that does not exist or does not
//    hold it; exit 3: no GL) leaves no study file behind and an existing one
//    byte-identical (the on-screen refusals, exit 2 and 5, are in
//    runner_xvfb.cpp);
//  - two `run`s started together on a study file that does not exist yet both
//    complete, 20 times out of 20.
// Skips where the binary finds no GL 4.5 context (exit status 3).
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "../store/store_test_support.h"
#include "../support/long_tests.h"
#include "../support/child_process.h"
#include "../support/skip.h"
#include "atonlab/store/json.h"
#include "atonlab/store/store.h"
#include "text_contains.h"

#ifndef ATONLAB_BINARY
#error "ATONLAB_BINARY (the atonlab executable) must be defined by the build"
#endif

namespace atonlab {
namespace {

namespace fs = std::filesystem;
using store::Store;
using store::test_support::file_bytes;
using store::test_support::RawDb;
using store::test_support::TempDir;

const fs::path kData = fs::path(ATONLAB_SOURCE_DIR) / "tests/data";
const fs::path kTiny = kData / "run/tiny_2afc.toml";

using Result = test::Captured;
using test::atonlab;

Result run_tiny(const fs::path& db, const fs::path& dir, const std::string& tag = "r",
                const fs::path& protocol = kTiny) {
    return atonlab({"run", protocol.string(), "--db", db.string(), "--headless", "--model-observer", "--quiet"}, dir,
                   tag);
}

using ::atonlab::test::contains;

/// One line on stderr that names the file.
void expect_one_sentence_naming(const Result& r, const fs::path& file) {
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_TRUE(contains(r.err, file.string())) << r.err;
}

void overwrite(const fs::path& path, std::int64_t offset, const std::string& bytes) {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(offset);
    f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

class StudyRefusals : public ::testing::Test {
protected:
    /// A study file with one completed session, made once by the binary.
    static void SetUpTestSuite() {
        dir_ = new TempDir;
        const Result r = run_tiny(good(), dir_->path(), "setup");
        if (r.code == 3) {
            skip_ = "no GL 4.5 context: " + r.err;
            return;
        }
        setup_code_ = r.code;
        setup_err_ = r.err;
    }
    static void TearDownTestSuite() {
        delete dir_;
        dir_ = nullptr;
    }
    void SetUp() override {
        if (!skip_.empty()) ATONLAB_SKIP_NO_GPU() << skip_;
        ASSERT_EQ(setup_code_, 0) << setup_err_;
    }
    static fs::path good() { return dir_->path() / "good.db"; }
    fs::path copy_of_good(const char* name) const {
        const fs::path p = tmp_.path() / name;
        fs::copy_file(good(), p);
        return p;
    }

    TempDir tmp_;
    static inline TempDir* dir_ = nullptr;
    static inline std::string skip_;
    static inline int setup_code_ = -1;
    static inline std::string setup_err_;
};

// --- Damaged and foreign files ---------------------------------------------------

struct Damaged {
    std::string name;
    fs::path path;
    bool damaged;  ///< damaged (salvageable) rather than not a study file at all (both: exit 4)
};

TEST_F(StudyRefusals, DamagedAndForeignFilesAreRefusedByEveryCommandAndLeftUnchanged) {
    std::vector<Damaged> files;
    {
        const fs::path p = tmp_.path() / "garbage.db";
        std::ofstream(p, std::ios::binary) << std::string(5000, 'g');
        files.push_back({"garbage", p, false});
    }
    {
        const fs::path p = copy_of_good("one-byte.db");
        fs::resize_file(p, 1);
        files.push_back({"cut to 1 byte", p, false});
    }
    {
        const fs::path p = copy_of_good("half.db");
        fs::resize_file(p, fs::file_size(p) / 2);
        files.push_back({"cut to half", p, true});
    }
    {
        const fs::path p = tmp_.path() / "other.db";
        RawDb raw(p, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
        ASSERT_EQ(raw.exec("CREATE TABLE recipes (name TEXT); INSERT INTO recipes VALUES ('bread');"), "");
        files.push_back({"another application's SQLite file", p, false});
    }
    {
        const fs::path p = copy_of_good("newer.db");
        RawDb raw(p);
        ASSERT_EQ(raw.exec("PRAGMA user_version = 99"), "");
        files.push_back({"a newer schema", p, false});
    }
    {
        const fs::path p = copy_of_good("header.db");
        overwrite(p, 16, std::string("\x12\x34", 2));  // the page size: not a power of two
        files.push_back({"header overwritten", p, true});
    }
    std::int64_t trials_root = 0, page = 0;
    {
        RawDb raw(good(), SQLITE_OPEN_READONLY);
        trials_root = raw.integer("SELECT rootpage FROM sqlite_schema WHERE name = 'trials'");
        page = raw.integer("PRAGMA page_size");
        const fs::path p = copy_of_good("trials-page.db");
        overwrite(p, (trials_root - 1) * page, std::string(12, '\xee'));  // the b-tree page's header
        files.push_back({"trials page overwritten", p, true});
    }

    for (const Damaged& f : files) {
        SCOPED_TRACE(f.name);
        const std::string before = file_bytes(f.path);

        const Result run = run_tiny(f.path, tmp_.path(), "run");
        EXPECT_EQ(run.code, 4) << run.err;
        expect_one_sentence_naming(run, f.path);
        EXPECT_EQ(file_bytes(f.path), before) << "run changed the refused file";

        const Result cal = atonlab({"calibrate", "import", (kData / "calibration/display.ti3").string(), "--display",
                                    "lcd", "--db", f.path.string(), "--width-px", "320", "--height-px", "180",
                                    "--width-m", "0.1", "--viewing-distance-m", "0.9", "--date", "2024-03-12"},
                                   tmp_.path(), "cal");
        EXPECT_EQ(cal.code, 4) << cal.err;
        expect_one_sentence_naming(cal, f.path);
        EXPECT_EQ(file_bytes(f.path), before) << "calibrate changed the refused file";

        const fs::path out = tmp_.path() / "report";
        const Result an = atonlab({"analyze", f.path.string(), "--out", out.string(), "--quiet"}, tmp_.path(), "an");
        EXPECT_EQ(an.code, 4) << an.err;
        expect_one_sentence_naming(an, f.path);
        EXPECT_FALSE(fs::exists(out / "report.html")) << "nothing is written for a refused input";
        EXPECT_EQ(file_bytes(f.path), before) << "analyze changed the refused file";
        if (f.damaged) {
            EXPECT_TRUE(contains(run.err, "is damaged")) << run.err;
        }
    }
}

TEST_F(StudyRefusals, SalvageReadsWhatIsLeftAndTheReportSaysSoFirst) {
    // Trials on several pages, so that one page can be lost and the rest read:
    // three sessions of the tiny protocol.
    const fs::path study = tmp_.path() / "study.db";
    for (int i = 0; i < 3; ++i) ASSERT_EQ(run_tiny(study, tmp_.path()).code, 0);
    std::int64_t leaf = 0, page = 0, trials = 0, leaves = 0;
    {
        RawDb raw(study, SQLITE_OPEN_READONLY);
        page = raw.integer("PRAGMA page_size");
        trials = raw.integer("SELECT count(*) FROM trials");
        try {
            leaves = raw.integer("SELECT count(*) FROM dbstat WHERE name = 'trials' AND pagetype = 'leaf'");
            leaf = raw.integer("SELECT min(pageno) FROM dbstat WHERE name = 'trials' AND pagetype = 'leaf'");
        } catch (const std::exception&) {
            ATONLAB_SKIP_MISSING_TOOL() << "no dbstat in this SQLite build: the trials table's leaves cannot be found";
        }
    }
    ASSERT_EQ(trials, 9);
    ASSERT_GE(leaves, 2) << "the trials should span several pages";
    overwrite(study, (leaf - 1) * page, std::string(12, '\xee'));  // one leaf's b-tree page header
    const std::string before = file_bytes(study);

    const fs::path out = tmp_.path() / "report";
    const Result refused = atonlab({"analyze", study.string(), "--out", out.string(), "--quiet"}, tmp_.path());
    ASSERT_EQ(refused.code, 4) << refused.err;
    EXPECT_TRUE(contains(refused.err, "--salvage")) << refused.err;

    const Result r = atonlab(
        {"analyze", study.string(), "--out", out.string(), "--quiet", "--salvage", "--bootstrap", "0"}, tmp_.path());
    ASSERT_TRUE(r.code == 0 || r.code == 5) << r.err;  // 5: figures missing without gnuplot
    EXPECT_EQ(file_bytes(study), before) << "salvage changed the damaged file";
    EXPECT_TRUE(contains(r.err, "is damaged")) << r.err;

    // summary.json: the damaged input before anything else.
    const std::string summary = file_bytes(out / "summary.json");
    const auto damaged_at = summary.find("\"damaged_inputs\"");
    ASSERT_NE(damaged_at, std::string::npos) << summary.substr(0, 400);
    EXPECT_LT(damaged_at, summary.find("\"software_version\""));
    const auto first = summary.substr(damaged_at, summary.find(']', damaged_at) - damaged_at);
    EXPECT_TRUE(contains(first, study.string())) << first;
    // The trials on the lost leaf are counted unreadable, the others read:
    // together the 9 that were stored.
    const nlohmann::json parsed = store::parse_json(summary, "summary.json");
    const auto number_after = [&](const std::string& key) {
        return static_cast<long>(store::number_at(parsed, "/damaged_inputs/0/" + key).value_or(-1.0));
    };
    const long read = number_after("trials_read"), unreadable = number_after("trials_unreadable");
    EXPECT_GT(read, 0) << first;
    EXPECT_GT(unreadable, 0) << first;
    EXPECT_EQ(read + unreadable, 9) << first;
    EXPECT_EQ(number_after("sessions_read"), 3) << first;

    // report.html: the first thing after the title.
    const std::string html = file_bytes(out / "report.html");
    const auto h1 = html.find("</h1>");
    const auto warn = html.find("Damaged input");
    ASSERT_NE(warn, std::string::npos);
    EXPECT_LT(warn - h1, 60u) << html.substr(h1, 300);
    EXPECT_TRUE(contains(html.substr(warn, 600), fmt::format("3 session(s) and {} trial(s) were read", read)))
        << html.substr(warn, 600);
}

// --- Damage inside a record -------------------------------------------------------

/// Overwrites, in `file`, the ':' after one key of the JSON text `json` with
/// 0xB0, at a place whose next 32 bytes occur once in the file: the JSON is
/// no longer valid, the record keeps its length and its page its structure.
void break_json_in_file(const fs::path& file, const std::string& json) {
    const std::string bytes = file_bytes(file);
    for (std::size_t i = 2; i + 32 <= json.size(); ++i) {
        if (json[i] != ':' || json[i - 1] != '"' || json[i - 2] == '\\') continue;
        const std::string window = json.substr(i, 32);
        const std::size_t at = bytes.find(window);
        if (at == std::string::npos || bytes.find(window, at + 1) != std::string::npos) continue;
        overwrite(file, static_cast<std::int64_t>(at), "\xb0");
        return;
    }
    FAIL() << "no place in the file holds a unique part of " << json.substr(0, 200);
}

/// Whether `s` is valid UTF-8 (RFC 3629: no stray continuation bytes, lead
/// bytes followed by their continuations), checked byte by byte here.
bool valid_utf8(const std::string& s) {
    for (std::size_t i = 0; i < s.size();) {
        const auto c = static_cast<unsigned char>(s[i]);
        const std::size_t n = c < 0x80                 ? 1
                              : c >= 0xc2 && c <= 0xdf ? 2
                              : c >= 0xe0 && c <= 0xef ? 3
                              : c >= 0xf0 && c <= 0xf4 ? 4
                                                       : 0;
        if (n == 0 || i + n > s.size()) return false;
        for (std::size_t k = 1; k < n; ++k)
            if ((static_cast<unsigned char>(s[i + k]) & 0xc0) != 0x80) return false;
        i += n;
    }
    return true;
}

// A trial's stimulus_json overwritten inside its record: SQLite's read-only
// integrity check says "ok", so analyze used to analyse it while run refused
// it. Now run, calibrate and analyze all refuse it (exit 4) with the row
// named; analyze --salvage leaves that trial out and names it.
TEST_F(StudyRefusals, ATrialOverwrittenInsideItsRecordIsRefusedByEveryCommandAndSalvageNamesIt) {
    const fs::path p = copy_of_good("record.db");
    std::int64_t trials = 0;
    {
        RawDb raw(p, SQLITE_OPEN_READONLY);
        trials = raw.integer("SELECT count(*) FROM trials");
        ASSERT_GE(trials, 3);
        break_json_in_file(p, raw.text("SELECT stimulus_json FROM trials WHERE id = 2"));
    }
    {
        RawDb raw(p);  // SQLite's own verdicts, read-write
        ASSERT_EQ(raw.text("PRAGMA integrity_check"), "CHECK constraint failed in trials");
        ASSERT_EQ(raw.integer("SELECT id FROM trials WHERE NOT json_valid(stimulus_json)"), 2);
    }
    const std::string before = file_bytes(p);
    const std::string sentence = "row 2 of trials breaks CHECK (json_valid(stimulus_json))";

    const Result run = run_tiny(p, tmp_.path(), "run");
    EXPECT_EQ(run.code, 4) << run.err;
    expect_one_sentence_naming(run, p);
    EXPECT_TRUE(contains(run.err, sentence)) << run.err;
    const Result cal = atonlab({"calibrate", "import", (kData / "calibration/display.ti3").string(), "--display", "lcd",
                                "--db", p.string(), "--width-px", "320", "--height-px", "180", "--width-m", "0.1",
                                "--viewing-distance-m", "0.9", "--date", "2024-03-12"},
                               tmp_.path(), "cal");
    EXPECT_EQ(cal.code, 4) << cal.err;
    EXPECT_TRUE(contains(cal.err, sentence)) << cal.err;
    const fs::path out = tmp_.path() / "record-report";
    const Result an = atonlab({"analyze", p.string(), "--out", out.string(), "--quiet"}, tmp_.path(), "an");
    EXPECT_EQ(an.code, 4) << an.err;
    expect_one_sentence_naming(an, p);
    EXPECT_TRUE(contains(an.err, sentence)) << an.err;
    EXPECT_TRUE(contains(an.err, "--salvage")) << an.err;
    EXPECT_FALSE(fs::exists(out / "report.html"));
    EXPECT_EQ(file_bytes(p), before) << "a command changed the refused file";

    const Result salvaged = atonlab(
        {"analyze", p.string(), "--out", out.string(), "--quiet", "--salvage", "--bootstrap", "0"}, tmp_.path(), "sv");
    ASSERT_TRUE(salvaged.code == 0 || salvaged.code == 5) << salvaged.err;  // 5: figures missing without gnuplot
    EXPECT_TRUE(contains(salvaged.err, "left out trials row 2: breaks CHECK (json_valid(stimulus_json))"))
        << salvaged.err;
    const nlohmann::json summary = store::parse_json(file_bytes(out / "summary.json"), "summary.json");
    EXPECT_EQ(store::string_at(summary, "/damaged_inputs/0/skipped_rows/0").value_or(""),
              "trials row 2: breaks CHECK (json_valid(stimulus_json))");
    EXPECT_EQ(store::number_at(summary, "/damaged_inputs/0/trials_read").value_or(-1), trials - 1);
    EXPECT_TRUE(contains(file_bytes(out / "report.html"), "trials row 2: breaks CHECK (json_valid(stimulus_json))"));
    EXPECT_EQ(file_bytes(p), before) << "salvage changed the file";
}

// A schema altered by hand (tests/data/store_schema/alterations.txt: a CHECK
// replaced, a CHECK removed, a column added, an index dropped, a trigger
// added, a view replaced; docs/store.md "Opening"): run, calibrate and analyze
// exit 4 with one sentence naming the difference, and the file's bytes are
// unchanged; analyze --salvage reads every trial and the first lines of
// report.html and summary.json say that the schema was altered.
TEST_F(StudyRefusals, ASchemaAlteredByHandIsRefusedByEveryCommandAndSalvageSaysSo) {
    std::ifstream in(kData / "store_schema/alterations.txt");
    int alterations = 0;
    for (std::string line; std::getline(in, line);) {
        if (line.empty() || line[0] == '#') continue;
        const auto a = line.find('|');
        const auto b = line.find('|', a + 1);
        const std::string name = line.substr(0, a);
        SCOPED_TRACE(name);
        ++alterations;
        const fs::path p = copy_of_good((name + ".db").c_str());
        {
            RawDb raw(p);
            ASSERT_EQ(raw.exec(line.substr(b + 1)), "");
        }
        const std::string before = file_bytes(p);
        const std::string sentence = p.string() + "'s schema was altered (" + line.substr(a + 1, b - a - 1);

        const Result run = run_tiny(p, tmp_.path(), "run");
        EXPECT_EQ(run.code, 4) << run.err;
        expect_one_sentence_naming(run, p);
        EXPECT_TRUE(contains(run.err, sentence)) << run.err;
        const Result cal = atonlab({"calibrate", "import", (kData / "calibration/display.ti3").string(), "--display",
                                    "lcd", "--db", p.string(), "--width-px", "320", "--height-px", "180", "--width-m",
                                    "0.1", "--viewing-distance-m", "0.9", "--date", "2024-03-12"},
                                   tmp_.path(), "cal");
        EXPECT_EQ(cal.code, 4) << cal.err;
        EXPECT_TRUE(contains(cal.err, sentence)) << cal.err;
        const fs::path out = tmp_.path() / (name + "-report");
        const Result an = atonlab({"analyze", p.string(), "--out", out.string(), "--quiet"}, tmp_.path(), "an");
        EXPECT_EQ(an.code, 4) << an.err;
        expect_one_sentence_naming(an, p);
        EXPECT_TRUE(contains(an.err, sentence)) << an.err;
        EXPECT_FALSE(fs::exists(out / "report.html"));
        EXPECT_EQ(file_bytes(p), before) << "a command changed the refused file";
        if (name != "check_replaced") continue;

        std::int64_t trials = 0;
        {
            RawDb raw(p, SQLITE_OPEN_READONLY);
            trials = raw.integer("SELECT count(*) FROM trials");
        }
        const Result salvaged = atonlab(
            {"analyze", p.string(), "--out", out.string(), "--quiet", "--salvage", "--bootstrap", "0"}, tmp_.path(),
            "sv");
        ASSERT_TRUE(salvaged.code == 0 || salvaged.code == 5) << salvaged.err;  // 5: figures missing without gnuplot
        const nlohmann::json summary = store::parse_json(file_bytes(out / "summary.json"), "summary.json");
        EXPECT_TRUE(store::boolean_at(summary, "/damaged_inputs/0/schema_altered").value_or(false));
        EXPECT_TRUE(contains(store::string_at(summary, "/damaged_inputs/0/problem").value_or(""), sentence));
        EXPECT_EQ(store::number_at(summary, "/damaged_inputs/0/trials_read").value_or(-1),
                  static_cast<double>(trials));
        const std::string html = file_bytes(out / "report.html");
        EXPECT_TRUE(contains(html, "Its schema was altered")) << "report.html does not say so";
        EXPECT_LT(html.find("Its schema was altered"), html.find("<h2")) << "not in the first lines";
        EXPECT_EQ(file_bytes(p), before) << "salvage changed the file";
    }
    EXPECT_EQ(alterations, 6);
}

// A session's displayability_json overwritten inside its record: analyze
// used to read it and echo the JSON parser's raw bytes ("at byte 2042:
// doc\xb0", not UTF-8). Now refused at the open, naming the row, in UTF-8.
TEST_F(StudyRefusals, ADisplayabilityOverwrittenInsideItsRecordIsRefusedInValidUtf8) {
    const fs::path p = copy_of_good("displayability.db");
    {
        RawDb raw(p, SQLITE_OPEN_READONLY);
        const std::string json = raw.text("SELECT displayability_json FROM sessions WHERE id = 1");
        ASSERT_GT(json.size(), 40u) << "the session records what the display showed";
        break_json_in_file(p, json);
    }
    ASSERT_EQ(RawDb(p).text("PRAGMA integrity_check"), "CHECK constraint failed in sessions");
    const std::string before = file_bytes(p);
    const std::string sentence =
        "row 1 of sessions breaks CHECK (displayability_json IS NULL OR json_valid(displayability_json))";
    const fs::path out = tmp_.path() / "displayability-report";
    const Result an = atonlab({"analyze", p.string(), "--out", out.string(), "--quiet"}, tmp_.path(), "an");
    EXPECT_EQ(an.code, 4) << an.err;
    expect_one_sentence_naming(an, p);
    EXPECT_TRUE(contains(an.err, sentence)) << an.err;
    EXPECT_TRUE(valid_utf8(an.err)) << an.err;
    const Result run = run_tiny(p, tmp_.path(), "run");
    EXPECT_EQ(run.code, 4) << run.err;
    EXPECT_TRUE(contains(run.err, sentence)) << run.err;
    EXPECT_TRUE(valid_utf8(run.err)) << run.err;
    EXPECT_EQ(file_bytes(p), before);
}

// --- Refusals of `run` leave nothing behind --------------------------------------

TEST_F(StudyRefusals, EveryHeadlessRefusalOfRunLeavesNoFileAndChangesNone) {
    const fs::path absent = tmp_.path() / "absent.db";
    const fs::path existing = copy_of_good("existing.db");
    const std::string before = file_bytes(existing);
    const fs::path wide = kData / "run/billboard_too_wide.toml";

    struct Case {
        std::string name;
        std::vector<std::string> extra;
        fs::path protocol;
        int code;
        bool on_existing_only = false;
    };
    const std::vector<Case> cases{
        {"billboard too wide for the display", {}, wide, 2},
        {"--resume in a file that does not exist", {"--resume", "1"}, kTiny, 2},
        {"--resume-last in a file that does not exist", {"--resume-last"}, kTiny, 2},
        {"--resume of a session the file does not hold", {"--resume", "7"}, kTiny, 2, true},
        {"--resume of a completed session", {"--resume", "1"}, kTiny, 2, true},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        for (const fs::path& db : {absent, existing}) {
            if (c.on_existing_only && db == absent) continue;
            std::vector<std::string> args{"run",       c.protocol.string(), "--db",
                                          db.string(), "--headless",        "--model-observer"};
            args.insert(args.end(), c.extra.begin(), c.extra.end());
            const Result r = atonlab(args, tmp_.path());
            EXPECT_EQ(r.code, c.code) << r.err;
            EXPECT_FALSE(fs::exists(absent)) << "a refused session created " << absent;
            EXPECT_FALSE(fs::exists(absent.string() + "-wal"));
            EXPECT_EQ(file_bytes(existing), before) << "a refused session changed " << existing;
        }
    }

    // Exit 3, no GL: EGL finds no driver (glvnd's vendor list points nowhere).
    for (const fs::path& db : {absent, existing}) {
        const fs::path out = tmp_.path() / "nogl.out", err = tmp_.path() / "nogl.err";
        const pid_t pid = fork();
        ASSERT_GE(pid, 0);
        if (pid == 0) {
            setenv("__EGL_VENDOR_LIBRARY_FILENAMES", "/nonexistent/egl_vendor.json", 1);
            setenv("__EGL_VENDOR_LIBRARY_DIRS", "/nonexistent", 1);
            setenv("EGL_PLATFORM", "surfaceless", 1);
            const std::vector<std::string> a{ATONLAB_BINARY, "run",        kTiny.string(),    "--db",
                                             db.string(),    "--headless", "--model-observer"};
            _exit(test::wait_for(test::spawn_to_files(a, out, err, false, false)));
        }
        int status = 0;
        ASSERT_EQ(waitpid(pid, &status, 0), pid);
        const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        if (code != 3) {
            std::printf("[ skip ] the EGL vendor override did not take GL away (exit %d): %s\n", code,
                        file_bytes(err).c_str());
            if (db == absent && fs::exists(absent)) fs::remove(absent);
            continue;
        }
        EXPECT_FALSE(fs::exists(absent)) << "a session without GL created " << absent;
        EXPECT_EQ(file_bytes(existing), before) << "a session without GL changed " << existing;
    }
}

// --- Two writers on one new file --------------------------------------------------

TEST_F(StudyRefusals, TwoRunsStartedTogetherOnANewFileBothComplete) {
    // 6 rounds in the suite's bounded form, 20 in the long form (tests/support/long_tests.h); the
    // store's own race, many more times and without GL: unit.StoreConcurrency.*.
    const int rounds = test::long_tests() ? 20 : 6;
    for (int round = 0; round < rounds; ++round) {
        SCOPED_TRACE("round " + std::to_string(round));
        TempDir dir;
        const fs::path db = dir.path() / "new.db";
        const std::vector<std::string> args{ATONLAB_BINARY, "run",        kTiny.string(),     "--db",
                                            db.string(),    "--headless", "--model-observer", "--quiet"};
        const pid_t a = test::spawn_to_files(args, dir.path() / "a.out", dir.path() / "a.err", false, false);
        const pid_t b = test::spawn_to_files(args, dir.path() / "b.out", dir.path() / "b.err", false, false);
        EXPECT_EQ(test::wait_for(a), 0) << file_bytes(dir.path() / "a.err");
        EXPECT_EQ(test::wait_for(b), 0) << file_bytes(dir.path() / "b.err");
        RawDb raw(db, SQLITE_OPEN_READONLY);
        EXPECT_EQ(raw.integer("SELECT count(*) FROM sessions WHERE status = 'completed'"), 2);
        EXPECT_EQ(raw.integer("SELECT count(*) FROM trials"), 6);
        EXPECT_EQ(raw.text("PRAGMA integrity_check"), "ok");
    }
}

}  // namespace
}  // namespace atonlab
