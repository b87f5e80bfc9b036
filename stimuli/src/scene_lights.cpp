// The scene file's [[light]] and [[disc]] tables, and the glare billboard check (scene_reader.h).
#include "scene_reader.h"

namespace atonlab::stimuli::scene_reader {

// ---------------------------------------------------------------------------
// Lights.

/// The colour key of a light: IALA name, xy or SPD name (at most one; default white).
glm::dvec3 read_colour(const Section& s) {
    if (auto name = s.string("colour")) {
        if (auto rgb = iala_colour_rgb(*name)) return *rgb;
        s.fail(s.get("colour"), "colour",
               fmt::format("unknown colour \"{}\"; IALA colours are {} (or give xy or spd).", text::echo(*name),
                           join(iala_colour_names(), "\"")));
    }
    if (auto xy = s.numbers("xy", 2)) {
        const double x = (*xy)[0];
        const double y = (*xy)[1];
        if (!(x >= 0.0 && y > 0.0 && x + y <= 1.0))
            s.fail(s.get("xy"), "xy",
                   fmt::format("xy = [{}, {}] is not a chromaticity: it needs x >= 0, y > 0 and x + y <= 1.",
                               number_text(x), number_text(y)));
        return normalised_rgb_from_xy(glm::dvec2(x, y), /*clip_to_gamut=*/true);
    }
    if (auto spd = s.string("spd")) {
        if (auto spectrum = named_spectrum(*spd)) return normalised_rgb_from_spectrum(*spectrum);
        s.fail(s.get("spd"), "spd",
               fmt::format("unknown spectrum \"{}\"; named spectra are {}.", text::echo(*spd),
                           join(spectrum_names(), "\"")));
    }
    return *iala_colour_rgb("white");
}

/// The named spectrum a light's glare is integrated over (docs/glare.md "The light's spectrum"): its
/// `spd`, else its IALA colour's representative spectrum (white's when no colour key is given), else
/// none for an `xy`, which names no spectrum (Light::spd empty: its glare is D65's, its rods see its
/// drawn colour).
std::string glare_spectrum(const Section& s) {
    if (auto spd = s.string("spd")) return *spd;
    if (s.has("xy")) return "";
    return iala_colour_spectrum_name(s.string("colour").value_or("white")).value_or("d65");
}

struct SceneBuilder {
    const Document& doc;
    Scene& scene;
    const Profiles& profiles;
    std::map<std::string, std::string> names;  // light name -> key of the light that took it

    int vertical_index(const Section& s, const std::string& name) {
        if (auto it = profiles.vertical.find(name); it != profiles.vertical.end())
            return intern(scene.profiles.vertical, it->second);
        if (contains(kBuiltinVertical, name)) return intern(scene.profiles.vertical, builtin_vertical(name));
        std::vector<std::string> known(std::begin(kBuiltinVertical), std::end(kBuiltinVertical));
        for (const auto& [n, p] : profiles.vertical) known.push_back(n);
        s.fail(s.get("vertical_profile"), "vertical_profile",
               fmt::format("unknown vertical profile \"{}\"; known profiles are {}.", text::echo(name),
                           join(known, "\"")));
    }

    int horizontal_index(const Section& s, const std::string& name) {
        if (auto it = profiles.horizontal.find(name); it != profiles.horizontal.end())
            return intern(scene.profiles.horizontal, it->second);
        if (name == "uniform") return intern(scene.profiles.horizontal, HorizontalProfile::uniform());
        std::vector<std::string> known(std::begin(kBuiltinHorizontal), std::end(kBuiltinHorizontal));
        for (const auto& [n, p] : profiles.horizontal) known.push_back(n);
        s.fail(s.get("horizontal_profile"), "horizontal_profile",
               fmt::format("unknown horizontal profile \"{}\"; known profiles are {}.", text::echo(name),
                           join(known, "\"")));
    }

    void claim_name(const Section& s, const std::string& name) {
        const toml::node* at = s.has("name") ? s.get("name") : &s.table();
        if (auto it = names.find(name); it != names.end())
            s.fail(at, "name",
                   fmt::format("the light name \"{}\" is already used by {}; names must be unique.", text::echo(name),
                               it->second));
        names.emplace(name, s.path());
    }

    void read_light(const toml::node& node, std::size_t index) {
        const std::string path = fmt::format("light[{}]", index);
        if (!node.is_table())
            doc.fail(&node, path,
                     fmt::format("each light must be a [[light]] table, got {}.", type_phrase(node.type())));
        Section s(doc, *node.as_table(), path, fmt::format("[[light]] number {} ({})", index + 1, path));
        s.allow(kLightKeys);

        Light light;
        light.name = s.string("name").value_or(fmt::format("light{}", index));
        if (light.name.empty()) s.fail(s.get("name"), "name", "a light's name must not be empty.");
        s.set_context(fmt::format("in light \"{}\", ", text::echo(light.name)));
        s.set_title(fmt::format("[[light]] \"{}\" ({})", text::echo(light.name), path));

        auto position = vec3(s, "position_m");
        if (!position) s.missing("position_m", "the light's position [x, y, z] in metres");
        light.position_m = *position;
        light.intensity_cd = s.required_number("intensity_cd", "the light's peak luminous intensity in cd");
        s.at_least("intensity_cd", light.intensity_cd, 0.0);
        light.radius_m = s.number_or("radius_m", light.radius_m);
        s.greater_than("radius_m", light.radius_m, 0.0);

        const std::vector<std::string_view> colour_keys = {"colour", "xy", "spd"};
        std::vector<std::string_view> given;
        for (auto k : colour_keys)
            if (s.has(k)) given.push_back(k);
        if (given.size() > 1)
            s.fail(s.get(given[1]), given[1],
                   fmt::format("give only one of colour, xy and spd; this light has {}.", join(given)));
        light.rgb_per_cd = read_colour(s);
        light.spd = glare_spectrum(s);
        light.glare = read_glare_model(s);

        light.orientation = orientation_from_yaw_pitch_roll(s.number_or("yaw_deg", 0.0), s.number_or("pitch_deg", 0.0),
                                                            s.number_or("roll_deg", 0.0));

        light.vertical_profile = vertical_index(s, s.string("vertical_profile").value_or("uniform"));
        if (s.has("sectors") && s.has("horizontal_profile"))
            s.fail(s.get("sectors"), "sectors", "give either horizontal_profile or sectors, not both.");
        if (s.has("sectors"))
            light.horizontal_profile =
                intern(scene.profiles.horizontal, horizontal_from_sectors(s, read_sectors(doc, s, "sectors")));
        else
            light.horizontal_profile = horizontal_index(s, s.string("horizontal_profile").value_or("uniform"));

        RhythmTiming timing;
        timing.ramp_s = s.number_or("ramp_s", timing.ramp_s);
        s.at_least("ramp_s", timing.ramp_s, 0.0);
        light.rhythm_phase_s = s.number_or("rhythm_phase_s", 0.0);
        const std::string rhythm_text = s.string("rhythm").value_or("F");
        Rhythm rhythm;
        try {
            rhythm = parse_rhythm(rhythm_text, timing);
        } catch (const InputError& e) {
            // The parser's sentence starts "rhythm 'TEXT': "; ours already names it.
            std::string why = e.message();
            for (const std::string& prefix :
                 {fmt::format("rhythm '{}': ", rhythm_text), fmt::format("rhythm \"{}\": ", rhythm_text)})
                if (why.starts_with(prefix)) why.erase(0, prefix.size());
            if (!why.empty() && why.back() != '.') why += '.';
            s.fail(s.has("rhythm") ? s.get("rhythm") : &s.table(), "rhythm",
                   fmt::format("invalid rhythm \"{}\": {}", text::echo(rhythm_text), why));
        }
        if (rhythm.channels.empty())
            s.fail(s.get("rhythm"), "rhythm",
                   fmt::format("the rhythm \"{}\" has no channel.", text::echo(rhythm_text)));
        light.rhythm_period_s = rhythm.period_s;

        // A character that names its colours (Al.WR) gives each channel the
        // colour of its chart letter; the light's own colour keys would conflict.
        const bool chart_colours = std::any_of(rhythm.channels.begin(), rhythm.channels.end(),
                                               [](const RhythmChannel& c) { return !c.colour.empty(); });
        if (chart_colours && !given.empty())
            s.fail(s.get(given[0]), given[0],
                   fmt::format("the rhythm \"{}\" gives the colours itself; remove {}.", text::echo(rhythm_text),
                               given[0]));

        const toml::node* name_node = s.has("name") ? s.get("name") : &s.table();
        if (rhythm.channels.size() == 1) {
            const RhythmChannel& channel = rhythm.channels.front();
            if (!channel.colour.empty()) {
                light.rgb_per_cd = chart_letter_rgb(s, channel.colour, rhythm_text);
                light.spd = chart_letter_spectrum(channel.colour);
            }
            light.rhythm = channel.knots;
            claim_name(s, light.name);
            scene.lights.push_back(std::move(light));
            return;
        }
        // Alternating: one light per channel, "NAME/W", "NAME/R", ...
        claim_name(s, light.name);
        for (const RhythmChannel& channel : rhythm.channels) {
            Light l = light;
            l.name = fmt::format("{}/{}", light.name, channel.colour);
            l.rgb_per_cd = chart_letter_rgb(s, channel.colour, rhythm_text);
            l.spd = chart_letter_spectrum(channel.colour);
            l.rhythm = channel.knots;
            if (auto it = names.find(l.name); it != names.end())
                s.fail(name_node, "name",
                       fmt::format("the alternating rhythm makes a light \"{}\", a name already used by {}.", l.name,
                                   it->second));
            names.emplace(l.name, s.path());
            scene.lights.push_back(std::move(l));
        }
    }

    /// One [[disc]]: a uniform patch of luminance (scene.h Disc). Its name is
    /// unique among lights and discs, so that a protocol's view names one thing.
    void read_disc(const toml::node& node, std::size_t index) {
        const std::string path = fmt::format("disc[{}]", index);
        if (!node.is_table())
            doc.fail(&node, path, fmt::format("each disc must be a [[disc]] table, got {}.", type_phrase(node.type())));
        Section s(doc, *node.as_table(), path, fmt::format("[[disc]] number {} ({})", index + 1, path));
        s.allow(kDiscKeys);
        Disc disc;
        disc.name = s.string("name").value_or(fmt::format("disc{}", index));
        if (disc.name.empty()) s.fail(s.get("name"), "name", "a disc's name must not be empty.");
        s.set_context(fmt::format("in disc \"{}\", ", text::echo(disc.name)));
        s.set_title(fmt::format("[[disc]] \"{}\" ({})", text::echo(disc.name), path));
        auto position = vec3(s, "position_m");
        if (!position) s.missing("position_m", "a point [x, y, z] in metres on the line of sight to the disc's centre");
        disc.position_m = *position;
        disc.diameter_deg = s.required_number("diameter_deg", "the disc's angular diameter in degrees");
        s.within("diameter_deg", disc.diameter_deg, 0.0, 90.0);
        disc.luminance_cd_m2 = s.required_number("luminance_cd_m2", "the disc's luminance in cd/m²");
        s.at_least("luminance_cd_m2", disc.luminance_cd_m2, 0.0);
        std::vector<std::string_view> given;
        for (std::string_view k : {"colour", "xy", "spd"})
            if (s.has(k)) given.push_back(k);
        if (given.size() > 1)
            s.fail(s.get(given[1]), given[1],
                   fmt::format("give only one of colour, xy and spd; this disc has {}.", join(given)));
        disc.rgb_per_cd_m2 = read_colour(s);
        const toml::node* at = s.has("name") ? s.get("name") : &s.table();
        if (auto it = names.find(disc.name); it != names.end())
            s.fail(at, "name",
                   fmt::format("the name \"{}\" is already used by {}; lights and discs need names of their own.",
                               text::echo(disc.name), it->second));
        names.emplace(disc.name, path);
        scene.discs.push_back(std::move(disc));
    }

    /// The glare spectrum of a chart letter's colour (chart_letter_rgb has checked the letter).
    static std::string chart_letter_spectrum(const std::string& letter) {
        const auto name = iala_colour_from_chart_letter(letter);
        return iala_colour_spectrum_name(name.value_or("white")).value_or("d65");
    }

    glm::dvec3 chart_letter_rgb(const Section& s, const std::string& letter, const std::string& rhythm_text) {
        if (auto name = iala_colour_from_chart_letter(letter))
            if (auto rgb = iala_colour_rgb(*name)) return *rgb;
        s.fail(s.get("rhythm"), "rhythm",
               fmt::format("the rhythm \"{}\" names the colour letter \"{}\", which is not an IALA colour.",
                           rhythm_text, letter));
    }
};

/// A derived limit: the glare billboard, the model's radius in degrees times
/// the display's pixels per degree, must fit the glare kernel (4097 px). The
/// sentence names every key the width comes from, with its line (or --set).
void check_billboard(const Document& doc, const Section& root, const Scene& scene) {
    // The widest billboard of the models in use: the eye's, and any a light asks for.
    GlareSettings widest = scene.glare;
    double radius_deg = 0.0;
    for (const GlareModel m : glare_models_used(scene)) {
        GlareSettings g = scene.glare;
        g.model = m;
        if (const double r = glare_billboard_radius_deg(g); r > radius_deg) {
            radius_deg = r;
            widest = g;
        }
    }
    if (!(radius_deg > 0.0)) return;  // no glare: no billboard
    const double ppd = scene.display.pixels_per_degree_at_centre();
    const double width_px = glare_kernel_width_px(ppd, radius_deg);
    if (width_px <= kMaxGlareKernelPx) return;
    const auto node_in = [&](std::string_view table, std::string_view key) -> const toml::node* {
        const toml::node* t = root.get(table);
        return t != nullptr && t->is_table() ? t->as_table()->get(key) : nullptr;
    };
    const auto at = [&](std::string_view table, std::string_view key) {
        const toml::node* n = node_in(table, key);
        if (n == nullptr) return std::string(" (not given)");
        const SourceLocation w = doc.where(n, fmt::format("{}.{}", table, key));
        if (w.from_command_line()) return std::string(" (--set)");
        if (w.file != doc.file()) return fmt::format(" ({}:{})", w.file, w.line);  // e.g. a protocol's [display]
        return w.line > 0 ? fmt::format(" (line {})", w.line) : std::string();
    };
    const toml::node* radius_node = node_in("glare", "radius_deg");
    const std::string radius_text =
        radius_node != nullptr
            ? fmt::format("glare.radius_deg = {}{}", number_text(radius_deg), at("glare", "radius_deg"))
            : fmt::format("{:.4g}°, the {} model's default radius{}", radius_deg, glare_model_name(widest.model),
                          glare_psf_degrees_per_texel(widest) > 0.0  // the FFT models
                              ? " for its psf_size"
                              : "");
    const std::string message = fmt::format(
        "the glare billboard is {} px wide, more than the {} px a glare kernel may be: its radius ({}) at "
        "{:.1f} px per degree, from display.width_px = {}{}, display.width_m = {}{} and "
        "display.viewing_distance_m = {}{}. Check the display's size and viewing distance, or give a smaller "
        "glare.radius_deg.",
        number_text(width_px), kMaxGlareKernelPx, radius_text, ppd, scene.display.width_px, at("display", "width_px"),
        number_text(scene.display.width_m), at("display", "width_m"), number_text(scene.display.viewing_distance_m),
        at("display", "viewing_distance_m"));
    // At the radius when the file gives it, else at the viewing distance (the
    // usual culprit: a distance in mm written as metres).
    if (radius_node != nullptr) doc.fail(radius_node, "glare.radius_deg", message);
    doc.fail(node_in("display", "viewing_distance_m"), "display.viewing_distance_m", message);
}

void read_discs(const Section& root, SceneBuilder& builder) {
    const toml::node* discs = root.get("disc");
    if (discs == nullptr) return;
    if (!discs->is_array())
        root.fail(discs, "disc",
                  fmt::format("expected an array of [[disc]] tables, got {}; write [[disc]], not [disc].",
                              type_phrase(discs->type())));
    const toml::array& a = *discs->as_array();
    for (std::size_t i = 0; i < a.size(); ++i) builder.read_disc(*a.get(i), i);
}

void read_lights_and_discs(const Document& doc, const Section& root, Scene& scene, const Profiles& profiles,
                           bool profiles_read, text::ErrorList& errors) {
    const auto step = [&](auto&& f) { return errors.attempt(f); };
    SceneBuilder builder{doc, scene, profiles, {}};
    if (const toml::node* lights = root.get("light"); lights != nullptr && profiles_read) {
        const bool is_array = step([&] {
            if (!lights->is_array())
                root.fail(lights, "light",
                          fmt::format("expected an array of [[light]] tables, got {}; write [[light]], not [light].",
                                      type_phrase(lights->type())));
        });
        if (is_array) {
            const toml::array& a = *lights->as_array();
            for (std::size_t i = 0; i < a.size(); ++i) step([&] { builder.read_light(*a.get(i), i); });
        }
    }
    step([&] { read_discs(root, builder); });
}

}  // namespace atonlab::stimuli::scene_reader
