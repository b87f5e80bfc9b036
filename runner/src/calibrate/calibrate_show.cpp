#include "calibrate_show.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <optional>

#include "atonlab/analysis/calibration_drift.h"
#include "atonlab/stimuli/error.h"
#include "atonlab/store/json.h"
#include "atonlab/store/profiles.h"
#include "calibration_record.h"

namespace atonlab::runner {
namespace {

namespace fs = std::filesystem;

/// The file, opened read-only (a study or the display-profile file).
class ReadOnlyFile {
public:
    explicit ReadOnlyFile(const CalibrateOptions& o) {
        std::error_code ec;
        if (!fs::exists(o.db, ec))
            throw InputError(SourceLocation{o.profiles_file ? "--profiles" : "--db", 0, 0, ""},
                             fmt::format("the {} {} does not exist{}.",
                                         o.profiles_file ? "display-profile file" : "study file", o.db,
                                         o.profiles_file && o.profiles_default
                                             ? " (the per-user default: no display has been calibrated into it yet)"
                                             : ""));
        if (o.profiles_file)
            profiles_.emplace(store::Profiles::open_read_only(o.db));
        else
            study_.emplace(store::Store::open_read_only(o.db));
    }
    const store::Store& displays() const { return profiles_ ? profiles_->displays() : *study_; }

private:
    std::optional<store::Store> study_;
    std::optional<store::Profiles> profiles_;
};

std::string fit_values(const store::Calibration& c) {
    if (!is_measured(c)) return "nominal model (not measured)";
    try {
        const nlohmann::json j = store::parse_json(c.fit_json);
        std::string gamma = "-";
        for (const nlohmann::json& ramp : store::array_at(j, "/ramps"))
            if (store::string_at(ramp, "/channel") == "grey")
                if (const auto g = store::number_at(ramp, "/effective_gamma")) gamma = fmt::format("{:.3f}", *g);
        return fmt::format("peak {:.4g} cd/m², black {:.4g} cd/m², grey effective γ {}",
                           store::number_at(j, "/display/peak_cd_m2").value_or(NAN),
                           store::number_at(j, "/display/black_cd_m2").value_or(NAN), gamma);
    } catch (const store::StoreError&) {
        return "unreadable fit_json";
    }
}

void print_calibration(const store::Store& file, const store::Calibration& c) {
    std::printf("  calibration %lld, measured %s (%s)\n", static_cast<long long>(c.id.value), c.measured_at.c_str(),
                c.source.c_str());
    std::printf("    %d x %d px, %.4g x %.4g m at %.4g m; %s\n", c.width_px, c.height_px, c.width_m, c.height_m,
                c.viewing_distance_m, fit_values(c).c_str());
    const auto checks = file.calibration_checks(c.id);
    if (checks.empty())
        std::printf("    never checked\n");
    else
        std::printf("    %zu check%s, the latest %s on %s\n", checks.size(), checks.size() == 1 ? "" : "s",
                    checks.front().passed ? "passed" : "FAILED", checks.front().checked_at.c_str());
}

}  // namespace

int run_list(const CalibrateOptions& o) {
    const ReadOnlyFile file(o);
    const store::Store& f = file.displays();
    const std::vector<std::string> names = f.display_names();
    std::printf("%s (%s): %zu display%s\n", o.db.c_str(), o.profiles_file ? "display-profile file" : "study file",
                names.size(), names.size() == 1 ? "" : "s");
    for (const std::string& name : names) {
        std::printf("display \"%s\"\n", name.c_str());
        for (const store::Calibration& c : f.calibrations(name)) print_calibration(f, c);
    }
    return 0;
}

int run_show(const CalibrateOptions& o) {
    const ReadOnlyFile file(o);
    const store::Store& f = file.displays();
    const std::vector<store::Calibration> cals = f.calibrations(o.display);
    if (cals.empty())
        throw InputError(SourceLocation::command_line("--display"),
                         fmt::format("display \"{}\" has no calibration in {} (`atonlab calibrate list` shows which "
                                     "displays it has).",
                                     o.display, o.db));
    std::printf("display \"%s\" in %s: %zu calibration%s, latest first\n", o.display.c_str(), o.db.c_str(), cals.size(),
                cals.size() == 1 ? "" : "s");
    for (const store::Calibration& c : cals) print_calibration(f, c);
    std::vector<std::string> problems;
    const std::vector<analysis::DriftPoint> drift = analysis::display_drift(f, o.display, &problems);
    for (const std::string& p : problems) std::fprintf(stderr, "atonlab: warning: %s\n", p.c_str());
    if (drift.empty()) {
        std::printf("drift: no checks yet (`atonlab calibrate check` adds one)\n");
    } else {
        std::printf("drift: %zu check%s, oldest first\n%s", drift.size(), drift.size() == 1 ? "" : "s",
                    analysis::drift_table(drift).c_str());
    }
    if (!o.plot.empty()) {
        const std::string why =
            analysis::plot_drift(o.plot, drift, fmt::format("display {}: calibration checks over time", o.display));
        if (why.empty())
            std::printf("  plot: %s\n", o.plot.c_str());
        else
            std::fprintf(stderr, "atonlab: warning: no plot: %s\n", why.c_str());
    }
    return 0;
}

}  // namespace atonlab::runner
