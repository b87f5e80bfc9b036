// Continuing a session (resume.h).
#include "session/resume.h"

#include <fmt/format.h>
#include <unistd.h>

#include <filesystem>
#include <stdexcept>
#include <system_error>

#include "atonlab/protocols/rng.h"
#include "atonlab/stimuli/error.h"
#include "session/trial_record.h"

namespace atonlab::runner {

namespace p = atonlab::protocols;
namespace st = atonlab::store;

std::optional<st::Store> read_existing_study(const std::string& db, const st::StoreOptions& options) {
    std::error_code ec;
    const std::filesystem::path path(db);
    if (!std::filesystem::exists(path, ec)) return std::nullopt;
    if (std::filesystem::is_regular_file(path, ec) && std::filesystem::file_size(path, ec) == 0 &&
        !std::filesystem::exists(db + "-wal", ec))
        return std::nullopt;
    // The session will write to it: a write-protected file is refused now, with
    // the store's sentence for it (opening it for writing finds it read-only
    // before anything is written).
    if (::access(path.c_str(), W_OK) != 0) st::Store::open_existing(path, options);
    try {
        return st::Store::open_read_only(path, options);
    } catch (const st::StoreError& e) {
        if (e.kind() != st::StoreErrc::older_schema) throw;
    }
    { st::Store migrate = st::Store::create_or_open(path, options); }
    return st::Store::open_read_only(path, options);
}

namespace {

/// The session --resume or --resume-last names, unchecked.
st::SessionRecord named_session(const RunOptions& o, st::Store& existing, const std::string& protocol_sha,
                                const std::string& code) {
    if (o.resume) {
        try {
            return existing.session(st::SessionId{*o.resume});
        } catch (const st::StoreError& e) {
            if (e.kind() != st::StoreErrc::not_found) throw;
            throw InputError(SourceLocation::command_line("--resume"),
                             fmt::format("{} has no session {}.", o.db, *o.resume));
        }
    }
    std::optional<st::SessionRecord> last;
    for (const st::SessionRecord& r : existing.sessions())
        if (r.protocol_sha256 == protocol_sha && r.observer_code == code &&
            r.status != st::SessionStatus::completed && (!last || r.id > last->id))
            last = r;
    if (!last)
        throw InputError(SourceLocation::command_line("--resume-last"),
                         fmt::format("{} has no unfinished session of {} for observer \"{}\" to continue.", o.db,
                                     o.protocol, code));
    return *last;
}

}  // namespace

SessionToRun session_to_run(const RunOptions& o, std::optional<st::Store>& existing, const p::Protocol& protocol,
                            const std::string& protocol_sha, const std::string& scene_sha, const std::string& code) {
    if (!existing && (o.resume || o.resume_last))
        throw InputError(SourceLocation{o.resume ? "--resume" : "--resume-last", 0, 0, ""},
                         fmt::format("{} does not exist (or is empty): there is no session to continue.", o.db));
    SessionToRun run;
    run.seed = o.seed.value_or(protocol.seed);
    if (!o.resume && !o.resume_last) return run;
    const st::SessionRecord rec = named_session(o, *existing, protocol_sha, code);
    if (rec.status == st::SessionStatus::completed)
        throw InputError(
            SourceLocation::command_line("--resume"),
            fmt::format("session {} in {} is completed; there is nothing to continue.", rec.id.value, o.db));
    if (rec.protocol_sha256 != protocol_sha)
        throw InputError(SourceLocation{o.protocol, 0, 0, ""},
                         fmt::format("session {} in {} ran a different text of this protocol (SHA-256 {}…); a "
                                     "session continues only with the protocol it began with.",
                                     rec.id.value, o.db, rec.protocol_sha256.substr(0, 12)));
    // The scene is stored beside the protocol (schema v6) and held to it the
    // same way; a session from before stored none, and continues as it did.
    if (rec.scene_sha256 && *rec.scene_sha256 != scene_sha)
        throw InputError(SourceLocation{protocol.scene.string(), 0, 0, ""},
                         fmt::format("session {} in {} ran a different text of this scene (SHA-256 {}…); a "
                                     "session continues only with the scene it began with.",
                                     rec.id.value, o.db, rec.scene_sha256->substr(0, 12)));
    if (rec.observer_code != code)
        throw InputError(SourceLocation::command_line("--observer"),
                         fmt::format("session {} in {} is observer \"{}\"'s, not \"{}\".", rec.id.value, o.db,
                                     rec.observer_code, code));
    if (o.seed && *o.seed != rec.seed)
        throw InputError(
            SourceLocation::command_line("--seed"),
            fmt::format("session {} in {} runs with seed {}, not {}.", rec.id.value, o.db, rec.seed, *o.seed));
    run.seed = rec.seed;
    run.session = rec.id;
    run.logged = existing->resume_point(run.session).trials;
    run.resumed = true;
    return run;
}

std::uint64_t observer_seed_to_run(const RunOptions& o, const SessionToRun& run) {
    const std::uint64_t derived = o.observer_seed.value_or(p::derive_seed(run.seed, 0x6f62736572766572ULL));  // "observer"
    if (!run.resumed) return derived;
    const std::optional<std::uint64_t> stored = logged_observer_seed(run.logged);
    if (!stored) return derived;
    if (o.observer_seed && *o.observer_seed != *stored)
        throw InputError(SourceLocation::command_line("--observer-seed"),
                         fmt::format("session {} in {} runs with observer seed {}, not {}.", run.session.value, o.db,
                                     *stored, *o.observer_seed));
    return *stored;
}

Replayed replay_logged(const p::Protocol& protocol, const SessionToRun& run, const std::string& db,
                       SessionObserver& observer) {
    std::vector<p::Response> responses;
    std::vector<std::pair<p::ScheduledTrial, std::size_t>> open_match;
    double clock_s = 0.0;
    bool previous_ended_trial = true;
    p::Schedule check(protocol, run.seed);
    for (std::size_t row = 0; row < run.logged.size(); ++row) {
        const st::TrialRecord& t = run.logged[row];
        const std::optional<p::ScheduledTrial> next = check.next();
        // docs/running.md, "Missed frames and timeouts": shown again, skipped on replay.
        const bool uncounted = !p::is_counted_response_word(t.response);
        const std::optional<p::Response> r = uncounted ? std::nullopt : p::parse_response_word(t.response);
        if (!next || (!uncounted && !r) || next->condition_id != t.condition_id ||
            next->procedure_id != t.procedure_id || next->proposal.level != t.level ||
            next->proposal.test_on_left != t.test_on_left)
            throw InputError(SourceLocation{db, 0, 0, ""},
                             fmt::format("trial {} of session {} ({} at level {}, answered \"{}\") is not what "
                                         "this protocol and seed propose at that point ({}); the session cannot "
                                         "be continued.",
                                         t.trial_index, run.session.value, t.condition_id, t.level, t.response,
                                         next ? fmt::format("{} at level {}", next->condition_id, next->proposal.level)
                                              : std::string("the schedule has ended")));
        observer.skip(next->task, next->stimulus.adjusted_view);
        clock_s = t.onset_time_s + t.response_time_s;
        if (uncounted) {
            previous_ended_trial = true;
            continue;
        }
        // Counted: r holds the answer (checked above). value_or keeps GCC's
        // -Wmaybe-uninitialized from misreading the optional's payload.
        const p::Response answer = r.value_or(p::Response::No);
        if (next->task == p::Task::Adjust) {
            if (!open_match.empty() && (open_match.front().first.procedure_id != next->procedure_id ||
                                        open_match.front().first.proposal.trial != next->proposal.trial))
                open_match.clear();
            open_match.emplace_back(*next, row);
            if (answer == p::Response::Confirm) open_match.clear();
        } else {
            open_match.clear();
        }
        previous_ended_trial = next->task != p::Task::Adjust || answer == p::Response::Confirm;
        check.record(answer);
        responses.push_back(answer);
    }
    Replayed out{p::Schedule::replay(protocol, run.seed, responses), std::move(open_match), clock_s,
                 previous_ended_trial};
    if (out.schedule.state() != check.state())
        throw std::logic_error("Schedule::replay disagrees with the step-by-step replay of the same responses");
    return out;
}

}  // namespace atonlab::runner
