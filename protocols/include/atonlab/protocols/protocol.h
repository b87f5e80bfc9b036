#pragma once
// A protocol: what a study asks (docs/architecture.md "One trial, from protocol to store"; every key of the file
// in docs/protocol-file.md). The display, the scene template, blocks of
// conditions that override scene keys, and for each condition the task, the
// procedure, what the procedure's level controls and how the stimulus is
// presented. Plain values: the protocol-file parser (protocol_file.h) fills
// them, the schedule (protocol_schedule.h) runs them.
//
// A condition never touches the scene itself: it produces scene overrides
// (common/scene_override.h: "section.key=value", the value in TOML syntax,
// exactly what `atonlab render --set` takes, with the line that wrote it;
// docs/scene-file.md "Overrides with --set"), so this library needs neither
// the stimuli library nor GL.
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <map>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "atonlab/common/input_error.h"  // bad input: InputError, as every library's
#include "atonlab/common/scene_override.h"
#include "atonlab/protocols/procedures.h"

namespace atonlab::protocols {

/// What the observer is asked to do on a trial.
enum class Task : std::uint8_t {
    TwoAfc,  ///< "2afc": which of two (intervals or sides)? Answers Left / Right
    YesNo,   ///< "yes-no": seen or not? Answers Yes / No
    Adjust,  ///< "adjust": method of adjustment; answers the five adjustment actions
};
std::string_view to_string(Task t) noexcept;
std::optional<Task> parse_task(std::string_view text) noexcept;

/// How the test and the reference are shown.
enum class Presentation : std::uint8_t {
    Single,       ///< "single": one frame (yes-no)
    TwoInterval,  ///< "two-interval": two frames one after the other (temporal 2IFC; adjust alternates them)
    SideBySide,   ///< "side-by-side": one frame holding both lights, at two positions
};
std::string_view to_string(Presentation p) noexcept;
std::optional<Presentation> parse_presentation(std::string_view text) noexcept;

/// How a procedure level becomes the scene value of `level_key`.
enum class LevelScale : std::uint8_t {
    Log10,   ///< "log10": value = 10^level (levels in log10 units of the key's unit)
    Linear,  ///< "linear": value = level
};
std::string_view to_string(LevelScale s) noexcept;
std::optional<LevelScale> parse_level_scale(std::string_view text) noexcept;

/// The two stimuli of a comparison. A single presentation shows the test only.
enum class Role : std::uint8_t { Test, Reference };
std::string_view to_string(Role r) noexcept;
std::optional<Role> parse_role(std::string_view text) noexcept;

/// The registered kind's name (procedures.h).
std::string_view to_string(ProcedureKind k) noexcept;
std::optional<ProcedureKind> parse_procedure_kind(std::string_view text) noexcept;

struct ProcedureSpec {
    ProcedureKind kind = ProcedureKind::Staircase;
    ProcedureParams params;
    /// One interleaved track per entry: the track's `start` (staircases) or
    /// `t_guess` (QUEST). Empty: one track with the parameters as they are.
    std::vector<double> track_starts;

    std::size_t tracks() const noexcept { return track_starts.empty() ? 1 : track_starts.size(); }
    /// What protocols and analysis know of its kind (procedures.h).
    const ProcedureType& type() const noexcept { return procedure_type(kind); }

    /// The P(Yes) the procedure converges on, where it has one: a weighted
    /// staircase's target (Kaernbach 1991); a 1-up/n-down staircase 0.5^(1/n)
    /// and an n-up/1-down one 1 - 0.5^(1/n) (Levitt 1971: the level where n
    /// Yes, or n No, in a row are as likely as not); QUEST's p_threshold;
    /// constant stimuli's criterion; adjustment 0.5 (a match). nullopt for an
    /// n-up/m-down staircase with n, m > 1 or an up_step_ratio other than 1
    /// (no closed form). Yes is the procedure's Yes: see Condition::yes_means_level.
    std::optional<double> target_p_yes() const;
    /// The levels the procedure says it stays within: its min_level and
    /// max_level where given (constant stimuli: its lowest and highest level);
    /// empty when it gives neither.
    std::vector<double> level_bounds() const;
    /// The levels a true value (the level the procedure should converge on) is
    /// searched in: the procedure's bounds where given, else its starts ± 3
    /// (staircases, QUEST), its levels ± 1 (constant stimuli), its start range
    /// ± 2 (adjustment).
    std::pair<double, double> search_range() const;
    /// The bottom and top of the levels it can present: its level bounds where
    /// it has both (either order), else search_range(). The displayability
    /// check renders a condition at these two ends.
    std::pair<double, double> level_range() const;
    /// The most answers one track takes; nullopt when it has no upper bound
    /// (a staircase without max_trials, adjustment).
    std::optional<std::size_t> max_trials_per_track() const;
};

/// One condition of a block: the scene as overridden, the task, the procedure.
struct Condition {
    std::string name;  ///< unique in the protocol; the store's condition_id
    int line = 0;      ///< of its [[block.condition]] table
    Task task = Task::TwoAfc;
    Presentation presentation = Presentation::TwoInterval;
    std::string prompt;  ///< the question shown with the stimulus; empty: none
    /// Applied in order to every frame of the condition ([defaults], then the
    /// block's, then the condition's own), then test_set to the test's frame and
    /// reference_set to the reference's (both, in that order, to a side-by-side
    /// frame), then the level. Each override's origin is where the protocol
    /// wrote it: the file, line and key path "block[0].condition[1].set[0]",
    /// or a conditions file's row and column.
    std::vector<SceneOverride> set;
    std::vector<SceneOverride> test_set;
    std::vector<SceneOverride> reference_set;
    std::string level_key;  ///< the scene key the procedure's level sets, e.g. "light.reference.intensity_cd"
    LevelScale level_scale = LevelScale::Log10;
    Role level_on = Role::Reference;                       ///< which stimulus the level is applied to
    ChoiceMapping choice = ChoiceMapping::ChoseReference;  ///< 2AFC: what Yes means to the procedure
    std::string test_light;       ///< the scene light the observer judges as the test; empty: image centre
    std::string reference_light;  ///< the scene light of the reference; empty: image centre
    /// The scene disc of the reference instead of a light ([[disc]], a uniform
    /// patch of luminance: docs/scene-file.md); empty: none. At most one of
    /// reference_light and reference_disc. Side-by-side moves it with
    /// "disc.NAME.position_m"; its level key is e.g. "disc.NAME.luminance_cd_m2".
    std::string reference_disc;
    /// The name of the scene light or disc judged as `role`.
    const std::string& judged(Role role) const {
        return role == Role::Test ? test_light : reference_disc.empty() ? reference_light : reference_disc;
    }
    /// Side-by-side: where the left and right lights go (metres, world frame);
    /// the test goes left when the forced choice says so.
    std::optional<std::array<double, 3>> left_position_m;
    std::optional<std::array<double, 3>> right_position_m;
    ProcedureSpec procedure;

    /// The value written to level_key for a procedure level (10^level or level).
    double scene_value(double level) const;
    /// Whether the procedure's Yes means "chose (or saw) the stimulus the level
    /// is on": always for yes-no and adjustment; for 2AFC when `choice` names
    /// the role the level is on (chose_reference with the level on the
    /// reference, chose_test with it on the test). When false, the procedure
    /// converges where the level stimulus is chosen with 1 - target_p_yes().
    bool yes_means_level() const noexcept;
};

struct Block {
    std::string name;  ///< unique in the protocol
    int line = 0;
    double adaptation_s = 0.0;  ///< the observer adapts this long before each run of the block, s
    int repetitions = 1;        ///< runs of the block in a row, each with fresh procedures
    InterleaveOrder interleave = InterleaveOrder::Random;  ///< of all the tracks of all its conditions
    std::string instructions;                              ///< a text screen before each run; empty: none
    std::vector<Condition> conditions;
};

/// The observer's display: the scene's [display] keys (docs/scene-file.md).
struct Display {
    int width_px = 0;
    int height_px = 0;
    double width_m = 0.0;             ///< visible width of the picture, metres
    double viewing_distance_m = 0.0;  ///< eye to screen, metres
    /// The lab's name for the display (`atonlab calibrate --display NAME`): the
    /// session uses its latest measured calibration from the study file. Empty:
    /// the scene's nominal display model (docs/calibration.md).
    std::string name;
    /// `atonlab run` warns when the calibration is older than this, days (> 0).
    std::optional<double> max_calibration_age_days;
    /// `atonlab check` and `run` refuse a brightness-matching condition whose judged
    /// light gives up more than this share of its window's light to the scene's
    /// display.out_of_gamut (any choice but keep-luminance; docs/running.md), 0..1.
    double max_out_of_gamut_loss = 0.05;
    /// The line of each key in the protocol file ("viewing_distance_m" -> 9),
    /// so that a limit the scene derives from them (a glare billboard too wide
    /// for the display) names the protocol's lines; a key without a line was
    /// given on the command line (`atonlab check --set`).
    std::map<std::string, int> lines;
};

struct Timing {
    double stimulus_s = 1.0;                   ///< each interval / the frame, s
    double inter_stimulus_s = 0.5;             ///< blank between the two intervals, s
    double inter_trial_s = 1.0;                ///< answer to the next stimulus, s
    std::optional<double> response_timeout_s;  ///< none: wait for the answer
    /// A 2AFC or yes-no trial whose stimulus missed a refresh (a frame shown
    /// late) is stored as missed, not shown to the procedure, and shown again.
    bool repeat_missed = false;
    /// With repeat_missed: a run of `atonlab run` stops (exit status 7,
    /// docs/running.md "Missed frames and timeouts") at this many missed
    /// presentations in a row ...
    int max_missed_in_a_row = 5;
    /// ... or when its missed presentations exceed this share of the
    /// schedule's bound on trials (a schedule without a bound: only the
    /// consecutive bound applies). (0, 1].
    double max_missed_fraction = 0.1;
    /// The refresh rate the protocol's durations are meant for, Hz: the
    /// headless clock's rate (60 when absent); on screen the measured rate
    /// must agree with it.
    std::optional<double> refresh_hz;
    /// The continue key may end a block's adaptation period early.
    bool adaptation_skippable = false;
};

struct Screens {
    std::string instructions;  ///< before the first block
    std::string between;       ///< between runs of blocks (the file's `break`)
    std::string end;           ///< after the last block
    double text_cd_m2 = 10.0;  ///< the luminance of text on these screens, cd/m² (through the display model)
    /// The luminance of what is shown during adaptation and trials (the
    /// countdown, the prompt, the fixation mark), cd/m².
    double cue_cd_m2 = 1.0;
    double text_size_deg = 0.5;  ///< the height of a line of text, degrees of visual angle
    bool fixation = true;        ///< a fixation mark at the screen's centre before each stimulus
};

/// What a key or a gamepad button does.
enum class Action : std::uint8_t {
    Left,
    Right,
    Yes,
    No,
    CoarseUp,
    CoarseDown,
    FineUp,
    FineDown,
    Confirm,
    Continue,  ///< dismisses a text screen
    Quit,      ///< ends the session (what is recorded stays)
};
inline constexpr std::size_t kActionCount = 11;
/// "left", "right", "yes", "no", "coarse_up", "coarse_down", "fine_up", "fine_down", "confirm", "continue", "quit".
std::string_view to_string(Action a) noexcept;
/// The procedure answer an action gives (Continue and Quit give none).
std::optional<Response> response_of(Action a) noexcept;
/// The actions a task takes as answers.
std::span<const Action> task_actions(Task t) noexcept;

/// Keys and gamepad buttons for each action (names in docs/protocol-file.md).
struct ResponseMap {
    std::array<std::vector<std::string>, kActionCount> keys;
    std::array<std::vector<std::string>, kActionCount> buttons;

    /// The defaults: arrows for 2AFC and coarse adjustment, y/n, enter/space, escape; no buttons.
    static ResponseMap defaults();
    const std::vector<std::string>& keys_of(Action a) const { return keys[static_cast<std::size_t>(a)]; }
    const std::vector<std::string>& buttons_of(Action a) const { return buttons[static_cast<std::size_t>(a)]; }
    /// During a trial of `task`: the action of a key (one of the task's, or
    /// Quit), or nothing.
    std::optional<Action> key_action(Task task, std::string_view key) const;
    std::optional<Action> button_action(Task task, std::string_view button) const;
    /// On a text screen: Continue, Quit or nothing.
    std::optional<Action> screen_key_action(std::string_view key) const;
};

/// One key of the protocol's [observer] table (simulated_observer.h
/// observer_keys()), checked against its range when the file was read.
struct ObserverSetting {
    std::string key;
    double value = 0.0;
    SourceLocation where;  ///< the file, line and key it was written at
};

struct Protocol {
    std::string file;  ///< as given to the parser (messages)
    std::string name;
    std::string description;
    std::filesystem::path scene;  ///< the scene template, resolved against the protocol file's folder
    std::uint64_t seed = 0;       ///< the session's random seed unless the runner overrides it
    Display display;
    Timing timing;
    ResponseMap responses;
    Screens screens;
    std::vector<Block> blocks;
    /// [observer]: the model observer's parameters and a simulated observer's
    /// departures, in file order (simulated_observer.h observer_params()).
    std::vector<ObserverSetting> observer;

    /// The condition called `name`, or nullptr.
    const Condition* find_condition(std::string_view name) const;
    /// The display as scene overrides ("display.width_px=1920", ...), each at
    /// its [display] line: a limit the scene derives from the display (a glare
    /// billboard too wide for it) names the protocol's line.
    std::vector<SceneOverride> display_overrides() const;
};

/// Track `track` of a condition's procedure: the procedure built from its
/// parameters (with that track's start), wrapped in a ForcedChoice for 2AFC.
/// Seeds: the procedure gets derive_seed(seed, 0), the forced choice derive_seed(seed, 1).
/// Throws ProcedureError for bad parameters.
std::unique_ptr<Procedure> make_track(const Condition& condition, std::size_t track, std::uint64_t seed);

/// The condition's procedure: its one track, or an Interleaver (random order)
/// of its tracks, track t seeded derive_seed(seed, t) and the interleaver
/// derive_seed(seed, tracks). The Schedule builds the same tracks (same
/// seeds) but interleaves all the tracks of a block together.
std::unique_ptr<Procedure> make_procedure(const Condition& condition, std::uint64_t seed);

/// One frame to render: the scene overrides in the order they apply, each
/// with where it was written (the level and the side-by-side positions: the
/// condition's line).
struct Frame {
    std::optional<Role> role;  ///< whose frame it is; nullopt: side-by-side (both)
    std::vector<SceneOverride> overrides;
    /// The overrides as "key=value" text, in order (what the study file stores).
    std::vector<std::string> override_texts() const;
};

/// One light the observer judges: in which frame and which scene light.
struct StimulusView {
    std::size_t frame = 0;
    std::string light;  ///< scene light (or, for a reference, disc) name; empty: the image centre
    Role role = Role::Test;
};

/// Everything a proposal asks to be shown.
struct Stimulus {
    std::vector<Frame> frames;                 ///< in presentation order
    std::vector<StimulusView> views;           ///< [0] left / first interval, [1] right / second; one for yes-no
    std::optional<std::size_t> adjusted_view;  ///< adjust: the view whose level the actions change
    double level = 0.0;                        ///< the procedure's level
    double scene_value = 0.0;                  ///< what level_key is set to
};

/// The frames and views for a proposal of the condition's procedure. The test
/// goes first / left when proposal.test_on_left is true or absent. Every frame
/// starts with the protocol's display overrides.
Stimulus make_stimulus(const Protocol& protocol, const Condition& condition, const Proposal& proposal);

}  // namespace atonlab::protocols
