// `atonlab calibrate measure|import|check` (docs/calibration.md): photometer
// readings of full-screen patches (or an ArgyllCMS .ti3 / CSV file) fitted
// with calibration.h's GOG model and stored, with the readings, as a new
// calibration row of the display; or a short re-measurement compared with the
// stored calibration, stored as a check row and plotted.
#include "calibrate_command.h"

#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>

#include "atonlab/common/atomic_file.h"
#include "atonlab/display/calibration.h"
#include "atonlab/stimuli/error.h"
#include "atonlab/store/error.h"
#include "atonlab/store/profiles.h"
#include "atonlab/store/store.h"
#include "calibrate/instrument_session.h"
#include "calibrate_show.h"
#include "calibration_record.h"
#include "profile_location.h"
#include "patch_screen.h"
#include "patch_session.h"

namespace atonlab::runner {
namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------
// Dates.

std::string utc_now(const char* format) {
    const std::time_t now = std::time(nullptr);
    std::tm utc{};
    gmtime_r(&now, &utc);
    char text[32];
    std::strftime(text, sizeof text, format, &utc);
    return text;
}

/// --date: YYYY-MM-DD, optionally followed by a time ("T10:30", "T10:30:00Z");
/// default now, to the second, UTC.
std::string measurement_date(const std::string& date) {
    if (date.empty()) return utc_now("%Y-%m-%dT%H:%M:%SZ");
    // YYYY-MM-DD, then optionally THH:MM, :SS and Z.
    auto shape = [&](std::string_view pattern) {
        if (date.size() != pattern.size()) return false;
        for (std::size_t i = 0; i < pattern.size(); ++i)
            if (pattern[i] == '9' ? !std::isdigit(static_cast<unsigned char>(date[i])) : date[i] != pattern[i])
                return false;
        return true;
    };
    bool shaped = false;
    for (std::string_view p :
         {"9999-99-99", "9999-99-99T99:99", "9999-99-99T99:99Z", "9999-99-99T99:99:99", "9999-99-99T99:99:99Z"})
        shaped = shaped || shape(p);
    const int y = shaped ? std::stoi(date.substr(0, 4)) : 0;
    const unsigned m = shaped ? static_cast<unsigned>(std::stoi(date.substr(5, 2))) : 0;
    const unsigned d = shaped ? static_cast<unsigned>(std::stoi(date.substr(8, 2))) : 0;
    const std::chrono::year_month_day ymd{std::chrono::year{y}, std::chrono::month{m}, std::chrono::day{d}};
    if (!shaped || !ymd.ok())
        throw InputError(
            SourceLocation::command_line("--date"),
            fmt::format("\"{}\" is not a date YYYY-MM-DD (optionally with a time, 2024-05-01T10:30Z).", date));
    return date;
}

// ---------------------------------------------------------------------------
// Geometry.

/// Each value: the option, else the display's latest calibration, else (pixels
/// only) the window's size; height_m defaults to square pixels.
display::DisplayGeometry resolve_geometry(const CalibrateOptions& o, const std::optional<store::Calibration>& prior,
                                 std::optional<std::pair<int, int>> screen_px) {
    // Every missing option is named in one message, so one more run gives them all.
    std::vector<std::string> missing;
    if (o.mode == "import" && o.file.empty()) missing.push_back("the readings file (FILE.ti3 or FILE.csv)");
    if (o.display.empty()) missing.push_back("--display (the display's name, e.g. lab-lcd)");
    display::DisplayGeometry g;
    g.width_px = o.width_px ? *o.width_px : prior ? prior->width_px : screen_px ? screen_px->first : 0;
    g.height_px = o.height_px ? *o.height_px : prior ? prior->height_px : screen_px ? screen_px->second : 0;
    if (g.width_px <= 0) missing.push_back("--width-px (the display's width in pixels)");
    if (g.height_px <= 0) missing.push_back("--height-px (the display's height in pixels)");
    if (o.width_m)
        g.width_m = *o.width_m;
    else if (prior)
        g.width_m = prior->width_m;
    else
        missing.push_back("--width-m (the picture's visible width in metres)");
    if (o.viewing_distance_m)
        g.viewing_distance_m = *o.viewing_distance_m;
    else if (prior)
        g.viewing_distance_m = prior->viewing_distance_m;
    else
        missing.push_back("--viewing-distance-m (eye to screen in metres)");
    if (!missing.empty()) {
        std::string list;
        for (std::size_t i = 0; i < missing.size(); ++i)
            list += (i == 0 ? "" : i + 1 == missing.size() ? " and " : ", ") + missing[i];
        throw InputError(
            o.display.empty()
                ? fmt::format("{} {} needed (the geometry may instead come from the display's latest calibration).",
                              list, missing.size() == 1 ? "is" : "are")
                : fmt::format("{} {} needed: display \"{}\" has no calibration in {} to take {} from.", list,
                              missing.size() == 1 ? "is" : "are", o.display, o.db,
                              missing.size() == 1 ? "it" : "them"));
    }
    const bool same_picture =
        prior && prior->width_px == g.width_px && prior->height_px == g.height_px && prior->width_m == g.width_m;
    if (o.height_m)
        g.measured_height_m = *o.height_m;
    else if (same_picture)
        g.measured_height_m = prior->height_m;  // else square pixels (DisplayGeometry::height_m)
    for (const auto& [value, option] : {std::pair{g.width_m, "--width-m"},
                                        {g.height_m(), "--height-m"},
                                        {g.viewing_distance_m, "--viewing-distance-m"}})
        if (!(std::isfinite(value) && value > 0.0))
            throw InputError(SourceLocation::command_line(option),
                             fmt::format("must be a positive length in metres, not {}.", value));
    return g;
}

// ---------------------------------------------------------------------------
// Measuring.

/// A file name part from a display name: letters, digits, '-', '_'.
std::string file_safe(std::string_view name) {
    std::string out;
    for (const char c : name) out += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_') ? c : '_';
    return out;
}

/// A file calibrate writes for the person (typed readings, the check's plot):
/// STUDY-NAME beside a study file; for the display-profile file (a shared or
/// per-user data file) profiles-NAME in the current directory.
fs::path output_path(const CalibrateOptions& o, const std::string& name) {
    if (o.profiles_file) return fs::path(fmt::format("profiles-{}", name));
    const fs::path db(o.db);
    return db.parent_path() / fmt::format("{}-{}", db.stem().string(), name);
}

/// Typed readings are written next to the study file before anything is
/// fitted, in the readings-file format, so that no measurement is lost to a
/// failing fit: `--readings` takes the file as it is.
fs::path save_typed_readings(const CalibrateOptions& o, const std::vector<Patch>& patches,
                             const std::vector<PhotometerReading>& readings, const std::string& how = "typed") {
    const fs::path path =
        output_path(o, fmt::format("{}-{}.readings", file_safe(o.display), utc_now("%Y%m%dT%H%M%SZ")));
    std::string text = fmt::format("# atonlab calibrate {} of display \"{}\", {} {} (cd/m²; X Y Z where given)\n",
                                   o.mode, o.display, how, utc_now("%Y-%m-%dT%H:%M:%SZ"));
    for (std::size_t i = 0; i < patches.size(); ++i) {
        const PhotometerReading& r = readings[i];
        if (r.xyz_cd_m2)
            text += fmt::format("{} {} {} {}\n", patches[i].name, r.xyz_cd_m2->x, r.xyz_cd_m2->y, r.xyz_cd_m2->z);
        else
            text += fmt::format("{} {}\n", patches[i].name, r.luminance_cd_m2);
    }
    try {
        files::write_file_atomically(path, text);  // whole or not at all
    } catch (const files::WriteError& e) {
        throw InputError(SourceLocation{path.string(), 0, 0, ""},
                         fmt::format("cannot write the typed readings here: {}.", e.reason()));
    }
    return path;
}

void print_patch_list(const std::vector<Patch>& patches) {
    std::printf("# %zu patches, in the order shown; a readings file gives one reading per line, e.g. \"%s 0.21\"\n",
                patches.size(), patches.front().name.c_str());
    for (std::size_t i = 0; i < patches.size(); ++i)
        std::printf("%-10s # %2zu: R G B = %3d %3d %3d\n", patches[i].name.c_str(), i + 1, patches[i].rgb.r,
                    patches[i].rgb.g, patches[i].rgb.b);
}

struct Measured {
    std::vector<PhotometerReading> readings;
    display::DisplayGeometry geometry;
    std::string source;  ///< where the readings came from, for the source column
    std::string file;    ///< readings file name for Measurement (errors name it)
};

/// Shows the patches and collects their readings; std::nullopt when the
/// operator gave up. Geometry is resolved against the window's size.
std::optional<Measured> measure(const CalibrateOptions& o, const std::vector<Patch>& patches,
                                const std::optional<store::Calibration>& prior, bool need_geometry) {
    const bool instrument = !o.instrument.kind.empty();
    if (instrument && !o.readings.empty())
        throw InputError(SourceLocation::command_line("--instrument"),
                         "the readings come from --instrument or from --readings FILE, not both.");
    if (instrument) validate_instrument_options(o.instrument);
    if (o.headless && o.readings.empty() && !instrument)
        throw InputError(SourceLocation::command_line("--headless"),
                         "--headless shows the patches to no one: give the readings with --readings FILE (or "
                         "--instrument virtual).");
    if (!(o.window_percent > 0.0 && o.window_percent <= 100.0))
        throw InputError(
            SourceLocation::command_line("--window-percent"),
            fmt::format("the patch covers more than 0 and at most 100 % of the screen, not {}.", o.window_percent));
    if (!(o.patch_seconds >= 0.0 && std::isfinite(o.patch_seconds)))
        throw InputError(SourceLocation::command_line("--patch-seconds"), "must be a number of seconds >= 0.");
    PatchSessionOptions session;
    session.patch_seconds = o.patch_seconds;
    session.quiet = o.quiet;
    if (!o.readings.empty()) session.scripted = read_readings_file(o.readings, patches);  // before any window

    Measured m;
    PatchScreenOptions screen_options;
    screen_options.headless = o.headless;
    screen_options.monitor = o.monitor;
    screen_options.window_percent = o.window_percent;
    if (o.headless && need_geometry) {
        m.geometry = resolve_geometry(o, prior, std::nullopt);
        screen_options.headless_width = std::min(m.geometry.width_px, 4096);
        screen_options.headless_height = std::min(m.geometry.height_px, 4096);
    }
    PatchScreen screen(screen_options);
    if (!o.headless && need_geometry) {
        m.geometry = resolve_geometry(o, prior, std::pair{screen.width(), screen.height()});
        if (m.geometry.width_px != screen.width() || m.geometry.height_px != screen.height())
            std::fprintf(stderr,
                         "atonlab: warning: the screen is %d x %d pixels but the geometry says %d x %d: is this the "
                         "right monitor (--monitor) and mode?\n",
                         screen.width(), screen.height(), m.geometry.width_px, m.geometry.height_px);
    }
    if (!o.quiet) std::printf("showing %zu patches %s\n", patches.size(), screen.description().c_str());
    if (instrument) {
        if (o.headless && o.instrument.kind == "spotread")
            std::printf("note: --headless: the patches are off-screen; spotread measures whatever the screen shows\n");
        const std::unique_ptr<Instrument> meter = open_instrument(o.instrument);
        auto readings = measure_with_instrument(patches, screen, *meter, o.instrument, o.quiet);
        if (!readings) return std::nullopt;
        m.readings = std::move(*readings);
        m.source = meter->description();
        m.file = save_typed_readings(o, patches, m.readings, "measured with the " + m.source).string();
        std::printf("the readings are saved in %s (give it to --readings to fit them again)\n", m.file.c_str());
        return m;
    }
    auto readings = collect_readings(patches, screen, session);
    if (!readings) return std::nullopt;
    m.readings = std::move(*readings);
    if (!o.readings.empty()) {
        m.source = fmt::format("readings {}", o.readings);
        m.file = o.readings;
    } else {
        m.source = "typed";
        m.file = save_typed_readings(o, patches, m.readings).string();
        std::printf("the readings are saved in %s (give it to --readings to fit them again)\n", m.file.c_str());
    }
    return m;
}

std::vector<display::Measurement> measurements_of(const std::vector<Patch>& patches, const Measured& m) {
    std::vector<display::Measurement> out;
    for (std::size_t i = 0; i < patches.size(); ++i) {
        const Patch& p = patches[i];
        const PhotometerReading& r = m.readings[i];
        display::Measurement x{p.level(),
                               p.channel,
                               r.luminance_cd_m2,
                               r.line.value_or(static_cast<int>(i) + 2),
                               glm::dvec3(p.rgb) / static_cast<double>(Patch::max_code),
                               m.file};
        x.xyz_cd_m2 = r.xyz_cd_m2;
        out.push_back(x);
    }
    return out;
}

std::vector<store::CalibrationReading> readings_of(const std::vector<Patch>& patches, const Measured& m) {
    std::vector<store::CalibrationReading> out;
    for (std::size_t i = 0; i < patches.size(); ++i) {
        const Patch& p = patches[i];
        const PhotometerReading& r = m.readings[i];
        store::CalibrationReading s;
        s.patch = p.name;
        s.channel = display::channel_name(p.channel);
        s.level = p.level();
        s.code = p.code;
        s.bits = Patch::bits;
        s.drive_r = static_cast<double>(p.rgb.r) / Patch::max_code;
        s.drive_g = static_cast<double>(p.rgb.g) / Patch::max_code;
        s.drive_b = static_cast<double>(p.rgb.b) / Patch::max_code;
        s.luminance_cd_m2 = r.luminance_cd_m2;
        if (r.xyz_cd_m2) {
            s.xyz_x_cd_m2 = r.xyz_cd_m2->x;
            s.xyz_z_cd_m2 = r.xyz_cd_m2->z;
        }
        s.source_line = r.line;
        if (!r.transcript.empty()) s.transcript = r.transcript;
        out.push_back(std::move(s));
    }
    return out;
}

/// Fits, stores and reports a calibration.
int store_calibration(store::Store& db, const CalibrateOptions& o, const std::vector<display::Measurement>& ms,
                      const std::vector<store::CalibrationReading>& readings, const display::DisplayGeometry& geometry,
                      const std::string& method, const std::string& source, const std::string& measured_at) {
    const display::CalibrationReport report = display::fit_calibration(ms);
    const display::DisplayModel model = display::display_from_calibration(report, o.display);
    store::Calibration c;
    c.display_name = o.display;
    c.width_px = geometry.width_px;
    c.height_px = geometry.height_px;
    c.width_m = geometry.width_m;
    c.height_m = geometry.height_m();
    c.viewing_distance_m = geometry.viewing_distance_m;
    c.fit_json = display::measured_fit_json(report, model, geometry, method);
    c.source = source;
    c.measured_at = measured_at;
    const store::CalibrationId id = db.put_calibration(c, readings);
    std::printf("display \"%s\": calibration %lld stored in %s (%s, %zu readings, measured %s)\n", o.display.c_str(),
                static_cast<long long>(id.value), o.db.c_str(), source.c_str(), readings.size(), measured_at.c_str());
    print_fit_summary(stdout, report, model, geometry);
    return 0;
}

/// The display's latest calibration in an existing study file (opening it
/// reports a study-file problem before any time is spent measuring); none when
/// the file does not exist yet. A new file is created only when there is a
/// calibration to store, so bad input leaves no empty study behind.
/// The file calibrate works on: a study file (--db) or the display-profile file.
class CalibrationFile {
public:
    /// Opens it; `create`: creating it (and, for the per-user default profile
    /// file only, its folder) when it does not exist.
    CalibrationFile(const CalibrateOptions& o, bool create) {
        if (!o.profiles_file) {
            study_.emplace(create ? store::Store::create_or_open(o.db) : store::Store::open_existing(o.db));
            return;
        }
        if (create && o.profiles_default) {
            std::error_code ec;
            fs::create_directories(fs::path(o.db).parent_path(), ec);  // a failure is reported by the open
        }
        profiles_.emplace(create ? store::Profiles::create_or_open(o.db) : store::Profiles::open_existing(o.db));
    }
    store::Store& displays() { return profiles_ ? profiles_->displays() : *study_; }

private:
    std::optional<store::Store> study_;
    std::optional<store::Profiles> profiles_;
};

/// "--profiles" or "--db": the option that names the file calibrate works on.
const char* file_option(const CalibrateOptions& o) {
    return o.profiles_file ? "--profiles" : "--db";
}

/// "study file" or "display-profile file".
const char* file_noun(const CalibrateOptions& o) {
    return o.profiles_file ? "display-profile file" : "study file";
}

std::optional<store::Calibration> prior_calibration(const CalibrateOptions& o) {
    std::error_code ec;
    if (fs::exists(o.db, ec)) return CalibrationFile(o, false).displays().latest_calibration(o.display);
    const fs::path dir = fs::path(o.db).parent_path().empty() ? fs::path(".") : fs::path(o.db).parent_path();
    if (!fs::is_directory(dir, ec) && !o.profiles_default)
        throw InputError(SourceLocation{file_option(o), 0, 0, ""},
                         fmt::format("cannot create the {} {}: the directory {} does not exist.", file_noun(o), o.db,
                                     dir.string()));
    return std::nullopt;
}

int run_measure(const CalibrateOptions& o) {
    const std::vector<Patch> patches = measurement_patches(o.grey_levels, o.colour_levels);
    if (o.list_patches) {
        print_patch_list(patches);
        return 0;
    }
    const std::string measured_at = measurement_date(o.date);
    const std::optional<store::Calibration> prior = prior_calibration(o);
    const auto m = measure(o, patches, prior, true);
    if (!m) {
        std::fprintf(stderr, "atonlab: the measurement of display \"%s\" was given up; nothing was stored\n",
                     o.display.c_str());
        return 1;
    }
    // Fitted before the study file is created or written: readings that cannot be fitted store nothing.
    const std::vector<display::Measurement> ms = measurements_of(patches, *m);
    display::fit_calibration(ms);
    CalibrationFile file(o, true);
    const std::string source =
        o.readings.empty() && o.instrument.kind.empty() ? std::string("measured") : "measured, " + m->source;
    return store_calibration(file.displays(), o, ms, readings_of(patches, *m), m->geometry, "measured", source,
                             measured_at);
}

int run_import(const CalibrateOptions& o) {
    const std::string measured_at = measurement_date(o.date);
    display::CalibrationFileOptions file_options;
    if (!o.drive_scale.empty()) {
        file_options.drive_scale = display::drive_scale_from_name(o.drive_scale);
        if (!file_options.drive_scale)
            throw InputError(SourceLocation::command_line("--drive-scale"),
                             fmt::format("\"{}\" is not a drive scale: fraction (0 to 1), 8bit (codes 0 to 255) or "
                                         "10bit (codes 0 to 1023).",
                                         o.drive_scale));
    }
    // The options first, so that a user missing several learns of all of them
    // (with the file's own errors after) in as few runs as possible.
    const display::DisplayGeometry geometry = resolve_geometry(o, prior_calibration(o), std::nullopt);
    const std::vector<display::Measurement> ms = display::read_calibration_file(o.file, file_options);
    display::fit_calibration(ms);  // a file that cannot be fitted is refused before the study file is touched
    CalibrationFile file(o, true);
    return store_calibration(file.displays(), o, ms, readings_from_measurements(ms), geometry, "imported",
                             "imported " + o.file, measured_at);
}

int run_check(const CalibrateOptions& o) {
    const std::vector<Patch> patches = check_patches();
    if (o.list_patches) {
        print_patch_list(patches);
        return 0;
    }
    const std::string checked_at = measurement_date(o.date);
    for (const auto& [value, option] : {std::pair{o.tolerances.luminance_percent, "--tol-luminance-percent"},
                                        {o.tolerances.black_cd_m2, "--tol-black-cd-m2"},
                                        {o.tolerances.peak_percent, "--tol-peak-percent"},
                                        {o.tolerances.gamma, "--tol-gamma"}})
        if (!(std::isfinite(value) && value > 0.0))
            throw InputError(SourceLocation::command_line(option), fmt::format("a tolerance must be > 0, not {}.", value));
    std::error_code ec;
    if (o.profiles_file && !fs::exists(o.db, ec))
        throw InputError(SourceLocation::command_line("--display"),
                         fmt::format("display \"{}\" has no measured calibration to check: the display-profile file "
                                     "{} ({}) does not exist yet; run `atonlab calibrate measure` (or import) first.",
                                     o.display, o.db, o.profiles_default ? "the per-user default" : file_option(o)));
    CalibrationFile file(o, false);
    store::Store& db = file.displays();
    const std::optional<store::Calibration> cal = latest_measured_calibration(db, o.display);
    if (!cal)
        throw InputError(SourceLocation::command_line("--display"),
                         fmt::format("display \"{}\" has no measured calibration in {} to check: run `atonlab "
                                     "calibrate measure` (or import) first.",
                                     o.display, o.db));
    const display::DisplayModel model = display_model_of(*cal);
    if (!o.quiet)
        std::printf("checking display \"%s\" against calibration %lld (measured %s)\n", o.display.c_str(),
                    static_cast<long long>(cal->id.value), cal->measured_at.c_str());
    const auto m = measure(o, patches, cal, false);
    if (!m) {
        std::fprintf(stderr, "atonlab: the check of display \"%s\" was given up; nothing was stored\n",
                     o.display.c_str());
        return 1;
    }
    const CheckOutcome outcome = evaluate_check(model, patches, m->readings, o.tolerances);
    store::CalibrationCheck check;
    check.calibration = cal->id;
    check.checked_at = checked_at;
    check.passed = outcome.passed();
    check.results_json = check_results_json(outcome, o.tolerances, *cal);
    check.source = o.readings.empty() && o.instrument.kind.empty() ? std::string("measured") : "measured, " + m->source;
    const store::CalibrationCheckId id = db.put_calibration_check(check);
    std::printf("display \"%s\", calibration %lld: check %lld %s\n", o.display.c_str(),
                static_cast<long long>(cal->id.value), static_cast<long long>(id.value),
                outcome.passed() ? "PASSED" : "FAILED");
    print_check(stdout, outcome, o.tolerances);
    if (!o.no_plot) {
        const fs::path plot = !o.plot.empty()
                                  ? fs::path(o.plot)
                                  : output_path(o, fmt::format("check-{}-{}.svg", file_safe(o.display), id.value));
        std::string failed;
        for (const std::string& f : outcome.failed) failed += (failed.empty() ? "" : ", ") + f;
        const std::string title =
            fmt::format("display {}, calibration {} ({}), check {} ({}): {}", o.display, cal->id.value,
                        cal->measured_at.substr(0, 10), id.value, checked_at.substr(0, 10),
                        outcome.passed() ? "passed" : "FAILED: " + failed);
        const std::string why = plot_check(plot, outcome, o.tolerances, model, title);
        if (why.empty())
            std::printf("  plot: %s\n", plot.string().c_str());
        else
            std::fprintf(stderr, "atonlab: warning: no plot: %s\n", why.c_str());
    }
    if (!outcome.passed()) {
        std::string failed;
        for (const std::string& f : outcome.failed) failed += (failed.empty() ? "" : ", ") + f;
        std::fprintf(stderr, "atonlab: display \"%s\" failed its calibration check (%s): recalibrate it\n",
                     o.display.c_str(), failed.c_str());
    }
    return outcome.passed() ? 0 : 1;
}

void add_file_options(CLI::App* cmd, CalibrateOptions& o) {
    CLI::Option* db =
        cmd->add_option("--db", o.db, "Work on this study file (SQLite; docs/store.md) instead of the profile file");
    CLI::Option* profiles = cmd->add_option(
        "--profiles", o.profiles,
        "The lab's display-profile file (default: $ATONLAB_PROFILES, else $XDG_DATA_HOME/atonlab/profiles.sqlite)");
    db->excludes(profiles);
    profiles->excludes(db);
}

void add_display_and_db(CLI::App* cmd, CalibrateOptions& o, bool display_required = true) {
    cmd->add_option("--display", o.display, "The display's name (the lab's name for it, e.g. lab-oled-1)")
        ->required(display_required);
    add_file_options(cmd, o);
    cmd->add_option("--date", o.date, "When the readings were taken: YYYY-MM-DD[THH:MM[:SS]Z] (default: now, UTC)");
    cmd->add_flag("--quiet", o.quiet, "No line per patch for file readings");
}

void add_geometry(CLI::App* cmd, CalibrateOptions& o) {
    const char* from = " (default: the display's latest calibration)";
    cmd->add_option("--width-px", o.width_px, std::string("Display width in pixels") + from)
        ->check(CLI::Range(1, 65536));
    cmd->add_option("--height-px", o.height_px, std::string("Display height in pixels") + from)
        ->check(CLI::Range(1, 65536));
    cmd->add_option("--width-m", o.width_m, std::string("Visible picture width in metres") + from);
    cmd->add_option("--height-m", o.height_m,
                    "Visible picture height in metres (default: the latest calibration's, else square pixels)");
    cmd->add_option("--viewing-distance-m", o.viewing_distance_m, std::string("Eye to screen in metres") + from);
}

void add_patch_options(CLI::App* cmd, CalibrateOptions& o) {
    cmd->add_option("--readings", o.readings,
                    "Take the readings from this file (one per patch, in --list-patches order) instead of the "
                    "terminal");
    cmd->add_flag("--headless", o.headless, "Render the patches off-screen (EGL); needs --readings");
    cmd->add_option("--monitor", o.monitor, "Full-screen on this monitor (default 0)")->check(CLI::NonNegativeNumber);
    cmd->add_option("--window-percent", o.window_percent,
                    "The patch's share of the screen's area, centred on black (default 100: full screen)");
    cmd->add_option("--patch-seconds", o.patch_seconds,
                    "With --readings: show each patch this long, s (for a meter that logs; default 0)");
    cmd->add_flag("--list-patches", o.list_patches, "Print the patches in the order shown and exit");
    add_instrument_options(cmd, o.instrument);
}

}  // namespace

void add_calibrate_command(CLI::App& app, CalibrateOptions& o) {
    CLI::App* cal = app.add_subcommand("calibrate", "Measure, import or check a display's calibration");
    cal->require_subcommand(1);

    CLI::App* measure_cmd =
        cal->add_subcommand("measure", "Show patches full screen, take the photometer's readings, fit and store");
    add_display_and_db(measure_cmd, o);
    add_geometry(measure_cmd, o);
    add_patch_options(measure_cmd, o);
    measure_cmd->add_option("--grey-levels", o.grey_levels, "Grey ramp levels, black and white included (default 17)");
    measure_cmd->add_option("--colour-levels", o.colour_levels,
                            "Red, green and blue ramp levels, black included (default 9)");
    measure_cmd->parse_complete_callback([&o] { o.mode = "measure"; });

    CLI::App* import_cmd =
        cal->add_subcommand("import", "Fit and store the readings of an ArgyllCMS .ti3 or a CSV file");
    // Not required here: import names every missing option and argument in one message.
    import_cmd->add_option("file", o.file, "The readings: .ti3 (ArgyllCMS dispread) or .csv (level,channel,cd_m2)");
    add_display_and_db(import_cmd, o, false);
    add_geometry(import_cmd, o);
    import_cmd->add_option("--drive-scale", o.drive_scale,
                           "How the CSV's `level` column is written: fraction (0-1, the default), 8bit (0-255) or "
                           "10bit (0-1023)");
    import_cmd->parse_complete_callback([&o] { o.mode = "import"; });

    CLI::App* check_cmd = cal->add_subcommand(
        "check", "Re-measure black, 25/50/75 % grey and white against the stored calibration; exit 1 on a failure");
    add_display_and_db(check_cmd, o);
    add_patch_options(check_cmd, o);
    check_cmd->add_option("--tol-luminance-percent", o.tolerances.luminance_percent,
                          "Largest error of a grey patch above black, % (default 5)");
    check_cmd->add_option("--tol-black-cd-m2", o.tolerances.black_cd_m2,
                          "Largest error of black, cd/m² (default 0.05)");
    check_cmd->add_option("--tol-peak-percent", o.tolerances.peak_percent, "Largest error of white, % (default 5)");
    check_cmd->add_option("--tol-gamma", o.tolerances.gamma, "Largest error of the effective gamma (default 0.1)");
    check_cmd->add_option("--plot", o.plot,
                          "Write the plot here (.svg or .png; default: STUDY-check-DISPLAY-ID.svg beside the study, or "
                          "profiles-check-DISPLAY-ID.svg here)");
    check_cmd->add_flag("--no-plot", o.no_plot, "Write no plot");
    check_cmd->parse_complete_callback([&o] { o.mode = "check"; });

    CLI::App* list_cmd = cal->add_subcommand("list", "List the displays, their calibrations and latest checks");
    add_file_options(list_cmd, o);
    list_cmd->parse_complete_callback([&o] { o.mode = "list"; });

    CLI::App* show_cmd = cal->add_subcommand(
        "show", "Show a display's calibrations and its drift: every check over time, as a table and a plot");
    show_cmd->add_option("--display", o.display, "The display's name")->required();
    add_file_options(show_cmd, o);
    show_cmd->add_option("--plot", o.plot, "Write the drift plot here (.svg or .png); default: none");
    show_cmd->parse_complete_callback([&o] { o.mode = "show"; });
}

int run_calibrate(const CalibrateOptions& given) {
    try {
        CalibrateOptions o = given;
        if (o.display.empty() && o.mode != "list" && o.mode != "import")
            throw InputError(SourceLocation::command_line("--display"), "the display's name must not be empty.");
        if (o.db.empty()) {
            const std::optional<ProfilesLocation> where = profiles_location(o.profiles);
            if (!where)
                throw InputError(SourceLocation::command_line("--profiles"),
                                 fmt::format("no display-profile file: give --profiles FILE (or --db STUDY.db), or "
                                             "set {} (HOME and XDG_DATA_HOME are both unset).",
                                             kProfilesEnv));
            o.db = where->path.string();
            o.profiles_file = true;
            o.profiles_default = !where->explicit_path;
        }
        if (o.mode == "measure") return run_measure(o);
        if (o.mode == "import") return run_import(o);
        if (o.mode == "list") return run_list(o);
        if (o.mode == "show") return run_show(o);
        return run_check(o);
    } catch (const store::StoreError& e) {
        std::fprintf(stderr, "atonlab: %s\n", e.what());
        return 4;
    } catch (const InstrumentError& e) {
        std::fprintf(stderr, "atonlab: %s; nothing was stored.\n", e.what());
        return 5;
    }
}

}  // namespace atonlab::runner
