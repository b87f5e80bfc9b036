// A simulation's folder (simulation_folder.h).
#include "simulate/simulation_folder.h"

#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>

#include <nlohmann/json.hpp>
#include <stdexcept>
#include <system_error>

#include "atonlab/common/input_error.h"
#include "atonlab/common/read_file.h"

namespace atonlab::runner {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

std::string SimulationManifest::json() const {
    Json j;
    j["format"] = "atonlab-simulation";
    j["version"] = 1;
    // The protocol as the report names it: the file, or the files of several
    // designs; its SHA-256 when every design has one text.
    std::string protocols, sha = designs.empty() ? "" : designs.front().protocol_sha256;
    for (const ManifestDesign& d : designs) {
        if (protocols.find(d.protocol) == std::string::npos) protocols += (protocols.empty() ? "" : ", ") + d.protocol;
        if (d.protocol_sha256 != sha) sha = "(one per design)";
    }
    j["protocol"] = protocols;
    j["protocol_sha256"] = sha;
    Json ds = Json::array();
    for (const ManifestDesign& d : designs) {
        Json one;
        one["label"] = d.label;
        one["protocol"] = d.protocol;
        one["protocol_sha256"] = d.protocol_sha256;
        one["overrides"] = d.overrides;
        one["table"] = d.table;
        ds.push_back(std::move(one));
    }
    j["designs"] = std::move(ds);
    j["seed"] = seed;
    j["sessions"] = sessions;
    j["observer"] = Json::parse(observer_json);
    j["decisions"] = decisions;
    j["software_version"] = software_version;
    return j.dump(1);
}

SimulationManifest SimulationManifest::parse(const std::string& text) {
    const Json j = Json::parse(text, nullptr, false);
    if (!j.is_object() || j.value("format", "") != "atonlab-simulation")
        throw std::runtime_error("not an atonlab simulation manifest");
    if (j.value("version", 0) != 1)
        throw std::runtime_error(fmt::format("manifest version {} is not this atonlab's (1)", j.value("version", 0)));
    try {
        SimulationManifest m;
        for (const Json& d : j.at("designs"))
            m.designs.push_back(ManifestDesign{d.at("label").get<std::string>(), d.at("protocol").get<std::string>(),
                                               d.at("protocol_sha256").get<std::string>(),
                                               d.at("overrides").get<std::vector<std::string>>(),
                                               d.at("table").get<std::string>()});
        m.seed = j.at("seed").get<std::uint64_t>();
        m.sessions = j.at("sessions").get<std::size_t>();
        m.observer_json = j.at("observer").dump();
        m.decisions = j.at("decisions").get<std::string>();
        m.software_version = j.value("software_version", "");
        return m;
    } catch (const Json::exception& e) {
        throw std::runtime_error(fmt::format("a field is missing or of the wrong type: {}", e.what()));
    }
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

fs::path manifest_path(const fs::path& dir) {
    return dir / "simulation.json";
}

fs::path tables_dir(const fs::path& dir) {
    return dir / "tables";
}

fs::path session_file(const fs::path& dir, std::size_t design, std::size_t index) {
    return dir / "sessions" / fmt::format("{:02}", design) / fmt::format("session-{:06}.db", index);
}

std::optional<SimulationManifest> read_manifest(const fs::path& dir) {
    std::error_code ec;
    if (!fs::exists(dir, ec)) return std::nullopt;
    if (!fs::is_directory(dir, ec))
        throw InputError(SourceLocation::command_line("--out"), fmt::format("{} is not a folder.", dir.string()));
    const fs::path m = manifest_path(dir);
    if (!fs::exists(m, ec)) {
        if (!fs::is_empty(dir, ec))
            throw InputError(SourceLocation::command_line("--out"),
                             fmt::format("{} holds other files but no simulation.json: give an empty or new folder "
                                         "(nothing in it was changed).",
                                         dir.string()));
        return std::nullopt;
    }
    try {
        return SimulationManifest::parse(files::read_text(m, "simulation manifest"));
    } catch (const std::runtime_error& e) {
        throw InputError(SourceLocation{m.string(), 0, 0, ""},
                         fmt::format("{} is not a simulation manifest this atonlab reads ({}); nothing in {} was "
                                     "changed.",
                                     m.string(), e.what(), dir.string()));
    }
}

void check_writable(const fs::path& dir) {
    std::error_code ec;
    fs::path existing = dir;
    while (!existing.empty() && !fs::exists(existing, ec)) existing = existing.parent_path();
    if (existing.empty()) existing = ".";
    if (!fs::is_directory(existing, ec))
        throw InputError(SourceLocation::command_line("--out"),
                         fmt::format("{} cannot be made: {} is not a folder.", dir.string(), existing.string()));
    // A probe file made and removed: access() says yes to root on any folder.
    std::string probe = (existing / ".atonlab-probe-XXXXXX").string();
    const int fd = ::mkstemp(probe.data());
    if (::access(existing.c_str(), W_OK | X_OK) != 0 || fd < 0) {
        const std::string why = std::generic_category().message(fd < 0 ? errno : EACCES);
        throw InputError(SourceLocation::command_line("--out"),
                         fmt::format("{} cannot be written: {} is not writable ({}).", dir.string(), existing.string(),
                                     why));
    }
    ::close(fd);
    ::unlink(probe.c_str());
}

}  // namespace atonlab::runner
