// The registries (docs/architecture.md "How to add a glare model", "How to add a
// display encoding"): each one's names are unique and read back through every
// reader, and no name is spelled in a string literal outside its registry's
// files, so that adding one touches only the files the doc names.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "atonlab/common/scene_override.h"
#include "atonlab/display/display_encodings.h"
#include "atonlab/display/display_model.h"
#include "atonlab/stimuli/glare_models/glare_model.h"
#include "atonlab/stimuli/image_glare.h"
#include "atonlab/stimuli/scene.h"
#include "atonlab/stimuli/scene_file.h"

namespace {

namespace fs = std::filesystem;
using namespace atonlab::stimuli;
namespace display = atonlab::display;

std::string read_text(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

// ---------------------------------------------------------------------------
// The registries and where their names may be spelled. A registry joins the
// scan by one entry here: the names it registers, and the files (paths or
// folders, from the source root) that may spell them.

struct Registry {
    std::string what;
    /// Scanned as whole words inside string literals ("an image's glare can be spencer or cie").
    std::vector<std::string> words;
    /// Scanned as whole string literals only (a display's name: "a PQ display" is prose, "PQ" is a name).
    std::vector<std::string> literals;
    std::vector<std::string> allowed;
};

std::vector<Registry> registries() {
    std::vector<Registry> out;
    Registry glare{"glare models", {}, {}, {"stimuli/include/atonlab/stimuli/glare_models/glare_model_list.h",
                                           "stimuli/src/glare_models/"}};
    for (const GlareModelType* m : glare_models())
        // "none" is also a window, a hue preservation, a light's background: not scanned.
        if (m->id() != GlareModel::none) glare.words.emplace_back(m->name());
    out.push_back(glare);

    Registry encodings{"display encodings", {}, {}, {"display/include/atonlab/display/display_encodings.h",
                                                     "display/src/display_encodings.cpp"}};
    for (const display::DisplayEncoding& e : display::display_encodings())
        // "gog" and "lut" are also the JSON fields holding those laws' parameters (fit_json): not scanned.
        if (e.from_peak_black != nullptr) encodings.words.emplace_back(e.name);
    out.push_back(encodings);
    return out;
}

/// The folders scanned: the libraries and the command line (not docs, tests, examples or scenes).
constexpr const char* kScannedFolders[] = {"stimuli", "display", "runner", "protocols", "analysis", "common", "store"};

struct Literal {
    int line = 0;
    std::string text;
};

/// The string literals of a C++ source (comments and character literals skipped; raw strings read).
std::vector<Literal> string_literals(const std::string& src) {
    std::vector<Literal> out;
    int line = 1;
    const std::size_t n = src.size();
    auto word_char = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
    for (std::size_t i = 0; i < n;) {
        const char c = src[i];
        if (c == '\n') {
            ++line;
            ++i;
        } else if (src.compare(i, 2, "//") == 0) {
            i = std::min(src.find('\n', i), n);
        } else if (src.compare(i, 2, "/*") == 0) {
            const std::size_t end = std::min(src.find("*/", i + 2), n);
            line += static_cast<int>(std::count(src.begin() + static_cast<std::ptrdiff_t>(i),
                                                src.begin() + static_cast<std::ptrdiff_t>(end), '\n'));
            i = end + 2;
        } else if (c == 'R' && i + 1 < n && src[i + 1] == '"' && (i == 0 || !word_char(src[i - 1]))) {
            const std::size_t open = src.find('(', i);
            const std::string close = ")" + src.substr(i + 2, open - i - 2) + "\"";
            const std::size_t end = std::min(src.find(close, open), n);
            out.push_back({line, src.substr(open + 1, end - open - 1)});
            line += static_cast<int>(std::count(src.begin() + static_cast<std::ptrdiff_t>(i),
                                                src.begin() + static_cast<std::ptrdiff_t>(end), '\n'));
            i = end + close.size();
        } else if (c == '"') {
            std::size_t j = i + 1;
            while (j < n && src[j] != '"') j += src[j] == '\\' ? 2 : 1;
            out.push_back({line, src.substr(i + 1, j - i - 1)});
            i = j + 1;
        } else if (c == '\'' && (i == 0 || !std::isalnum(static_cast<unsigned char>(src[i - 1])))) {
            std::size_t j = i + 1;
            while (j < n && src[j] != '\'') j += src[j] == '\\' ? 2 : 1;
            i = j + 1;
        } else {
            ++i;
        }
    }
    return out;
}

bool has_word(const std::string& text, const std::string& word) {
    auto word_char = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-'; };
    for (std::size_t at = text.find(word); at != std::string::npos; at = text.find(word, at + 1)) {
        const bool start = at == 0 || !word_char(text[at - 1]);
        const std::size_t end = at + word.size();
        if (start && (end == text.size() || !word_char(text[end]))) return true;
    }
    return false;
}

/// "file:line: 'name' in "literal"" for every name of `r` spelled outside its files.
std::vector<std::string> misplaced_names(const Registry& r) {
    const fs::path root = ATONLAB_SOURCE_DIR;
    std::vector<std::string> found;
    for (const char* folder : kScannedFolders) {
        for (const auto& entry : fs::recursive_directory_iterator(root / folder)) {
            const std::string ext = entry.path().extension().string();
            if (!entry.is_regular_file() || (ext != ".cpp" && ext != ".h")) continue;
            const std::string rel = entry.path().lexically_relative(root).generic_string();
            if (std::any_of(r.allowed.begin(), r.allowed.end(), [&](const std::string& a) { return rel.starts_with(a); }))
                continue;
            for (const Literal& lit : string_literals(read_text(entry.path()))) {
                for (const std::string& w : r.words)
                    if (has_word(lit.text, w))
                        found.push_back(rel + ":" + std::to_string(lit.line) + ": '" + w + "' in \"" + lit.text + "\"");
                for (const std::string& l : r.literals)
                    if (lit.text == l) found.push_back(rel + ":" + std::to_string(lit.line) + ": \"" + l + "\"");
            }
        }
    }
    return found;
}

TEST(Registries, NamesAreSpelledOnlyInTheirRegistry) {
    for (const Registry& r : registries()) {
        ASSERT_FALSE(r.words.empty() && r.literals.empty()) << r.what;
        std::string list;
        for (const std::string& f : misplaced_names(r)) list += "\n  " + f;
        EXPECT_TRUE(list.empty()) << r.what << " spelled outside " << r.allowed.front()
                                  << " (read the name from the registry instead):" << list;
    }
}

TEST(Registries, TheScanFindsANameInALiteral) {
    // The scanner itself: a name in a literal is found, in a comment or as part of a longer word it is not.
    const auto lits = string_literals("// \"spencer\"\nauto a = \"spencer or cie\"; /* \"cie\" */ char c = '\"';\n"
                                      "auto b = R\"x(wave-optics)x\"; auto d = \"cie_age_years\";\n");
    ASSERT_EQ(lits.size(), 3u);
    EXPECT_EQ(lits[0].line, 2);
    EXPECT_TRUE(has_word(lits[0].text, "cie"));
    EXPECT_TRUE(has_word(lits[1].text, "wave-optics"));
    EXPECT_FALSE(has_word(lits[2].text, "cie"));
    EXPECT_FALSE(has_word("gaussian-bloom-like", "gaussian-bloom"));
}

// ---------------------------------------------------------------------------
// Glare models.

TEST(Registries, GlareModelNamesAreUniqueAndRoundTrip) {
    std::set<std::string_view> names;
    std::size_t i = 0;
    for (const GlareModelType* m : glare_models()) {
        EXPECT_EQ(static_cast<std::size_t>(m->id()), i++) << m->name();
        EXPECT_TRUE(names.insert(m->name()).second) << "twice: " << m->name();
        EXPECT_EQ(glare_model_from_name(m->name()), m->id());
        EXPECT_EQ(&glare_model_type(m->id()), m);
        EXPECT_FALSE(m->summary().empty()) << m->name();
    }
    EXPECT_FALSE(glare_model_from_name("sparkle").has_value());
}

constexpr const char* kScene = R"([display]
width_px = 800
height_px = 600
width_m = 0.4
viewing_distance_m = 0.6
[[light]]
name = "buoy"
position_m = [0, 2, -500]
intensity_cd = 1
)";

TEST(Registries, EveryGlareModelReadsBackFromASceneAndFromSet) {
    for (const GlareModelType* m : glare_models()) {
        const std::string name(m->name());
        const Scene file = parse_scene(std::string(kScene) + "glare = \"" + name + "\"\n[eye]\nglare = \"" + name + "\"\n",
                                       "registry.toml");
        EXPECT_EQ(file.glare.model, m->id()) << name;
        ASSERT_EQ(file.lights.size(), 1u);
        EXPECT_EQ(file.lights[0].glare, m->id()) << name;
        const Scene set = parse_scene(kScene, "registry.toml",
                                      {atonlab::SceneOverride::parse("eye.glare=\"" + name + "\""),
                                       atonlab::SceneOverride::parse("light.buoy.glare=\"" + name + "\"")});
        EXPECT_EQ(set.glare.model, m->id()) << name;
        EXPECT_EQ(light_glare_model(set, set.lights[0]), m->id()) << name;
    }
}

/// The table row of `doc` whose first cell is `key` ("| `bloom_sigma_deg` | …"); "" when none.
std::string row_of(const std::string& doc, std::string_view key) {
    std::istringstream lines(doc);
    const std::string start = "| `" + std::string(key) + "` |";
    for (std::string line; std::getline(lines, line);)
        if (line.starts_with(start)) return line;
    return {};
}

TEST(Registries, EveryGlareModelsSettingsAreReadAndDocumentedAsDeclared) {
    // Each model's declared settings (glare_setting.h) are keys of the scene file (--set takes them), and
    // docs/scene-file.md's row of each is its declaration: type, unit, default and meaning.
    const std::string doc = read_text(fs::path(ATONLAB_SOURCE_DIR) / "docs/scene-file.md");
    std::set<std::string_view> keys;
    for (const GlareModelType* m : glare_models()) {
        for (const GlareSetting& s : m->settings()) {
            EXPECT_TRUE(keys.insert(s.key).second) << s.key << " is declared twice";
            const std::string row = fmt::format("| `{}` | {} | {} | {} | {} |", s.key, s.type, s.unit, s.default_text,
                                                s.doc);
            EXPECT_EQ(row_of(doc, s.key), row) << m->name() << ": docs/scene-file.md's row of " << s.key
                                               << " is not its declaration";
            try {
                // A key the reader does not know is refused as unknown; a known one may only be refused for its value.
                (void)parse_scene(kScene, "registry.toml",
                                  {atonlab::SceneOverride::parse(fmt::format("{}.{}=1", glare_table_name(s.table), s.key))});
            } catch (const atonlab::InputError& e) {
                EXPECT_EQ(std::string(e.what()).find("unknown key"), std::string::npos) << m->name() << ": " << e.what();
            }
        }
    }
    // The `glare` rows of [eye] and [[light]] name every model.
    std::istringstream lines(doc);
    int rows = 0;
    for (std::string line; std::getline(lines, line);) {
        if (!line.starts_with("| `glare` |")) continue;
        ++rows;
        for (const GlareModelType* m : glare_models())
            EXPECT_NE(line.find("`\"" + std::string(m->name()) + "\"`"), std::string::npos)
                << "docs/scene-file.md's glare row lacks " << m->name() << ": " << line;
    }
    EXPECT_EQ(rows, 2);
}

TEST(Registries, EveryImageGlareKernelConservesEnergy) {
    // Each model `atonlab glare` takes: every channel of its kernel sums to 1 (glare_kernel.h), so the
    // convolution keeps Σ L·Ω. Texels are floats: 1e-5 allows their rounding over a few thousand texels.
    GlareSettings g;
    g.psf_size = 128;
    g.spectral_samples = 5;
    g.spectral_anchors = 2;
    int models = 0;
    for (const GlareModelType* m : glare_models()) {
        g.model = m->id();
        if (!m->on_images()) {
            EXPECT_THROW((void)image_glare_kernel(g, 1.0, 0.05), atonlab::InputError) << m->name();
            continue;
        }
        ++models;
        const GlareKernel k = image_glare_kernel(g, 1.0, 0.05);
        glm::dvec3 sum{0.0};
        for (const glm::vec4& t : k.rgba) sum += glm::dvec3(t.r, t.g, t.b);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[c], 1.0, 1e-5) << m->name() << " channel " << c;
    }
    EXPECT_GE(models, 1);
}

// ---------------------------------------------------------------------------
// Display encodings.

TEST(Registries, DisplayEncodingsAreUniqueAndPairedWithTheirGlsl) {
    const std::string glsl = read_text(fs::path(ATONLAB_SOURCE_DIR) / "stimuli/shaders/display_encode.glsl");
    const std::string dispatch = display::display_encodings_glsl();
    std::set<std::string_view> names, display_names, functions;
    std::size_t i = 0;
    for (const display::DisplayEncoding& e : display::display_encodings()) {
        EXPECT_EQ(static_cast<std::size_t>(e.kind), i++) << e.name;
        EXPECT_TRUE(names.insert(e.name).second) << e.name;
        EXPECT_TRUE(display_names.insert(e.display_name).second) << e.display_name;
        EXPECT_TRUE(functions.insert(e.glsl_drive_function).second) << e.glsl_drive_function;
        EXPECT_EQ(display::display_encoding_named(e.name), &e);
        EXPECT_NE(glsl.find("double " + std::string(e.glsl_drive_function) + "(DisplayChannel c, double L)"),
                  std::string::npos)
            << e.name << ": display_encode.glsl has no " << e.glsl_drive_function;
        EXPECT_NE(dispatch.find(std::string(e.glsl_drive_function) + "(c, L)"), std::string::npos) << e.name;
    }
    EXPECT_EQ(display::display_encoding_named("PQ"), nullptr);
}

TEST(Registries, EveryNamedDisplayReadsBackFromASceneAndItsFitJson) {
    for (const display::DisplayEncoding& e : display::display_encodings()) {
        if (e.from_peak_black == nullptr) continue;
        const std::string name(e.name);
        const Scene s = parse_scene(kScene, "registry.toml",
                                    {atonlab::SceneOverride::parse("display.transfer=\"" + name + "\"")});
        EXPECT_EQ(display::display_encoding_of(s.output.display), &e) << name;
        EXPECT_EQ(s.output.display.name, e.display_name) << name;
        const display::DisplayModel d = *display::display_from_transfer(name, 200.0, 0.1);
        for (const display::ChannelTransfer& ch : d.channels) {
            EXPECT_EQ(ch.kind, e.kind);
            // The law and its inverse agree (the registry pairs them): L(V(L)) = L.
            const double L = 0.5 * (ch.min_cd_m2() + ch.max_cd_m2());
            EXPECT_NEAR(ch.luminance_cd_m2(ch.drive_for(L)), L, 1e-9 * ch.max_cd_m2()) << name;
        }
    }
}

}  // namespace
