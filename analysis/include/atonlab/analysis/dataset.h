#pragma once
// The trials `atonlab analyze` works on (docs/analysis.md "Input"): read from
// one or more study files (store/, opened read-only, so a running session is
// never disturbed and nothing stored can be lost) or from a long-format CSV
// of trials, merged into one Dataset. Observers are keyed by their code (the
// same code in two study files is one observer); sessions are kept apart by
// "FILE#ID", so two files that both hold a session 1 never mix.
//
// Every trial carries the binary answer the psychometric function counts
// (`outcome`), the guess rate and target probability its procedure implies,
// and the stimulus parameters the report groups by (adaptation luminance,
// tone mapper, glare of test and reference, test intensity), read from the
// stored stimulus JSON. For adaptive tracks the study reader also replays the
// logged answers through the protocol's own procedure (protocols/), which
// gives the staircase reversals and QUEST's posterior after every trial.
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/analysis/calibration_drift.h"
#include "atonlab/analysis/scene_lights.h"
#include "atonlab/common/input_error.h"
#include "atonlab/protocols/protocol.h"

namespace atonlab::analysis {

// Bad input for an analysis (a CSV without a required column, a value that is
// not a number, a study file given twice) is the one InputError
// (common/input_error.h): what() is "FILE:LINE: column 'COLUMN': MESSAGE" with
// the parts that are known (SourceLocation::csv).

/// One trial: one row of the study's `trials` table, or of a CSV.
struct Trial {
    // --- where it came from ---------------------------------------------------
    std::string source;            ///< the study file or CSV as named on the command line
    std::string session;           ///< unique over all inputs: "FILE#ID" for a study file's session
    std::string observer;          ///< the observer's code
    std::int64_t trial_index = 0;  ///< 0-based within the session
    int block = 0;                 ///< 0-based block of the protocol
    std::string block_name;        ///< the protocol's name of the block; empty when unknown
    std::string condition;         ///< the protocol's condition name
    std::string track;             ///< the procedure instance ("CONDITION/rREP/tTRACK"); empty when unknown
    /// "staircase", "weighted-staircase", "quest", "constant-stimuli",
    /// "adjustment"; empty when unknown (the trials then get a psychometric fit only).
    std::string procedure;

    // --- what was shown and answered --------------------------------------------
    protocols::Task task = protocols::Task::TwoAfc;
    /// The procedure's level, its own units; from a study file without the
    /// noise of decimal steps summed in binary (-0.30000000000000004 is -0.3:
    /// within 1e-12, docs/analysis.md "trials.csv"; the file keeps it bit for bit).
    double level = 0.0;
    std::string level_key;               ///< the scene key the level sets, e.g. "light.reference.intensity_cd"
    std::string level_scale = "log10";   ///< "log10" (scene value = 10^level) or "linear"
    std::string level_on = "reference";  ///< "test" or "reference": the stimulus the level sets
    std::string response;                ///< the answer's word: left, right, yes, no, coarse_up, ..., confirm
    /// The binary answer a psychometric function counts: 2AFC, the observer chose
    /// the stimulus the level is on ("chose the reference" when level_on is the
    /// reference); yes-no, "yes". Absent for adjustment actions and timeouts.
    std::optional<bool> outcome;
    std::optional<bool> test_on_left;      ///< 2AFC: the test was the left / first stimulus
    std::optional<double> response_value;  ///< adjustment: the scene value shown
    double response_time_s = 0.0;
    double onset_time_s = 0.0;
    int dropped_frames = 0;
    bool missed_deadline = false;

    // --- the stimulus, from the stored overrides (absent where not stated) ------
    std::optional<double> adaptation_cd_m2;   ///< eye.adaptation_cd_m2, cd/m²
    std::string tone_operator;                ///< tonemap.operator
    /// The glare model the test light was drawn with (the stored view's, else
    /// light.NAME.glare or eye.glare in the test's frame)
    std::string glare_test;
    std::string glare_reference;              ///< the same for the reference light
    std::optional<double> test_intensity_cd;  ///< the test light's intensity_cd, cd
    /// The test and reference lights as the stored scene gives them in their
    /// views' frames, the frames' overrides applied (scene_lights.h); empty
    /// where unknown: a study file that holds no scene, a CSV without them,
    /// or a task without a reference.
    LightLook test_look, reference_look;
    /// Every other override of the trial's frames, by factor column (raw TOML
    /// value text): the scene key where the test's and the reference's frames
    /// agree, else "test.KEY" and "reference.KEY". The level's own key and the
    /// keys of the columns above are left out. Empty for a CSV input.
    std::map<std::string, std::string> settings;

    // --- what the procedure implies -----------------------------------------------
    double guess_rate = 0.0;  ///< gamma of the psychometric function for `outcome`
    double target_p = 0.5;    ///< P(outcome) the procedure converges on (0.5: a PSE)
    /// Staircases: this trial's level was a reversal (protocols/staircase.h).
    std::optional<bool> reversal;
    /// QUEST: the posterior after this trial, log10 units: mean (QuestMean), SD
    /// (QuestSd) and the 2.5% and 97.5% quantiles (QuestQuantile).
    std::optional<double> posterior_mean, posterior_sd, posterior_lower, posterior_upper;

    /// An adjustment trial that confirms a match (its level is the match).
    bool is_match() const noexcept { return task == protocols::Task::Adjust && (response == "confirm" || response == "match"); }
};

/// One judged light's share of its light lost on the display, as the
/// displayability check stored it (docs/running.md "Displayability").
struct LightLoss {
    double share = 0.0;  ///< of the light its intensity asks for within the observer's window
    std::string role;    ///< "test" or "reference"
    std::string light;   ///< the scene light's name
    double level = 0.0;  ///< the end of the level range it was rendered at
};

/// What the displayability check stored of one condition's judged lights: the
/// largest share lost at the display's white (W1) and to display.out_of_gamut
/// (R5) over its lights at both ends of its level range. nullopt: the record
/// holds no such share (written before the shares were stored).
struct DisplayLoss {
    std::string condition;
    std::optional<LightLoss> white, gamut;
    /// The choice at the end with the largest gamut loss ("keep-luminance", ...).
    std::string out_of_gamut;
    /// W1's warnings as `check` stored them (the judged end only), one sentence each.
    std::vector<std::string> warnings;
};

/// A session of a study file (or of a CSV's session column).
struct SessionInfo {
    std::string key;      ///< as Trial::session
    std::string source;   ///< the file
    std::int64_t id = 0;  ///< the session's id in its study file (0 for a CSV)
    std::string observer;
    std::string protocol_name;
    std::string protocol_sha256;
    /// The scene the session rendered, as stored beside its protocol (docs/store.md,
    /// `scenes`): its name and SHA-256; both empty when the file holds none
    /// (written before schema version 6), and the lights are then unknown.
    std::string scene_name, scene_sha256;
    std::string software_version;
    std::uint64_t seed = 0;
    std::string started_at, ended_at;
    std::string status;  ///< running, quit, completed, crashed ("" for a CSV)
    /// Who answered: "person", "model" or "script" (the first trial's
    /// procedure_state_json); "" when unknown (a CSV, no trials). Only a
    /// person's session has frame timing worth plotting: the model and script
    /// observers run on the virtual clock when headless.
    std::string answered_by;
    std::int64_t trial_count = 0;
    std::optional<std::int64_t> calibration_id;
    /// The displayability check before the first trial (docs/running.md,
    /// "Displayability"): none for a session from before it (or a CSV).
    std::optional<bool> displayable;
    bool allowed_undisplayable = false;         ///< the session ran with --allow-undisplayable
    /// display.out_of_gamut as displayability_json stored it; nullopt in files from before it was stored.
    std::optional<std::string> out_of_gamut;
    std::vector<std::string> undisplayable;     ///< the conditions that could not produce a match on its display
    /// Per condition of the record, the light lost on its display; empty without a record.
    std::vector<DisplayLoss> display_losses;
    /// The limits the losses were judged by when the session ran (W1's warning
    /// share, 0.01; display.max_out_of_gamut_loss): nullopt in files from
    /// before they were stored, where the report judges nothing by them.
    std::optional<double> white_loss_warning_share, max_out_of_gamut_loss;
    /// The runner's stops before the session's end (sessions.stop_json;
    /// docs/running.md "Missed frames and timeouts"): how many, and the last
    /// one's reason ("missed_in_a_row", "missed_per_session") and sentence;
    /// 0 and empty when it never stopped (or for a CSV).
    int stops = 0;
    std::string stop_reason, stop_text;
    /// The presentation margin before the first trial (on screen;
    /// docs/running.md "Presentation margin"): the share of a refresh left once
    /// a frame is shown. None headless, for a CSV, or before it was measured.
    std::optional<double> presentation_margin;
    /// Every condition the session's protocol defines, in file order (so a
    /// condition without trials is still reported); empty for a CSV.
    std::vector<std::string> protocol_conditions;
    /// A simulated session's observer, true values and design (the store's
    /// sessions.simulation_json, schema v7; docs/simulate.md); none for any
    /// other session (or a CSV). The simulation report reads it (simulation.h).
    std::optional<std::string> simulation_json;
};

/// One photometer reading behind a calibration (the store's calibration_readings).
struct CalibrationPoint {
    std::string patch;    ///< "black", "grey-128", ...
    std::string channel;  ///< "red", "green", "blue", "grey" or "other"
    double drive = 0.0;   ///< drive level of the lit channel(s), [0, 1]
    double luminance_cd_m2 = 0.0;
};

/// A display calibration a session used (the store's `calibrations` row).
struct CalibrationInfo {
    std::string source;  ///< the study file
    std::int64_t id = 0;
    std::string display_name;
    int width_px = 0, height_px = 0;
    double width_m = 0.0, height_m = 0.0, viewing_distance_m = 0.0;
    std::string fit_json;  ///< the model's parameters (docs/analysis.md "Display calibration")
    std::string how;       ///< the row's `source`: "measured", "imported FILE", ...
    std::string measured_at;
    std::vector<CalibrationPoint> readings;  ///< in measuring order; empty for a nominal model
    /// Every check of this display's calibrations in the same file, oldest
    /// first: the copies `atonlab run` stores with the calibration it used
    /// (calibration_drift.h). Empty when none was checked.
    std::vector<DriftPoint> drift;
};

/// A stored stimulus snapshot (an EXR) of one condition in one session.
struct SnapshotRef {
    std::string source;  ///< the study file
    std::int64_t session_id = 0;
    std::string session;  ///< as Trial::session
    std::string condition;
    /// The file to open to read it: the study file, or the migrated temporary
    /// copy of a study file with an older schema (kept while the Dataset lives).
    std::string read_from;
};

/// A study file that was damaged and was read with salvage (read_study):
/// what is wrong with it and how much could still be read.
struct DamagedInput {
    std::string file;
    std::string problem;  ///< the store's sentence saying what is wrong
    /// Its schema is not the one atonlab's migrations make (StoreErrc::schema_altered):
    /// its rows were held to constraints atonlab did not write.
    bool schema_altered = false;
    std::size_t sessions_read = 0;
    std::size_t trials_read = 0;
    std::int64_t sessions_unreadable = 0;  ///< session rows that could not be read
    std::int64_t trials_unreadable = 0;    ///< trial rows that could not be read
    /// Every row left out, named: "trials row 4: breaks CHECK (json_valid(stimulus_json))".
    std::vector<std::string> skipped_rows;
};

/// Everything read, from every input.
struct Dataset {
    std::vector<std::string> sources;  ///< the inputs, in the order given
    std::vector<Trial> trials;         ///< in input order, then session, then trial_index
    std::vector<SessionInfo> sessions;
    std::vector<CalibrationInfo> calibrations;
    std::vector<SnapshotRef> snapshots;  ///< one per (session, condition) that has one
    std::vector<std::string> notes;      ///< what the reader could not do (a protocol it could not replay, ...)
    std::vector<DamagedInput> damaged;   ///< inputs found damaged and salvaged (read_study with salvage)
    /// Owns temporary files the dataset refers to (migrated copies of older
    /// study files, see SnapshotRef::read_from); removed with the last copy.
    std::vector<std::shared_ptr<void>> temporaries;
};

/// Reads a study file read-only (Store::open_read_only: readable while a
/// session runs), checked by SQLite's integrity_check first. Throws
/// store::StoreError for a file the store refuses (not SQLite, not a study, a
/// newer schema, damaged: StoreErrc::corrupt, ...), InputError for nothing
/// else. With `salvage`, a damaged file is read row by row instead
/// (Store::salvage()): what SQLite can still read, with a DamagedInput saying
/// what is wrong and how many rows were read.
Dataset read_study(const std::filesystem::path& study_file, bool salvage = false);

/// The CSV's required columns ("observer", "condition", "level", "response").
const std::vector<std::string>& required_csv_columns();
/// Every column read_trials_csv understands, in the order write_trials_csv writes them.
const std::vector<std::string>& trials_csv_columns();

/// Reads a long-format CSV of trials (RFC 4180 quoting, a header row; columns
/// in docs/analysis.md "CSV input"). Throws InputError naming the file, line
/// and column for a missing required column, an unknown column, a bad value,
/// or a file without trials.
Dataset read_trials_csv(const std::filesystem::path& csv_file);

/// Writes `data.trials` as the tidy trials.csv: a header of trials_csv_columns()
/// and one row per trial, then one column per setting (an array of numbers,
/// such as a position, one column per element: "KEY[0]", ...). `block` is the
/// block's name, `block_index` its index. Numbers in their shortest round-trip
/// form, so that read_trials_csv gives back the same values; the level
/// without the noise of summed decimal steps (csv.h level_value, applied by read_study:
/// -0.30000000000000004 is written -0.3). Written whole or not at all
/// (files::write_file_atomically); throws files::WriteError (a
/// std::runtime_error) when the file cannot be written.
void write_trials_csv(const std::filesystem::path& csv_file, const Dataset& data);

/// Appends `more` to `into`. A session key already present (the same study
/// file given twice) is an InputError.
void merge(Dataset& into, Dataset&& more);

}  // namespace atonlab::analysis
