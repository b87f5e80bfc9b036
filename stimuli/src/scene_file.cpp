// The scene file (scene_file.h; every key documented in docs/scene-file.md).
//
// Three steps: parse the TOML text (syntax errors keep the parser's line),
// apply the --set overrides to the parsed tree, then validate the tree against
// the schema while building the Scene. Every value's error names the file,
// line and dotted key; a value that came from --set names "--set KEY" instead
// (override values are parsed with the source path "--set KEY", and toml++
// keeps a node's source when it is moved into the scene's tree).
#include "atonlab/stimuli/scene_file.h"

#include "scene_reader.h"

namespace atonlab::stimuli {
namespace {

using namespace scene_reader;  // NOLINT: the reader's parts

Scene build_scene(Document& doc, const toml::table& root_table) {
    // Every table (and every light) is read even after an error in another:
    // all the errors, in file order, in one run (text::ErrorList; docs/scene-file.md).
    text::ErrorList errors;
    const auto step = [&](auto&& f) { return errors.attempt(f); };
    // Every unknown key of a table is reported, not only the first (Section::allow).
    doc.collect_into(&errors);
    Section root(doc, root_table, "", "the scene");
    // Unknown top-level tables are reported with the list of sections.
    for (auto&& entry : root_table) {
        // Named references, not structured bindings: clang 14 (the fuzz
        // build) cannot capture a binding in a lambda.
        const toml::key& k = entry.first;
        const toml::node& v = entry.second;
        if (contains(kSections, k.str())) continue;
        step([&] {
            throw InputError(
                doc.where(k, std::string(k.str())),
                fmt::format("unknown {} '{}'.{} A scene has the tables {}.", v.is_table() ? "table" : "key",
                            text::echo(k.str()), did_you_mean(k.str(), kSections), join(kSections)));
        });
    }
    Scene scene;
    step([&] { scene.display = read_display(doc, root); });
    step([&] { scene.camera = read_camera(doc, root); });
    step([&] { scene.environment = read_environment(doc, root); });
    step(
        [&] { scene.adaptation_cd_m2 = read_eye(doc, root, scene.environment, scene.glare, scene.output.adaptation); });
    scene.output.adaptation.fixed_cd_m2 = scene.adaptation_cd_m2;
    // The pupil the glare stage will use (glare_stage.h glare_pupil_mm): given,
    // or eq 3.15 from the fixed adaptation, or the dark-adapted 7.9 mm when the
    // adaptation follows the frame.
    const double pupil_mm = scene.glare.pupil_mm ? *scene.glare.pupil_mm
                            : scene.output.adaptation.mode == AdaptationMode::dynamic
                                ? pupil_diameter_mm_from_adaptation(0.0)
                                : pupil_diameter_mm_from_adaptation(scene.adaptation_cd_m2);
    step([&] { read_glare(doc, root, scene.glare, pupil_mm); });
    const bool output_read = step([&] { read_output(doc, root, scene.output); });
    Profiles profiles;
    const bool profiles_read = step([&] { profiles = read_profiles(doc, root); });

    read_lights_and_discs(doc, root, scene, profiles, profiles_read, errors);
    // The billboard check needs the display, the output and each light's own
    // glare model as read.
    if (output_read && errors.empty()) step([&] { check_billboard(doc, root, scene); });
    doc.collect_into(nullptr);
    errors.throw_if_any();
    return scene;
}

}  // namespace

SceneOverride SceneOverride::parse(std::string_view text) {
    const auto trim = [](std::string_view s) {
        while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
        while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
        return s;
    };
    const auto eq = text.find('=');
    if (eq == std::string_view::npos)
        throw InputError(SourceLocation::command_line(std::string(kSetOption), std::string(trim(text))),
                         fmt::format("expected KEY=VALUE, e.g. camera.yaw_deg=45, got \"{}\".", text::echo(text)));
    SceneOverride o;
    o.key = std::string(trim(text.substr(0, eq)));
    o.value = std::string(trim(text.substr(eq + 1)));
    if (o.key.empty())
        throw InputError(SourceLocation::command_line(std::string(kSetOption)),
                         fmt::format("the key before '=' is empty in \"{}\".", text::echo(text)));
    return o;
}

// The text is kept and parsed again by each instantiate(): toml++ drops a
// node's source region when it is copied ("does not copy source information"),
// and every error must keep the file's line, so a copy of one parsed tree
// cannot serve. The template checks the syntax once, and reads the file once.
struct SceneTemplate::Parsed {
    std::string file_label;
    std::string text;
};

SceneTemplate SceneTemplate::parse(std::string_view toml_text, std::string_view file_label) {
    auto parsed = std::make_shared<Parsed>();
    parsed->file_label = std::string(file_label);
    parsed->text = std::string(toml_text);
    try {
        (void)toml::parse(toml_text, file_label);
    } catch (const toml::parse_error& e) {
        throw InputError(SourceLocation{std::string(file_label), static_cast<int>(e.source().begin.line),
                                        static_cast<int>(e.source().begin.column), ""},
                         fmt::format("TOML syntax error: {}.", std::string(e.description())));
    }
    return SceneTemplate(std::move(parsed));
}

SceneTemplate SceneTemplate::load(const std::filesystem::path& file) {
    // Read only up to a limit: /dev/zero or a video file given by mistake is
    // refused, not read until the memory runs out.
    const text::FileText read = text::read_text_file(file);
    if (!read.ok())
        throw InputError(SourceLocation{file.string(), 0, 0, ""},
                         fmt::format("cannot read the scene file: {}.", read.error));
    return parse(read.text, file.string());
}

const std::string& SceneTemplate::file_label() const noexcept { return parsed_->file_label; }

Scene SceneTemplate::instantiate(const std::vector<SceneOverride>& overrides) const {
    Document doc{parsed_->file_label};
    toml::table root = toml::parse(parsed_->text, parsed_->file_label);
    for (const SceneOverride& o : overrides) apply_override(doc, root, o);
    return build_scene(doc, root);
}

Scene parse_scene(std::string_view toml_text, std::string_view file_label,
                  const std::vector<SceneOverride>& overrides) {
    return SceneTemplate::parse(toml_text, file_label).instantiate(overrides);
}

Scene load_scene(const std::filesystem::path& file, const std::vector<SceneOverride>& overrides) {
    return SceneTemplate::load(file).instantiate(overrides);
}

}  // namespace atonlab::stimuli
