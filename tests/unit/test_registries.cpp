// The registries (docs/architecture.md "How to add a glare model", "How to add a
// display encoding", "How to add a procedure"): each one's names are unique and
// read back through every reader, no name is spelled in a string literal
// outside its registry's files, and the number of files each "How to add …"
// says a new entry touches is the number the tree makes an entry touch.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "atonlab/common/scene_override.h"
#include "atonlab/display/display_encodings.h"
#include "atonlab/display/display_model.h"
#include "atonlab/display/fit_json.h"
#include "atonlab/protocols/procedures.h"
#include "atonlab/stimuli/glare_models/glare_model.h"
#include "atonlab/stimuli/image_glare.h"
#include "atonlab/stimuli/scene.h"
#include "atonlab/stimuli/scene_file.h"
#include "scene_file_test_support.h"

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
    /// A file outside `allowed` that may spell one name, and why (kept narrow: no other name, no other file).
    std::map<std::string, std::set<std::string>> exceptions = {};
};

std::vector<Registry> registries() {
    std::vector<Registry> out;
    Registry glare{"glare models",
                   {},
                   {},
                   {"stimuli/include/atonlab/stimuli/glare_models/glare_model_list.h", "stimuli/src/glare_models/"}};
    for (const GlareModelType* m : glare_models())
        // "none" is also a window, a hue preservation, a light's background: not scanned.
        if (m->id() != GlareModel::none) glare.words.emplace_back(m->name());
    out.push_back(glare);

    Registry encodings{"display encodings",
                       {},
                       {},
                       {"display/include/atonlab/display/display_encodings.h", "display/src/display_encodings.cpp",
                        "display/src/encodings/"}};
    for (const display::DisplayEncoding* e : display::display_encodings())
        // "gog" and "lut" are also the JSON fields holding those laws' parameters (fit_json): not scanned.
        if (e->from_peak_black != nullptr) encodings.words.emplace_back(e->name);
    out.push_back(encodings);
    return out;
}

/// The folders scanned: the libraries, the command line, the Python module, the
/// bench and the presentation layer (not docs, tests, examples or scenes).
constexpr const char* kScannedFolders[] = {"stimuli", "display", "runner", "protocols", "analysis",
                                           "common",  "store",   "python", "bench",     "present"};

struct Literal {
    int line = 0;
    std::string text;
};

/// A C++ or GLSL source read: its string literals, and the identifiers of its
/// code outside comments and literals.
struct Scanned {
    std::vector<Literal> literals;
    std::set<std::string> identifiers;
};

/// `src` scanned (comments and character literals skipped; raw strings read).
Scanned scan_source(const std::string& src) {
    Scanned scanned;
    std::vector<Literal>& out = scanned.literals;
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
        } else if (word_char(c) && !std::isdigit(static_cast<unsigned char>(c)) && (i == 0 || !word_char(src[i - 1]))) {
            std::size_t j = i;
            while (j < n && word_char(src[j])) ++j;
            scanned.identifiers.insert(src.substr(i, j - i));
            i = j;
        } else {
            ++i;
        }
    }
    return scanned;
}

/// The string literals of a C++ source.
std::vector<Literal> string_literals(const std::string& src) {
    return scan_source(src).literals;
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

/// "file:line: 'name' in "literal"" for every name of `r` spelled outside its files;
/// `excepted` gets "file: name" for each exception that a literal used.
std::vector<std::string> misplaced_names(const Registry& r, std::set<std::string>* excepted_used = nullptr) {
    const fs::path root = ATONLAB_SOURCE_DIR;
    std::vector<std::string> found;
    for (const char* folder : kScannedFolders) {
        for (const auto& entry : fs::recursive_directory_iterator(root / folder)) {
            const std::string ext = entry.path().extension().string();
            if (!entry.is_regular_file() || (ext != ".cpp" && ext != ".h")) continue;
            const std::string rel = entry.path().lexically_relative(root).generic_string();
            if (std::any_of(r.allowed.begin(), r.allowed.end(),
                            [&](const std::string& a) { return rel.starts_with(a); }))
                continue;
            const auto exception = r.exceptions.find(rel);
            const auto excepted = [&](const std::string& name) {
                const bool is = exception != r.exceptions.end() && exception->second.count(name) != 0;
                if (is && excepted_used != nullptr) excepted_used->insert(rel + ": " + name);
                return is;
            };
            for (const Literal& lit : string_literals(read_text(entry.path()))) {
                for (const std::string& w : r.words)
                    if (has_word(lit.text, w) && !excepted(w))
                        found.push_back(rel + ":" + std::to_string(lit.line) + ": '" + w + "' in \"" + lit.text + "\"");
                for (const std::string& l : r.literals)
                    if (lit.text == l && !excepted(l))
                        found.push_back(rel + ":" + std::to_string(lit.line) + ": \"" + l + "\"");
            }
        }
    }
    return found;
}

TEST(Registries, NamesAreSpelledOnlyInTheirRegistry) {
    for (const Registry& r : registries()) {
        ASSERT_FALSE(r.words.empty() && r.literals.empty()) << r.what;
        std::string list;
        std::set<std::string> excepted_used;
        for (const std::string& f : misplaced_names(r, &excepted_used)) list += "\n  " + f;
        EXPECT_TRUE(list.empty()) << r.what << " spelled outside " << r.allowed.front()
                                  << " (read the name from the registry instead):" << list;
        // An exception no literal needs any more is taken off the table.
        for (const auto& [file, names] : r.exceptions)
            for (const std::string& name : names)
                EXPECT_EQ(excepted_used.count(file + ": " + name), 1u)
                    << r.what << ": " << file << " no longer spells " << name << "; take it off the exceptions";
    }
}

TEST(Registries, TheScanFindsANameInALiteral) {
    // The scanner itself: a name in a literal is found, in a comment or as part of a longer word it is not.
    const auto lits = string_literals(
        "// \"spencer\"\nauto a = \"spencer or cie\"; /* \"cie\" */ char c = '\"';\n"
        "auto b = R\"x(wave-optics)x\"; auto d = \"cie_age_years\";\n");
    ASSERT_EQ(lits.size(), 3u);
    EXPECT_EQ(lits[0].line, 2);
    EXPECT_TRUE(has_word(lits[0].text, "cie"));
    EXPECT_TRUE(has_word(lits[1].text, "wave-optics"));
    EXPECT_FALSE(has_word(lits[2].text, "cie"));
    EXPECT_FALSE(has_word("gaussian-bloom-like", "gaussian-bloom"));
}

// ---------------------------------------------------------------------------
// "How to add …": the number of files docs/architecture.md says a new entry
// touches, against the tree. Each existing entry is looked for in every
// scanned file (its identifiers in code, its name as a word in a literal);
// the entry spelled in the fewest files is what a new one is like (no other
// code uses it yet), so those files must be the section's numbered list, NAME
// read as the entry's file name, and as many as its "Files to touch, N" or
// "touches N" says. A new switch over the entries, or a file the list leaves
// out, makes the least-used entry's files more than the doc says.

struct Entry {
    std::string name;                   ///< as files and messages spell it
    std::string file_name;              ///< NAME in the doc's paths
    std::set<std::string> identifiers;  ///< code tokens that name it
    std::vector<std::string> words;     ///< whole words in a string literal that name it
};

struct HowToAdd {
    std::string section;  ///< its docs/architecture.md heading
    std::vector<Entry> entries;
};

std::string snake(std::string_view name) {
    std::string s(name);
    std::replace(s.begin(), s.end(), '-', '_');
    return s;
}

std::vector<HowToAdd> how_to_adds() {
    std::vector<HowToAdd> out;
    HowToAdd glare{"How to add a glare model", {}};
    for (const GlareModelType* m : glare_models()) {
        if (m->id() == GlareModel::none) continue;  // also a window's, a hue preservation's value
        const std::string id = snake(m->name());    // glare_model_list.h: X(gaussian_bloom, "gaussian-bloom")
        glare.entries.push_back({std::string(m->name()), id, {id, "glare_model_" + id}, {std::string(m->name())}});
    }
    out.push_back(glare);
    HowToAdd encoding{"How to add a display encoding", {}};
    for (const display::DisplayEncoding* e : display::display_encodings()) {
        // Its file defines display_encoding_pq(), which the list's line names. DisplayModel::pq
        // and the other makers of the library's encodings are conveniences a new one needs not.
        const std::string name(e->name);
        encoding.entries.push_back({name, name, {"display_encoding_" + name}, {}});
    }
    out.push_back(encoding);
    HowToAdd procedure{"How to add a procedure", {}};
    for (const atonlab::protocols::ProcedureType* t : atonlab::protocols::procedure_types()) {
        const std::string file = snake(t->name);  // weighted_staircase.h, class WeightedStaircase
        std::string camel;
        for (std::size_t i = 0; i < file.size(); ++i)
            if (file[i] != '_')
                camel += i == 0 || file[i - 1] == '_' ? static_cast<char>(std::toupper(file[i])) : file[i];
        procedure.entries.push_back(
            {std::string(t->name), file, {camel, camel + "Params"}, {std::string(t->name), file}});
    }
    out.push_back(procedure);
    return out;
}

/// Every scanned source (C++ and GLSL), read once.
const std::map<std::string, Scanned>& scanned_sources() {
    static const std::map<std::string, Scanned> sources = [] {
        const fs::path root = ATONLAB_SOURCE_DIR;
        std::map<std::string, Scanned> out;
        for (const char* folder : kScannedFolders)
            for (const auto& entry : fs::recursive_directory_iterator(root / folder)) {
                const std::string ext = entry.path().extension().string();
                if (!entry.is_regular_file() || (ext != ".cpp" && ext != ".h" && ext != ".glsl" && ext != ".comp" &&
                                                 ext != ".frag" && ext != ".vert"))
                    continue;
                out[entry.path().lexically_relative(root).generic_string()] = scan_source(read_text(entry.path()));
            }
        return out;
    }();
    return sources;
}

/// The scanned files that spell `e`.
std::set<std::string> files_spelling(const Entry& e) {
    std::set<std::string> out;
    for (const auto& [rel, src] : scanned_sources()) {
        const auto& identifiers =
            src.identifiers;  // a structured binding cannot be captured before C++20's P1091 (clang 14)
        bool spells = std::any_of(e.identifiers.begin(), e.identifiers.end(),
                                  [&](const std::string& id) { return identifiers.count(id) != 0; });
        for (const Literal& lit : src.literals)
            for (const std::string& w : e.words) spells = spells || has_word(lit.text, w);
        if (spells) out.insert(rel);
    }
    return out;
}

/// What a "How to add …" section states: its count, and the code paths its numbered list names.
struct HowToAddDoc {
    int count = -1;
    std::set<std::string> files;
};

HowToAddDoc how_to_add_doc(const std::string& doc, const std::string& section) {
    HowToAddDoc out;
    const std::size_t heading = doc.find("# " + section + "\n");
    if (heading == std::string::npos) return out;
    const std::size_t end = doc.find("\n#", heading + 1);
    const std::string text = doc.substr(heading, end == std::string::npos ? std::string::npos : end - heading);
    std::smatch m;
    if (!std::regex_search(text, m, std::regex(R"((?:Files to touch, |touches )(\d+)\b)"))) return out;
    out.count = std::stoi(m[1].str());
    // The numbered list after it: its items and their indented lines, up to the next paragraph.
    std::istringstream lines(m.suffix().str());
    std::string list;
    bool in_list = false;
    const std::regex item(R"(^\d+\. )");
    for (std::string line; std::getline(lines, line);) {
        const bool is_item = std::regex_search(line, item);
        if (is_item) in_list = true;
        if (!in_list) continue;
        if (!is_item && !line.empty() && line.front() != ' ') break;
        list += line + "\n";
    }
    const std::regex path(R"(`((?:[a-z_]+/)+[A-Za-z0-9_.]+\.(?:h|cpp|glsl|comp|frag|vert))`)");
    for (auto p = std::sregex_iterator(list.begin(), list.end(), path); p != std::sregex_iterator(); ++p)
        out.files.insert((*p)[1].str());
    return out;
}

std::string listed(const std::set<std::string>& files) {
    std::string s;
    for (const std::string& f : files) s += "\n    " + f;
    return s;
}

TEST(Registries, TheHowToAddReaderTakesTheCountAndTheNumberedList) {
    const std::string doc =
        "## Other\n\nFiles to touch, 9:\n\n1. `a/NAME.h`\n\n"
        "### How to add a thing\n\nText `x/prose.cpp`. Files to touch, 2 in code:\n\n"
        "1. `a/src/NAME.cpp` (as `a/`, or `NAME.h`);\n2. `b/include/list.h`: one line, beside\n"
        "   `b/src/list.cpp`;\n\nThen `c/later.cpp`.\n\n## Next\n\nFiles to touch, 7:\n";
    const HowToAddDoc d = how_to_add_doc(doc, "How to add a thing");
    EXPECT_EQ(d.count, 2);
    EXPECT_EQ(d.files, (std::set<std::string>{"a/src/NAME.cpp", "b/include/list.h", "b/src/list.cpp"}));
    EXPECT_EQ(how_to_add_doc(doc, "How to add another").count, -1);
    // The scanner's identifiers: code only, not comments or literals.
    const Scanned s = scan_source("int quest = 1; // Staircase\nauto q = \"Adjustment\"; Quest::type(); x1y2 = 3e5;\n");
    EXPECT_EQ(s.identifiers, (std::set<std::string>{"int", "quest", "auto", "q", "Quest", "type", "x1y2"}));
}

TEST(Registries, HowToAddCountsAreTheFilesTheTreeMakesANewEntryTouch) {
    const std::string doc = read_text(fs::path(ATONLAB_SOURCE_DIR) / "docs/architecture.md");
    ASSERT_GT(scanned_sources().size(), 300u) << "the scan found too few sources under " << ATONLAB_SOURCE_DIR;
    for (const HowToAdd& h : how_to_adds()) {
        SCOPED_TRACE(h.section);
        const HowToAddDoc d = how_to_add_doc(doc, h.section);
        ASSERT_GT(d.count, 0) << "docs/architecture.md's \"" << h.section << "\" states no \"Files to touch, N\"";
        EXPECT_EQ(d.files.size(), static_cast<std::size_t>(d.count))
            << "docs/architecture.md's \"" << h.section << "\" says " << d.count << " files; its list names"
            << listed(d.files);
        ASSERT_FALSE(h.entries.empty());
        std::map<std::string, std::set<std::string>> files;
        std::size_t fewest = std::numeric_limits<std::size_t>::max();
        std::string table;
        for (const Entry& e : h.entries) {
            files[e.name] = files_spelling(e);
            fewest = std::min(fewest, files[e.name].size());
            table += fmt::format("\n  {}: {} files", e.name, files[e.name].size());
        }
        EXPECT_EQ(fewest, static_cast<std::size_t>(d.count))
            << "docs/architecture.md's \"" << h.section << "\" says " << d.count
            << " files; the entry spelled in the fewest files (the one a new entry is like) is in " << fewest << ":"
            << table;
        for (const Entry& e : h.entries) {
            if (files[e.name].size() != fewest) continue;
            std::set<std::string> expected;
            for (std::string f : d.files) {
                for (std::size_t at = f.find("NAME"); at != std::string::npos; at = f.find("NAME"))
                    f.replace(at, 4, e.file_name);
                expected.insert(f);
            }
            EXPECT_EQ(files[e.name], expected) << e.name << " is spelled in" << listed(files[e.name])
                                               << "\n  and docs/architecture.md's list is" << listed(expected);
        }
    }
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

constexpr const char* kScene = atonlab::stimuli::scene_file_test::kOneBuoyScene;

TEST(Registries, EveryGlareModelReadsBackFromASceneAndFromSet) {
    for (const GlareModelType* m : glare_models()) {
        const std::string name(m->name());
        const Scene file = parse_scene(
            std::string(kScene) + "glare = \"" + name + "\"\n[eye]\nglare = \"" + name + "\"\n", "registry.toml");
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
            const std::string row =
                fmt::format("| `{}` | {} | {} | {} | {} |", s.key, s.type, s.unit, s.default_text, s.doc);
            EXPECT_EQ(row_of(doc, s.key), row)
                << m->name() << ": docs/scene-file.md's row of " << s.key << " is not its declaration";
            try {
                // A key the reader does not know is refused as unknown; a known one may only be refused for its value.
                (void)parse_scene(
                    kScene, "registry.toml",
                    {atonlab::SceneOverride::parse(fmt::format("{}.{}=1", glare_table_name(s.table), s.key))});
            } catch (const atonlab::InputError& e) {
                EXPECT_EQ(std::string(e.what()).find("unknown key"), std::string::npos)
                    << m->name() << ": " << e.what();
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
    const std::string glsl = display::display_encodings_glsl();
    std::set<std::string_view> names, display_names, functions;
    int i = 0;
    for (const display::DisplayEncoding* e : display::display_encodings()) {
        EXPECT_EQ(display::display_encoding_index(*e), i++) << e->name;
        EXPECT_TRUE(names.insert(e->name).second) << e->name;
        EXPECT_TRUE(display_names.insert(e->display_name).second) << e->display_name;
        EXPECT_TRUE(functions.insert(e->glsl_drive_function).second) << e->glsl_drive_function;
        EXPECT_EQ(display::display_encoding_named(e->name), e);
        // Its GLSL defines the function it names, and the dispatch calls it for its kind.
        EXPECT_NE(e->glsl.find("double " + std::string(e->glsl_drive_function) + "(DisplayChannel c, double L)"),
                  std::string::npos)
            << e->name << ": its glsl defines no " << e->glsl_drive_function;
        EXPECT_NE(glsl.find(fmt::format("{}(c, L);  // {}", e->glsl_drive_function, e->name)), std::string::npos)
            << e->name;
        EXPECT_LE(e->parameters.size(), display::kEncodingParameters) << e->name;
    }
    EXPECT_EQ(display::display_encoding_named("PQ"), nullptr);
    EXPECT_THROW((void)display::display_encoding("hlg"), std::logic_error);
    EXPECT_THROW(display::register_display_encoding(display::display_encoding("pq")), std::logic_error);
}

TEST(Registries, EveryNamedDisplayReadsBackFromASceneAndItsFitJson) {
    for (const display::DisplayEncoding* e : display::display_encodings()) {
        if (e->from_peak_black == nullptr) continue;
        const std::string name(e->name);
        const Scene s =
            parse_scene(kScene, "registry.toml", {atonlab::SceneOverride::parse("display.encoding=\"" + name + "\"")});
        EXPECT_EQ(display::display_encoding_of(s.output.display), e) << name;
        EXPECT_EQ(s.output.display.name, e->display_name) << name;
        const display::DisplayModel d = *display::display_from_encoding(name, 200.0, 0.1);
        const display::DisplayModel back =
            display::display_model_from_fit_json(display::nominal_fit_json(d, display::EncodeSettings{}), d.name);
        for (std::size_t c = 0; c < 3; ++c) {
            const display::ChannelEncoding& ch = d.channels[c];
            EXPECT_EQ(ch.encoding, e);
            EXPECT_EQ(back.channels[c].encoding, e);
            EXPECT_EQ(back.channels[c].parameter, ch.parameter) << name;
            // The law and its inverse agree (the registry pairs them): L(V(L)) = L.
            const double L = 0.5 * (ch.min_cd_m2() + ch.max_cd_m2());
            EXPECT_NEAR(ch.luminance_cd_m2(ch.drive_for(L)), L, 1e-9 * ch.max_cd_m2()) << name;
        }
    }
}

}  // namespace
