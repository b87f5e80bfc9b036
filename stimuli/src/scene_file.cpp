// The scene file (scene_file.h; every key documented in docs/scene-file.md).
//
// Three steps: parse the TOML text once (SceneTemplate; syntax errors keep the
// parser's line), apply the overrides to the parsed tree, then validate the
// tree against the schema while building the Scene (and undo the overrides).
// Every value's error names the file, line and dotted key; a value that an
// override gave names where the override was written: its protocol line, or
// "--set KEY" (override values are parsed with the source path "--set KEY",
// toml++ keeps a node's source when it is moved into the tree, and the
// Document maps that path to the override's origin).
#include "atonlab/stimuli/scene_file.h"

#include <mutex>

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

// The tree is parsed once. instantiate() applies the overrides to it in place
// and undoes them after the scene is built (TreeEdits: the nodes are moved,
// never copied, so they keep their source lines; toml++ drops a node's source
// when it is copied, and every error must name the file's line). The mutex
// makes concurrent instantiate() calls on copies of one template safe.
struct SceneTemplate::Parsed {
    std::string file_label;
    mutable std::mutex mutex;
    mutable toml::table root;  ///< the file's tree; changed only inside instantiate(), under the mutex
};

SceneTemplate SceneTemplate::parse(std::string_view toml_text, std::string_view file_label) {
    auto parsed = std::make_shared<Parsed>();
    parsed->file_label = std::string(file_label);
    try {
        parsed->root = toml::parse(toml_text, file_label);
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
    const std::lock_guard<std::mutex> lock(parsed_->mutex);
    Document doc{parsed_->file_label};
    TreeEdits edits;  // undone on the way out, scene made or refused: the tree is the file's again
    for (const SceneOverride& o : overrides) apply_override(doc, parsed_->root, o, edits);
    return build_scene(doc, parsed_->root);
}

Scene parse_scene(std::string_view toml_text, std::string_view file_label,
                  const std::vector<SceneOverride>& overrides) {
    return SceneTemplate::parse(toml_text, file_label).instantiate(overrides);
}

Scene load_scene(const std::filesystem::path& file, const std::vector<SceneOverride>& overrides) {
    return SceneTemplate::load(file).instantiate(overrides);
}

}  // namespace atonlab::stimuli
