// A simulation folder's manifest (simulation_manifest.h).
#include "atonlab/analysis/simulation_manifest.h"

#include <fmt/format.h>

#include <algorithm>

#include <nlohmann/json.hpp>

#include "atonlab/common/input_error.h"
#include "atonlab/common/read_file.h"

namespace atonlab::analysis {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

namespace {

constexpr const char* kFormat = "atonlab-simulation";
constexpr int kVersion = 1;

}  // namespace

std::string SimulationManifest::protocol() const {
    std::vector<std::string> seen;
    std::string out;
    for (const ManifestDesign& d : designs) {
        if (std::find(seen.begin(), seen.end(), d.protocol) != seen.end()) continue;
        seen.push_back(d.protocol);
        out += (out.empty() ? "" : ", ") + d.protocol;
    }
    return out;
}

std::string SimulationManifest::protocol_sha256() const {
    if (designs.empty()) return {};
    for (const ManifestDesign& d : designs)
        if (d.protocol_sha256 != designs.front().protocol_sha256) return "(one per design)";
    return designs.front().protocol_sha256;
}

std::string SimulationManifest::json() const {
    Json j;
    j["format"] = kFormat;
    j["version"] = kVersion;
    // Written for a reader of the file; parse() derives them from the designs.
    j["protocol"] = protocol();
    j["protocol_sha256"] = protocol_sha256();
    Json ds = Json::array();
    for (const ManifestDesign& d : designs)
        ds.push_back(Json{{"label", d.label},
                          {"protocol", d.protocol},
                          {"protocol_sha256", d.protocol_sha256},
                          {"overrides", d.overrides},
                          {"table", d.table}});
    j["designs"] = std::move(ds);
    j["seed"] = seed;
    j["sessions"] = sessions;
    j["observer"] = Json::parse(observer_json);
    j["decisions"] = decisions;
    j["software_version"] = software_version;
    return j.dump(1);
}

SimulationManifest SimulationManifest::parse(const std::string& text, const std::string& file) {
    const auto at = [&](const std::string& key) { return SourceLocation{file, 0, 0, key}; };
    const Json j = Json::parse(text, nullptr, false);
    if (j.is_discarded()) throw InputError(at(""), "the simulation manifest is not JSON");
    if (!j.is_object() || !j.contains("format") || j["format"] != kFormat)
        throw InputError(at("format"), fmt::format("this is not an atonlab simulation manifest (format \"{}\")", kFormat));
    if (!j.contains("version") || j["version"] != kVersion)
        throw InputError(at("version"), fmt::format("version {} is not one this atonlab reads ({})",
                                                    j.contains("version") ? j["version"].dump() : "(none)", kVersion));
    SimulationManifest m;
    std::string key = "designs";
    try {
        for (const Json& d : j.at("designs"))
            m.designs.push_back(ManifestDesign{d.at("label").get<std::string>(), d.at("protocol").get<std::string>(),
                                                 d.at("protocol_sha256").get<std::string>(),
                                                 d.at("overrides").get<std::vector<std::string>>(),
                                                 d.at("table").get<std::string>()});
        if (m.designs.empty()) throw InputError(at("designs"), "the manifest names no design");
        key = "seed";
        m.seed = j.at(key).get<std::uint64_t>();
        key = "sessions";
        m.sessions = j.at(key).get<std::size_t>();
        key = "observer";
        m.observer_json = j.at(key).dump();
        key = "decisions";
        m.decisions = j.at(key).get<std::string>();
        key = "software_version";
        m.software_version = j.value(key, "");
    } catch (const Json::exception& e) {
        throw InputError(at(key), fmt::format("missing or of the wrong type ({})", e.what()));
    }
    return m;
}

std::string SimulationManifest::identity_difference(const SimulationManifest& o) const {
    if (designs.size() != o.designs.size())
        return fmt::format("it has {} design(s), this run {}", designs.size(), o.designs.size());
    for (std::size_t i = 0; i < designs.size(); ++i) {
        const ManifestDesign &a = designs[i], &b = o.designs[i];
        if (a.protocol_sha256 != b.protocol_sha256 || a.overrides != b.overrides)
            return fmt::format("its design {} is {} (protocol SHA-256 {}…), this run's {} ({}…)", i,
                               a.label.empty() ? a.protocol : a.label, a.protocol_sha256.substr(0, 12),
                               b.label.empty() ? b.protocol : b.label, b.protocol_sha256.substr(0, 12));
        if (a.table != b.table)
            return fmt::format("its design {}'s decision table is {}…, this run's {}… (the scene, display or "
                               "atonlab version changed)",
                               i, a.table.substr(0, 12), b.table.substr(0, 12));
    }
    if (seed != o.seed) return fmt::format("its seed is {}, this run's {}", seed, o.seed);
    if (Json::parse(observer_json) != Json::parse(o.observer_json))
        return fmt::format("its observer is {}, this run's {}", observer_json, o.observer_json);
    if (decisions != o.decisions)
        return fmt::format("its trials are decided by {}, this run's by {}", decisions == "table" ? "the table" : "renders",
                           o.decisions == "table" ? "the table" : "renders");
    return {};
}

fs::path simulation_manifest_path(const fs::path& dir) {
    return dir / "simulation.json";
}

fs::path simulation_session_file(const fs::path& dir, std::size_t design, std::size_t index) {
    return dir / "sessions" / fmt::format("{:02}", design) / fmt::format("session-{:06}.db", index);
}

SimulationManifest read_simulation_manifest(const fs::path& dir) {
    const fs::path file = simulation_manifest_path(dir);
    return SimulationManifest::parse(files::read_text(file, "simulation manifest"), file.string());
}

bool is_simulation_folder(const fs::path& dir) {
    std::error_code ec;
    return fs::is_directory(dir, ec) && fs::is_regular_file(simulation_manifest_path(dir), ec);
}

}  // namespace atonlab::analysis
