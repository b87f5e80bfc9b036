// read_study(): a study file's sessions, trials, calibrations and snapshot
// list, through the store's read-only connection (docs/store.md), with the
// stimulus parameters taken from each trial's stimulus_json and the
// procedures' per-trial state replayed from the stored protocol text.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <charconv>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "atonlab/analysis/dataset.h"
#include "atonlab/analysis/display_losses.h"
#include "atonlab/common/input_error.h"
#include "atonlab/common/scene_override.h"
#include "atonlab/store/json.h"
#include "atonlab/store/store.h"
#include "csv.h"
#include "gnuplot.h"
#include "procedure_replay.h"

namespace atonlab::analysis {

namespace {

/// The runner's stops (sessions.stop_json, an array of stop records): how
/// many, the last one's reason, and a sentence for it (a note on the report).
void read_stops(const std::string& text, std::int64_t id, const std::string& file, SessionInfo& info, Dataset& d) {
    const nlohmann::json j = store::parse_json(text, fmt::format("stop_json of session {}", id));
    if (!j.is_array() || j.empty()) return;
    const nlohmann::json& last = j.back();
    info.stops = static_cast<int>(j.size());
    info.stop_reason = store::string_at(last, "/reason").value_or("?");
    const double period_ms = store::number_at(last, "/refresh_period_s").value_or(0.0) * 1e3;
    info.stop_text = fmt::format(
        "{}: {} of {} presentations missed their refresh, {} refreshes lost (worst {}, {:.0f} ms)",
        info.stop_reason == "missed_in_a_row" ? "missed presentations in a row" : "too many missed presentations",
        store::number_at(last, "/missed_this_run").value_or(0),
        store::number_at(last, "/presented_this_run").value_or(0),
        store::number_at(last, "/dropped_frames").value_or(0),
        store::number_at(last, "/worst_dropped_frames").value_or(0),
        store::number_at(last, "/worst_dropped_frames").value_or(0) * period_ms);
    d.notes.push_back(fmt::format("{} session {} was stopped by the runner {} time(s), last at trial {}: {}", file, id,
                                  info.stops, store::number_at(last, "/trials_stored").value_or(0), info.stop_text));
}

/// An override's value as a number: its typed value's, when it is a finite number.
std::optional<double> number_of(const SceneOverride& o) {
    if (o.typed() == nullptr) return std::nullopt;
    const toml::node& n = o.typed()->node();
    if (!n.is_integer() && !n.is_floating_point()) return std::nullopt;
    const double x = *n.value<double>();
    return std::isfinite(x) ? std::optional<double>(x) : std::nullopt;
}

/// An override's value as text: a string's contents, any other value as written.
std::string text_of(const SceneOverride& o) {
    if (o.typed() != nullptr && o.typed()->node().is_string()) return *o.typed()->node().value<std::string>();
    return o.value;
}

struct Frame {
    std::string role;                      ///< "test", "reference", "both"
    std::vector<SceneOverride> overrides;  ///< as stored, read by SceneOverride::parse, in order

    /// The last override of `key` (later overrides win).
    const SceneOverride* value(std::string_view key) const {
        const SceneOverride* v = nullptr;
        for (const SceneOverride& o : overrides)
            if (o.key == key) v = &o;
        return v;
    }
};

/// The glare model a frame's overrides give a light: its own
/// (light.NAME.glare), else the eye's (eye.glare); nullopt: the scene's.
const SceneOverride* glare_of(const Frame& frame, const std::string& light) {
    if (!light.empty())
        if (const SceneOverride* v = frame.value("light." + light + ".glare")) return v;
    return frame.value("eye.glare");
}

/// Fills the trial's task, level scale and stimulus parameters from its
/// stimulus JSON (docs/running.md "What each trial stores").
void read_stimulus(Trial& t, const std::string& json, const SceneLights* scene, std::vector<std::string>& problems) {
    nlohmann::json j;
    try {
        j = store::parse_json(json, fmt::format("the stimulus_json of trial {}", t.trial_index));
    } catch (const store::StoreError& e) {
        problems.push_back(e.what());
        return;
    }
    if (const auto task = protocols::parse_task(store::string_at(j, "/task").value_or(""))) t.task = *task;
    t.level_key = store::string_at(j, "/level_key").value_or("");
    t.level_scale = store::string_at(j, "/level_scale").value_or("log10");
    t.level_on = store::string_at(j, "/level_on").value_or(t.task == protocols::Task::YesNo ? "test" : "reference");
    std::vector<Frame> frames;
    for (const nlohmann::json& f : store::array_at(j, "/frames")) {
        Frame frame;
        frame.role = store::string_at(f, "/role").value_or("both");
        for (const nlohmann::json& o : store::array_at(f, "/overrides")) {
            // The one reader of "key=value" (common/scene_override.h): the value typed once.
            const std::string text = o.is_string() ? o.get<std::string>() : std::string();
            try {
                frame.overrides.push_back(SceneOverride::parse(text));
            } catch (const InputError&) {
                continue;  // not "key=value": the runner stores none such
            }
        }
        frames.push_back(std::move(frame));
    }
    std::string test_light, reference_light;
    // The glare model each view's light was drawn with, as the runner stored
    // it (its own model, else the eye's); absent in files written before lights
    // had their own model.
    std::optional<std::string> test_glare, reference_glare;
    std::optional<std::size_t> test_frame, reference_frame;  // the frame each view is in
    for (const nlohmann::json& view : store::array_at(j, "/views")) {
        const std::string role = store::string_at(view, "/role").value_or("");
        const std::string light = store::string_at(view, "/light").value_or("");
        const std::optional<std::string> glare = store::string_at(view, "/glare");
        std::optional<std::size_t> frame;
        if (const auto f = store::number_at(view, "/frame"); f && *f >= 0 && *f < static_cast<double>(frames.size()))
            frame = static_cast<std::size_t>(*f);
        if (role == "test") {
            test_light = light;
            test_glare = glare;
            test_frame = frame;
        } else if (role == "reference") {
            reference_light = light;
            reference_glare = glare;
            reference_frame = frame;
        }
    }
    const Frame* test = nullptr;
    const Frame* reference = nullptr;
    for (const Frame& f : frames) {
        if (!test && (f.role == "test" || f.role == "both")) test = &f;
        if (!reference && (f.role == "reference" || f.role == "both")) reference = &f;
    }
    if (!test && !frames.empty()) test = &frames.front();
    if (test) {
        if (const auto v = test->value("eye.adaptation_cd_m2")) t.adaptation_cd_m2 = number_of(*v);
        if (const auto v = test->value("tonemap.operator")) t.tone_operator = text_of(*v);
        if (const auto v = glare_of(*test, test_light)) t.glare_test = text_of(*v);
        if (!test_light.empty()) {
            if (const auto v = test->value("light." + test_light + ".intensity_cd")) {
                const auto cd = number_of(*v);
                if (cd && *cd > 0.0) t.test_intensity_cd = cd;
            }
        }
    }
    if (reference) {
        if (const auto v = glare_of(*reference, reference_light)) t.glare_reference = text_of(*v);
    }
    if (test_glare) t.glare_test = *test_glare;
    if (reference_glare) t.glare_reference = *reference_glare;
    // Each judged light's colour, rhythm and spectrum: the stored scene with
    // the overrides of the frame its view is in.
    if (scene) {
        const auto look = [&](const std::string& light, std::optional<std::size_t> frame, const Frame* fallback) {
            const Frame* f = frame ? &frames[*frame] : fallback;
            if (light.empty() || f == nullptr) return LightLook{};
            return scene->look(light, f->overrides).value_or(LightLook{});
        };
        t.test_look = look(test_light, test_frame, test);
        t.reference_look = look(reference_light, reference_frame, reference);
    }
    // The other overrides, as factor columns (Trial::settings).
    std::set<std::string> keys;
    for (const Frame& f : frames)
        for (const SceneOverride& o : f.overrides) keys.insert(o.key);
    const std::set<std::string> covered{
        t.level_key,
        "eye.adaptation_cd_m2",
        "tonemap.operator",
        "eye.glare",
        test_light.empty() ? std::string() : "light." + test_light + ".intensity_cd",
        test_light.empty() ? std::string() : "light." + test_light + ".glare",
        reference_light.empty() ? std::string() : "light." + reference_light + ".glare"};
    for (const std::string& key : keys) {
        if (covered.count(key)) continue;
        // The values as written (the factor columns' text).
        const SceneOverride* to = test ? test->value(key) : nullptr;
        const SceneOverride* ro = reference ? reference->value(key) : nullptr;
        const std::optional<std::string> tv = to ? std::optional<std::string>(to->value) : std::nullopt;
        const std::optional<std::string> rv = ro ? std::optional<std::string>(ro->value) : std::nullopt;
        if (tv == rv) {
            if (tv) t.settings[key] = *tv;
            continue;
        }
        if (tv) t.settings["test." + key] = *tv;
        if (rv) t.settings["reference." + key] = *rv;
    }
}

/// The binary outcome of a trial (Trial::outcome).
std::optional<bool> outcome_of(const Trial& t) {
    if (t.task == protocols::Task::TwoAfc) {
        if ((t.response != "left" && t.response != "right") || !t.test_on_left) return std::nullopt;
        const bool chose_test = (t.response == "left") == *t.test_on_left;
        return t.level_on == "test" ? chose_test : !chose_test;
    }
    if (t.task == protocols::Task::YesNo) {
        if (t.response == "yes") return true;
        if (t.response == "no") return false;
    }
    return std::nullopt;
}

/// The procedure kind named in the schedule state line (a fallback when the
/// protocol text cannot be read): "[i: 2afc mapping=... [staircase trials=...".
std::string kind_from_state(const std::string& state_json) {
    for (const protocols::ProcedureType* type : protocols::procedure_types()) {
        if (state_json.find(fmt::format("[{} ", type->name)) != std::string::npos ||
            state_json.find(fmt::format(": {} ", type->name)) != std::string::npos)
            return std::string(type->name);
    }
    return {};
}

}  // namespace

namespace {

Dataset read_store(const store::Store& db, const std::string& file);
Dataset salvage_store(const std::filesystem::path& study_file, const store::StoreError& damage);

}  // namespace

Dataset read_study(const std::filesystem::path& study_file, bool salvage) {
    const std::string file = study_file.string();
    try {
        return read_store(store::Store::open_read_only(study_file), file);
    } catch (const store::StoreError& e) {
        if (salvage && (e.kind() == store::StoreErrc::corrupt || e.kind() == store::StoreErrc::schema_altered))
            return salvage_store(study_file, e);
        if (e.kind() != store::StoreErrc::older_schema) throw;
    }
    // A file of an older schema can only be migrated by a writer, and the input
    // is never written to: migrate a private copy (the file and its WAL) instead.
    auto tmp = std::make_shared<detail::TempFolder>("atonlab-analyze-");
    const std::filesystem::path copy = tmp->path() / "study.db";
    std::filesystem::copy_file(study_file, copy);
    std::error_code ec;
    if (std::filesystem::exists(file + "-wal", ec)) std::filesystem::copy_file(file + "-wal", copy.string() + "-wal");
    { store::Store migrate = store::Store::open_existing(copy); }
    Dataset d = read_store(store::Store::open_read_only(copy), file);
    for (SnapshotRef& r : d.snapshots) r.read_from = copy.string();
    d.temporaries.push_back(tmp);
    d.notes.push_back(
        fmt::format("{} was written with an older schema; it was read through a migrated temporary "
                    "copy and is unchanged",
                    file));
    return d;
}

namespace {

/// The larger of `into` and the share at `at` of light `l` (nothing where the light has no such share).
void keep_largest(std::optional<LightLoss>& into, const nlohmann::json& l, const char* at, double level) {
    const std::optional<double> share = store::number_at(l, at);
    if (!share || (into && into->share >= *share)) return;
    into = LightLoss{*share, store::string_at(l, "/role").value_or("?"), store::string_at(l, "/light").value_or("?"),
                     level};
}

/// Per condition of the record, the largest shares its judged lights lost at the display's white
/// and to display.out_of_gamut, and the limits they were judged by (absent in older records).
void read_display_losses(const nlohmann::json& j, SessionInfo& info) {
    info.white_loss_warning_share = store::number_at(j, "/thresholds/white_loss_warning_share");
    info.max_out_of_gamut_loss = store::number_at(j, "/thresholds/max_out_of_gamut_loss");
    for (const nlohmann::json& c : store::array_at(j, "/conditions")) {
        DisplayLoss loss;
        loss.condition = store::string_at(c, "/name").value_or("?");
        for (const nlohmann::json& e : store::array_at(c, "/ends")) {
            const double level = store::number_at(e, "/level").value_or(0.0);
            const double gamut_before = loss.gamut ? loss.gamut->share : -1.0;
            for (const nlohmann::json& l : store::array_at(e, "/lights")) {
                keep_largest(loss.white, l, "/white_loss_share", level);
                keep_largest(loss.gamut, l, "/gamut_loss_share", level);
            }
            if (loss.gamut && loss.gamut->share > gamut_before)
                loss.out_of_gamut = store::string_at(e, "/out_of_gamut").value_or("");
        }
        for (const nlohmann::json& w : store::array_at(c, "/warnings"))
            if (w.is_string()) loss.warnings.push_back(w.get<std::string>());
        info.display_losses.push_back(std::move(loss));
    }
}

/// The session's displayability record (displayability_json): whether it could show a match, its
/// presentation margin and its gamut choice, into `info`; a note for each departure into `d`.
void read_displayability(const std::string& text, std::int64_t session_id, const std::string& file, SessionInfo& info,
                         Dataset& d) {
    const nlohmann::json j = store::parse_json(text, fmt::format("displayability_json of session {}", session_id));
    info.displayable = store::boolean_at(j, "/displayable");
    info.allowed_undisplayable = store::boolean_at(j, "/allowed_undisplayable").value_or(false);
    for (const nlohmann::json& c : store::array_at(j, "/conditions"))
        if (!store::boolean_at(c, "/displayable").value_or(true))
            info.undisplayable.push_back(store::string_at(c, "/name").value_or("?"));
    if (const auto m = store::number_at(j, "/presentation/margin")) info.presentation_margin = *m;
    // The scene's choice, or a condition's own (a `set` of display.out_of_gamut) where it differs.
    info.out_of_gamut = store::string_at(j, "/display/out_of_gamut");
    for (const nlohmann::json& c : store::array_at(j, "/conditions"))
        for (const nlohmann::json& e : store::array_at(c, "/ends"))
            if (const auto g = store::string_at(e, "/out_of_gamut"); g && *g != "keep-luminance") info.out_of_gamut = g;
    if (info.out_of_gamut && *info.out_of_gamut != "keep-luminance")
        d.notes.push_back(fmt::format(
            "{} session {} showed colours its display cannot show by display.out_of_gamut = \"{}\", not "
            "keep-luminance: its out-of-gamut lights gave up luminance (docs/tone-mapping.md \"Out of gamut: "
            "colour or luminance\")",
            file, session_id, *info.out_of_gamut));
    read_display_losses(j, info);
    for (const std::string& loss : display_loss_sentences(info))
        d.notes.push_back(fmt::format("{} session {}: {}", file, session_id, loss));
    if (info.displayable == false)
        d.notes.push_back(fmt::format(
            "{} session {} ran with --allow-undisplayable: condition(s) {} could not produce a match on its "
            "display (docs/running.md, \"Displayability\"); their estimates say little about the observer",
            file, session_id, fmt::join(info.undisplayable, ", ")));
}

/// One session and its trials into `d`: stimulus parameters, outcomes, the
/// procedures replayed. `salvage`: a protocol text that cannot be read is a
/// note, not an error.
void add_session(Dataset& d, const store::Store& db, const std::string& file, const store::SessionRecord& s,
                 const std::vector<store::TrialRecord>& records, std::set<std::int64_t>& calibrations, bool salvage) {
    SessionInfo info;
    // The file's name and the session's id: the same however the path to the
    // file was written (merge() qualifies it when two inputs share a name).
    info.key = fmt::format("{}#{}", std::filesystem::path(file).filename().string(), s.id.value);
    info.source = file;
    info.id = s.id.value;
    info.observer = s.observer_code;
    info.protocol_name = s.protocol_name;
    info.protocol_sha256 = s.protocol_sha256;
    info.software_version = s.software_version;
    info.seed = s.seed;
    info.started_at = s.started_at;
    info.ended_at = s.ended_at.value_or("");
    info.status = store::to_string(s.status);
    info.trial_count = s.trial_count;
    info.simulation_json = s.simulation_json;
    if (!records.empty()) {
        try {
            const nlohmann::json state =
                store::parse_json(records.front().procedure_state_json, "procedure_state_json");
            info.answered_by = store::string_at(state, "/observer").value_or("");
        } catch (const store::StoreError&) {
            // Unknown: the report then treats the session's timing as real.
        }
    }
    if (s.calibration) {
        info.calibration_id = s.calibration->value;
        calibrations.insert(s.calibration->value);
    }
    if (s.displayability_json) read_displayability(*s.displayability_json, s.id.value, file, info, d);
    if (s.stop_json) read_stops(*s.stop_json, s.id.value, file, info, d);
    info.scene_name = s.scene_name;
    info.scene_sha256 = s.scene_sha256.value_or("");
    std::optional<SceneLights> scene;
    if (s.scene_sha256) {
        try {
            std::string why;
            if (const std::optional<std::string> text = db.scene_text(s.id)) {
                scene = SceneLights::parse(*text, why);
                if (!scene)
                    d.notes.push_back(
                        fmt::format("{} session {}: {}; the lights' colour, rhythm and spectrum are "
                                    "not reported",
                                    file, s.id.value, why));
            }
        } catch (const store::StoreError&) {
            if (!salvage) throw;
            d.notes.push_back(
                fmt::format("{} session {}: its scene text could not be read from the damaged file", file, s.id.value));
        }
    }
    std::string protocol_text;
    try {
        protocol_text = db.protocol_text(s.id);
    } catch (const store::StoreError& e) {
        if (!salvage) throw;
        d.notes.push_back(
            fmt::format("{} session {}: its protocol text could not be read from the damaged file", file, s.id.value));
    }
    const detail::ProtocolDesign design = detail::design_of(protocol_text, s.protocol_name);
    if (!design.protocol)
        d.notes.push_back(
            fmt::format("{} session {}: its protocol text could not be read ({}); the procedures "
                        "are taken from the trials' state, guess rates 0 and targets 0.5",
                        file, s.id.value, design.error));
    info.protocol_conditions = design.order;
    for (const auto& [name, cd] : design.conditions)
        if (!cd.note.empty()) d.notes.push_back(fmt::format("{} session {}: {}", file, s.id.value, cd.note));

    const std::size_t first = d.trials.size();
    std::vector<std::string> problems;
    for (const store::TrialRecord& r : records) {
        Trial t;
        t.source = file;
        t.session = info.key;
        t.observer = s.observer_code;
        t.trial_index = r.trial_index;
        t.block = r.block;
        if (design.protocol && r.block >= 0 && static_cast<std::size_t>(r.block) < design.protocol->blocks.size())
            t.block_name = design.protocol->blocks[static_cast<std::size_t>(r.block)].name;
        t.condition = r.condition_id;
        t.track = r.procedure_id;
        t.level = r.level;
        t.response = r.response;
        t.test_on_left = r.test_on_left;
        t.response_value = r.response_value;
        t.response_time_s = r.response_time_s;
        t.onset_time_s = r.onset_time_s;
        t.dropped_frames = r.dropped_frames;
        t.missed_deadline = r.missed_deadline;
        read_stimulus(t, r.stimulus_json, scene ? &*scene : nullptr, problems);
        // Without the noise of decimal steps summed in binary (csv.h level_value):
        // what trials.csv writes, so that it reads back as the same trials.
        t.level = detail::level_value(r.level, t.level_scale == "log10");
        t.outcome = outcome_of(t);
        if (const auto it = design.conditions.find(t.condition); it != design.conditions.end()) {
            t.procedure = it->second.procedure;
            t.guess_rate = it->second.guess_rate;
            t.target_p = it->second.target_p;
        } else {
            t.procedure = kind_from_state(r.procedure_state_json);
        }
        d.trials.push_back(std::move(t));
    }
    for (const std::string& p : problems) d.notes.push_back(fmt::format("{} session {}: {}", file, s.id.value, p));

    // Replay each adaptive track through the protocol's procedure.
    std::map<std::string, std::vector<Trial*>> tracks;
    std::set<std::string> conditions_seen;
    for (std::size_t i = first; i < d.trials.size(); ++i) {
        tracks[d.trials[i].track].push_back(&d.trials[i]);
        conditions_seen.insert(d.trials[i].condition);
    }
    for (auto& [id, trials] : tracks) {
        const auto it = design.conditions.find(trials.front()->condition);
        if (it == design.conditions.end()) continue;
        const auto track = detail::track_number(id);
        if (!track) continue;
        const std::string why = detail::replay_track(it->second, *track, trials);
        if (!why.empty())
            d.notes.push_back(
                fmt::format("{} session {}: track {} could not be replayed ({}); its reversals "
                            "or QUEST posterior are not reported",
                            file, s.id.value, id, why));
    }
    for (const std::string& c : conditions_seen) d.snapshots.push_back({file, s.id.value, info.key, c, file});
    d.sessions.push_back(std::move(info));
}

/// The calibrations the sessions used. `salvage`: one that cannot be read is a note.
void add_calibrations(Dataset& d, const store::Store& db, const std::string& file,
                      const std::set<std::int64_t>& calibrations, bool salvage) {
    for (const std::int64_t id : calibrations) {
        try {
            const store::Calibration c = db.calibration(store::CalibrationId{id});
            CalibrationInfo ci;
            ci.source = file;
            ci.id = id;
            ci.display_name = c.display_name;
            ci.width_px = c.width_px;
            ci.height_px = c.height_px;
            ci.width_m = c.width_m;
            ci.height_m = c.height_m;
            ci.viewing_distance_m = c.viewing_distance_m;
            ci.fit_json = c.fit_json;
            ci.how = c.source;
            ci.measured_at = c.measured_at;
            for (const store::CalibrationReading& r : db.calibration_readings(store::CalibrationId{id}))
                ci.readings.push_back({r.patch, r.channel, r.level, r.luminance_cd_m2});
            ci.drift = display_drift(db, c.display_name, &d.notes);
            d.calibrations.push_back(std::move(ci));
        } catch (const store::StoreError&) {
            if (!salvage) throw;
            d.notes.push_back(fmt::format("{}: calibration {} could not be read from the damaged file", file, id));
        }
    }
}

/// One note for the sessions of `file` that hold no scene (schema before v6).
void note_sessions_without_scene(Dataset& d, const std::string& file) {
    std::vector<std::int64_t> without;
    for (const SessionInfo& s : d.sessions)
        if (s.source == file && s.scene_sha256.empty()) without.push_back(s.id);
    if (without.empty()) return;
    d.notes.push_back(fmt::format(
        "{}: the study file does not hold the scene of session{} {} (written before the scene was stored with "
        "the protocol, schema version 6): the lights' colour, rhythm and spectrum are not known, so the "
        "difference between test and reference is labelled test − reference",
        file, without.size() == 1 ? "" : "s", fmt::join(without, ", ")));
}

Dataset read_store(const store::Store& db, const std::string& file) {
    Dataset d;
    d.sources.push_back(file);
    std::set<std::int64_t> calibrations;
    for (const store::SessionRecord& s : db.sessions())
        add_session(d, db, file, s, db.trials(s.id), calibrations, false);
    add_calibrations(d, db, file, calibrations, false);
    note_sessions_without_scene(d, file);
    return d;
}

// A damaged file, or one whose schema was altered, read row by row: every
// session and trial SQLite can still read. The file is opened read-only
// without the checks (it has just failed one); nothing in it is changed.
Dataset salvage_store(const std::filesystem::path& study_file, const store::StoreError& damage) {
    const std::string file = study_file.string();
    store::StoreOptions options;
    options.verify = false;
    std::optional<store::Store> db;
    try {
        db.emplace(store::Store::open_read_only(study_file, options));
    } catch (const store::StoreError&) {
        throw damage;  // not even the header and schema can be read: nothing to salvage
    }
    const store::Salvage got = db->salvage();
    Dataset d;
    d.sources.push_back(file);
    std::set<std::int64_t> calibrations;
    for (const store::SessionRecord& s : got.sessions) {
        std::vector<store::TrialRecord> records;
        for (const store::SalvagedTrial& t : got.trials)
            if (t.session == s.id) records.push_back(t.trial);
        add_session(d, *db, file, s, records, calibrations, true);
    }
    add_calibrations(d, *db, file, calibrations, true);
    note_sessions_without_scene(d, file);
    DamagedInput damaged;
    damaged.file = file;
    damaged.problem = damage.what();
    damaged.schema_altered = damage.kind() == store::StoreErrc::schema_altered;
    damaged.sessions_read = got.sessions.size();
    for (const store::SessionRecord& s : got.sessions) damaged.trials_read += static_cast<std::size_t>(s.trial_count);
    damaged.sessions_unreadable = got.unreadable_sessions;
    damaged.trials_unreadable = got.unreadable_trials;
    for (const store::SkippedRow& r : got.skipped)
        damaged.skipped_rows.push_back(fmt::format("{} row {}: {}", r.table, r.row_id, r.why));
    for (const std::string& p : got.problems) d.notes.push_back(fmt::format("{}: {}", file, p));
    d.damaged.push_back(std::move(damaged));
    return d;
}

}  // namespace

}  // namespace atonlab::analysis
