// The scene file's [profiles] tables and light sectors (scene_reader.h; docs/scene-file.md).
#include "scene_reader.h"

namespace atonlab::stimuli::scene_reader {

/// Chart sector limits are bearings *from seaward*: the bearing on which an
/// observer sees the light. profile.h's Sector takes bearings from the light
/// towards the observer, which are the reciprocal: add 180°. Clockwise order
/// is kept, so "from 090 to 180" becomes "from 270 to 360".
Sector sector_from_seaward(double from_deg, double to_deg, double level, double edge_deg) {
    double span = to_deg - from_deg;
    if (span < 0) span += 360.0;  // the sector runs clockwise through north
    Sector s;
    s.level = level;
    s.edge_deg = edge_deg;
    if (span >= 360.0) {
        s.from_deg = 0.0;
        s.to_deg = 360.0;
        return s;
    }
    s.from_deg = wrap_degrees(from_deg + 180.0);
    s.to_deg = s.from_deg + span;  // from_sectors takes to > 360 as running on through 0°
    return s;
}

/// profile.h's checks throw InputError without a location; the file's checks
/// come first, so these only fire for what they missed.
HorizontalProfile horizontal_from_sectors(const Section& s, const std::vector<Sector>& sectors) {
    try {
        return HorizontalProfile::from_sectors(sectors);
    } catch (const InputError& e) {
        s.fail(s.get("sectors"), "sectors", e.message());
    }
}

std::vector<Sector> read_sectors(const Document& doc, const Section& owner, std::string_view key) {
    const toml::node* n = owner.get(key);
    if (!n->is_array() || n->as_array()->empty())
        owner.fail(n, key,
                   fmt::format("expected an array of sector tables like [{{ from_deg = 90, to_deg = 180 }}], got {}.",
                               n->is_array() ? "an empty array" : type_phrase(n->type())));
    std::vector<Sector> sectors;
    const toml::array& a = *n->as_array();
    for (std::size_t i = 0; i < a.size(); ++i) {
        const std::string element = fmt::format("{}[{}]", key, i);
        const toml::node* e = a.get(i);
        if (!e->is_table())
            owner.fail(e, element,
                       fmt::format("expected a sector table like {{ from_deg = 90, to_deg = 180 }}, got {}.",
                                   type_phrase(e->type())));
        Section s(doc, *e->as_table(), owner.key_path(element), fmt::format("sector {}", owner.key_path(element)));
        s.allow(kSectorKeys);
        const double from = s.required_number("from_deg", "bearing from seaward where the sector starts, degrees");
        const double to = s.required_number("to_deg", "bearing from seaward where the sector ends, clockwise, degrees");
        s.within("from_deg", from, 0.0, 360.0);
        s.within("to_deg", to, 0.0, 360.0);
        if (from == to)
            s.fail(s.get("to_deg"), "to_deg",
                   "to_deg equals from_deg: the sector is empty (use 0 and 360 for all round).");
        const double level = s.number_or("level", 1.0);
        s.at_least("level", level, 0.0);
        const double edge = s.number_or("edge_deg", 0.0);
        s.within("edge_deg", edge, 0.0, 90.0);
        sectors.push_back(sector_from_seaward(from, to, level, edge));
    }
    return sectors;
}

/// Two equal-length arrays: the first strictly increasing within [lo, hi), the second >= 0.
std::pair<std::vector<double>, std::vector<double>> read_table_pair(const Section& s, std::string_view angle_key,
                                                                    double lo, double hi, bool hi_inclusive,
                                                                    std::string_view what) {
    if (!s.has(angle_key)) s.missing(angle_key, what);
    if (!s.has("relative")) s.missing("relative", "relative intensities, one per angle, each >= 0");
    std::vector<double> angles = *s.numbers(angle_key, 0, 2);
    std::vector<double> relative = *s.numbers("relative", 0, 2);
    if (angles.size() != relative.size())
        s.fail(s.get("relative"), "relative",
               fmt::format("relative has {} values but {} has {}; they must have the same length.", relative.size(),
                           angle_key, angles.size()));
    const toml::array& angle_nodes = *s.get(angle_key)->as_array();
    const toml::array& relative_nodes = *s.get("relative")->as_array();
    for (std::size_t i = 0; i < angles.size(); ++i) {
        const std::string ak = fmt::format("{}[{}]", angle_key, i);
        if (angles[i] < lo || angles[i] > hi || (!hi_inclusive && angles[i] == hi))
            s.fail(angle_nodes.get(i), ak,
                   fmt::format("{} must be in [{}, {}{}, got {}.", ak, number_text(lo), number_text(hi),
                               hi_inclusive ? "]" : ")", number_text(angles[i])));
        if (i > 0 && !(angles[i] > angles[i - 1]))
            s.fail(angle_nodes.get(i), ak,
                   fmt::format("{} must be sorted in increasing order, but {} follows {}.", angle_key,
                               number_text(angles[i]), number_text(angles[i - 1])));
        const std::string rk = fmt::format("relative[{}]", i);
        if (relative[i] < 0)
            s.fail(relative_nodes.get(i), rk,
                   fmt::format("{} must be at least 0, got {}.", rk, number_text(relative[i])));
    }
    return {std::move(angles), std::move(relative)};
}

VerticalProfile read_vertical_profile(const Section& s) {
    s.allow(kVerticalKeys);
    auto [elevation, relative] = read_table_pair(s, "elevation_deg", -90.0, 90.0, true,
                                                 "elevations in degrees, -90 (down) to 90 (up), increasing");
    try {
        return VerticalProfile::from_elevation_table(elevation, relative);
    } catch (const InputError& e) {
        s.fail_table(e.message());
    }
}

HorizontalProfile read_horizontal_profile(const Document& doc, const Section& s) {
    s.allow(kHorizontalKeys);
    const bool has_sectors = s.has("sectors");
    const bool has_table = s.has("bearing_deg") || s.has("relative");
    if (has_sectors && has_table)
        s.fail(s.get("sectors"), "sectors", "give either sectors or bearing_deg and relative, not both.");
    if (has_sectors) {
        return horizontal_from_sectors(s, read_sectors(doc, s, "sectors"));
    }
    if (!has_table) s.fail_table(fmt::format("{} needs either sectors or bearing_deg and relative.", s.title()));
    auto [bearing, relative] =
        read_table_pair(s, "bearing_deg", 0.0, 360.0, false, "bearings from seaward in degrees, 0 to 360, increasing");
    // Bearings from seaward -> bearings from the light (+180°), re-sorted so the
    // periodic table still starts at its smallest bearing.
    std::vector<std::pair<double, double>> rows;
    for (std::size_t i = 0; i < bearing.size(); ++i) rows.emplace_back(wrap_degrees(bearing[i] + 180.0), relative[i]);
    std::sort(rows.begin(), rows.end());
    for (std::size_t i = 0; i < rows.size(); ++i) {
        bearing[i] = rows[i].first;
        relative[i] = rows[i].second;
    }
    try {
        return HorizontalProfile::from_bearing_table(bearing, relative);
    } catch (const InputError& e) {
        s.fail_table(e.message());
    }
}

VerticalProfile builtin_vertical(std::string_view name) {
    if (name == "sabik-vp") return sabik_vp_vertical_profile();
    return VerticalProfile::uniform();
}


Profiles read_profiles(const Document& doc, const Section& root) {
    Profiles out;
    const toml::table* t = sub_table(root, "profiles", "[profiles]");
    if (t == nullptr) return out;
    Section profiles(doc, *t, "profiles", "the [profiles] table");
    profiles.allow(kProfileKinds);
    for (std::string_view kind : kProfileKinds) {
        const toml::table* kt = sub_table(profiles, kind, fmt::format("[profiles.{}.NAME]", kind));
        if (kt == nullptr) continue;
        const bool vertical = kind == "vertical";
        for (auto&& [k, v] : *kt) {
            const std::string path = fmt::format("profiles.{}.{}", kind, k.str());
            if (contains(vertical ? KeyList(kBuiltinVertical) : KeyList(kBuiltinHorizontal), k.str()))
                throw InputError(
                    doc.where(k, path),
                    fmt::format("'{}' is the name of a builtin {} profile; choose another name.", text::echo(k.str()),
                                kind));
            if (!v.is_table())
                doc.fail(
                    &v, path,
                    fmt::format("expected a table [profiles.{}.{}], got {}.", kind, text::echo(k.str()),
                                type_phrase(v.type())));
            Section s(doc, *v.as_table(), path, fmt::format("[profiles.{}.{}]", kind, text::echo(k.str())));
            if (vertical)
                out.vertical.emplace(std::string(k.str()), read_vertical_profile(s));
            else
                out.horizontal.emplace(std::string(k.str()), read_horizontal_profile(doc, s));
        }
    }
    return out;
}

}  // namespace atonlab::stimuli::scene_reader
