// The protocol file (protocol_file.h; every key in docs/protocol-file.md).
// Three steps: parse the TOML text (syntax errors keep the parser's line), read
// every table of the schema strictly, then build each condition's procedures
// once so that the procedures' own parameter checks (ProcedureError) are
// reported at the line of the offending key.
#include "atonlab/protocols/protocol_file.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstdint>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <system_error>

#include "atonlab/common/input_limits.h"
#include "atonlab/common/input_text.h"
#include "atonlab/common/toml_text.h"
#include "protocol_reader.h"
#include "protocol_schema.h"

namespace atonlab::protocols {

namespace {

using detail::Document;
using detail::KeyList;
using detail::Section;
using namespace detail;  // NOLINT: the schema and the readers of protocol_schema.h

// ---------------------------------------------------------------------------
// The whole file.

class Parser {
public:
    explicit Parser(std::string file) : doc_(std::move(file)) {}

    Protocol parse(std::string_view text, bool check_scene_exists) {
        try {
            root_ = toml::parse(text, doc_.file());
        } catch (const toml::parse_error& e) {
            throw InputError(SourceLocation{doc_.file(), static_cast<int>(e.source().begin.line),
                                            static_cast<int>(e.source().begin.column), ""},
                             fmt::format("TOML syntax error: {}.", strip_period(std::string(e.description()))));
        }
        text_ = std::string(text);
        step([&] { expand_conditions_files(); });
        // Every table is read even after an error in another (and every
        // condition after an error in one): all the errors, in file order, in
        // one run (text::ErrorList; docs/protocol-file.md "Errors").
        doc_.collect_into(&errors_);
        Section root(doc_, root_, "", "the protocol file");
        step([&] { root.allow(kRootKeys, [](std::string_view k) { return belongs_elsewhere(k, ""); }); });

        Protocol p;
        p.file = doc_.file();
        step([&] { read_header(root, p, check_scene_exists); });
        step([&] { read_display(doc_, root, p); });
        step([&] { read_timing(doc_, root, p); });
        step([&] { read_screens(doc_, root, p); });
        step([&] { read_blocks(root, p); });
        step([&] { read_responses(doc_, root, p); });
        step([&] { read_observer(doc_, root, p); });
        doc_.collect_into(nullptr);
        errors_.throw_if_any();
        return p;
    }

private:

    /// Each [[block]] with conditions_file = "FILE.csv" gets one
    /// [[block.condition]] per row of the file (after those written in the
    /// block; rows with a `block` column only where it names this block). The
    /// rows are turned into TOML inline tables, one per line at the row's own
    /// line, so that every later check reports the CSV file's row and column
    /// (Document::add_csv_row).
    void expand_conditions_files() {
        toml::node* blocks = root_.get("block");
        if (blocks == nullptr || !blocks->is_array_of_tables()) return;
        toml::array& arr = *blocks->as_array();
        for (std::size_t bi = 0; bi < arr.size(); ++bi) {
            toml::table& bt = *arr.get(bi)->as_table();
            const toml::node* f = bt.get("conditions_file");
            if (f == nullptr) continue;
            step([&] { expand_conditions_file(doc_, text_, bt, bi, *f); });
        }
    }

    /// Runs one part of the reading; its error is kept and the reading goes on.
    template <class F>
    bool step(F&& f) {
        return errors_.attempt(f);
    }

    void read_header(const Section& root, Protocol& p, bool check_scene_exists) {
        const toml::table* t = root.table("protocol");
        if (t == nullptr)
            doc_.fail_at_line(0, "protocol",
                              "the protocol file has no [protocol] table, which is required (its scene and seed).");
        Section s(doc_, *t, "protocol", "the [protocol] table");
        s.allow(kProtocolKeys);
        p.name = s.string("name").value_or(std::filesystem::path(doc_.file()).stem().string());
        p.description = s.string("description").value_or("");
        const auto scene = s.string("scene");
        if (!scene) s.missing("scene", "the scene file the conditions override, relative to this file");
        if (scene->empty()) s.fail("scene", "scene must name a scene file, got an empty string.");
        const std::filesystem::path as_written(*scene);
        p.scene = as_written.is_absolute()
                      ? as_written
                      : (std::filesystem::path(doc_.file()).parent_path() / as_written).lexically_normal();
        if (check_scene_exists) {
            std::error_code ec;
            if (!std::filesystem::is_regular_file(p.scene, ec))
                s.fail("scene",
                       fmt::format("the scene file \"{}\" does not exist (looked for {}).", *scene, p.scene.string()));
        }
        const toml::node* seed = s.get("seed");
        if (seed == nullptr) s.missing("seed", "the random seed, an integer >= 0");
        const std::int64_t v = doc_.integer64(seed, "protocol.seed");
        if (v < 0) s.fail("seed", fmt::format("seed must be at least 0, got {}.", v));
        p.seed = static_cast<std::uint64_t>(v);
        adaptation_s_ = s.number("adaptation_s").value_or(0.0);
        s.at_least("adaptation_s", adaptation_s_, 0.0);
        s.duration_at_most("adaptation_s", adaptation_s_);
    }

    void read_blocks(const Section& root, Protocol& p) {
        const toml::table* defaults = root.table("defaults");
        if (defaults != nullptr) {
            Section d(doc_, *defaults, "defaults", "the [defaults] table");
            step([&] { d.allow(kConditionKeys, [](std::string_view k) { return belongs_elsewhere(k, "defaults"); }); });
        }
        const toml::node* blocks = root.get("block");
        if (blocks == nullptr)
            doc_.fail_at_line(0, "block",
                              "the protocol file has no [[block]], which is required (at least one block of "
                              "conditions).");
        if (!blocks->is_array_of_tables())
            doc_.fail(
                blocks, "block",
                fmt::format("expected an array of tables [[block]], got {}.", text::type_phrase(blocks->type())));
        std::vector<std::string_view> block_keys(std::begin(kBlockOwnKeys), std::end(kBlockOwnKeys));
        block_keys.insert(block_keys.end(), std::begin(kConditionKeys), std::end(kConditionKeys));

        std::map<std::string, int> block_lines;
        std::map<std::string, int> condition_lines;
        const toml::array& arr = *blocks->as_array();
        for (std::size_t bi = 0; bi < arr.size(); ++bi) {
            const toml::table& bt = *arr.get(bi)->as_table();
            const std::string bpath = fmt::format("block[{}]", bi);
            Section bs(doc_, bt, bpath, fmt::format("[[block]] {}", bi));
            step([&] { bs.allow(block_keys, [](std::string_view k) { return belongs_elsewhere(k, "block"); }); });
            Block b;
            b.line = bs.line();
            b.name = fmt::format("block{}", bi);
            step([&] { read_block_own(bs, b, block_lines); });
            const toml::array* carr_ptr = nullptr;
            step([&] { carr_ptr = block_conditions(bs, b); });
            if (carr_ptr == nullptr) {
                p.blocks.push_back(std::move(b));
                continue;
            }
            const toml::array& carr = *carr_ptr;
            for (std::size_t ci = 0; ci < carr.size(); ++ci) {
                step([&] {
                    const toml::table& ct = *carr.get(ci)->as_table();
                    const std::string cpath = fmt::format("{}.condition[{}]", bpath, ci);
                    Section cs(doc_, ct, cpath, fmt::format("[[block.condition]] {} of block \"{}\"", ci, b.name));
                    std::vector<std::string_view> ckeys(std::begin(kConditionKeys), std::end(kConditionKeys));
                    ckeys.push_back("name");
                    step(
                        [&] { cs.allow(ckeys, [](std::string_view k) { return belongs_elsewhere(k, "condition"); }); });
                    std::string name = cs.string("name").value_or(fmt::format("{}-c{}", b.name, ci));
                    if (name.empty()) cs.fail("name", "name must not be empty.");
                    if (auto [it, inserted] = condition_lines.emplace(name, cs.line()); !inserted)
                        cs.fail("name",
                                fmt::format("a condition called \"{}\" already exists (line {}); condition names are "
                                            "unique in the protocol.",
                                            name, it->second));
                    ConditionReader cr(doc_, {Layer{defaults, "defaults"}, Layer{&bt, bpath}, Layer{&ct, cpath}}, name,
                                       cs.line());
                    b.conditions.push_back(read_condition(cr, name, cs.line()));
                });
            }
            p.blocks.push_back(std::move(b));
        }
    }

    /// A block's own keys (not its conditions').
    void read_block_own(const Section& bs, Block& b, std::map<std::string, int>& block_lines) {
        {
            b.name = bs.string("name").value_or(b.name);
            if (b.name.empty()) bs.fail("name", "name must not be empty.");
            if (auto [it, inserted] = block_lines.emplace(b.name, b.line); !inserted)
                bs.fail("name", fmt::format("a block called \"{}\" already exists (line {}).", b.name, it->second));
            b.adaptation_s = bs.number("adaptation_s").value_or(adaptation_s_);
            bs.at_least("adaptation_s", b.adaptation_s, 0.0);
            bs.duration_at_most("adaptation_s", b.adaptation_s);
            b.repetitions = bs.integer("repetitions", 1, 1000).value_or(1);
            if (auto s = bs.string("interleave")) {
                try {
                    b.interleave = parse_interleave_order(*s);
                } catch (const ProcedureError& e) {
                    bs.fail("interleave", fmt::format("interleave {}.", e.message()));
                }
            }
            b.instructions = bs.string("instructions").value_or("");
        }
    }

    /// A block's [[block.condition]] array.
    const toml::array* block_conditions(const Section& bs, const Block& b) {
        {
            const toml::node* conds = bs.get("condition");
            // A conditions file that gave no rows has said so at its own key.
            if (conds == nullptr && bs.get("conditions_file") != nullptr) return nullptr;
            if (conds == nullptr)
                doc_.fail_at_line(b.line, bs.key_path("condition"),
                                  fmt::format("block \"{}\" (line {}) has no [[block.condition]], which is required "
                                              "(at least one condition).",
                                              b.name, b.line));
            if (!conds->is_array_of_tables())
                doc_.fail(conds, bs.key_path("condition"),
                          fmt::format("expected an array of tables [[block.condition]], got {}.",
                                      text::type_phrase(conds->type())));
            return conds->as_array();
        }
    }

    Condition read_condition(const ConditionReader& r, std::string name, int line) {
        Condition c;
        c.name = std::move(name);
        c.line = line;

        const auto task = r.choice<Task>("task", parse_task, kTaskNames);
        if (!task) r.missing("task", "\"2afc\", \"yes-no\" or \"adjust\"");
        c.task = *task;

        c.presentation = c.task == Task::YesNo ? Presentation::Single : Presentation::TwoInterval;
        if (auto v = r.choice<Presentation>("presentation", parse_presentation, kPresentationNames)) {
            c.presentation = *v;
            const bool single = *v == Presentation::Single;
            if (single != (c.task == Task::YesNo))
                r.fail(*r.find("presentation"),
                       c.task == Task::YesNo
                           ? fmt::format("a yes-no task shows one stimulus: presentation must be \"single\", got "
                                         "\"{}\".",
                                         to_string(*v))
                           : fmt::format("a {} task compares two stimuli: presentation must be \"two-interval\" or "
                                         "\"side-by-side\", got \"single\".",
                                         to_string(c.task)));
        }
        c.prompt = r.string("prompt").value_or("");

        // Every override with where it was written, for the conflict check below.
        std::vector<Written> written;
        auto take = [&](const Found& f, Scope scope, std::vector<SceneOverride>& into) {
            std::vector<SceneOverride> list = doc_.scene_overrides(f.node, f.key, r.context());
            for (std::size_t i = 0; i < list.size(); ++i)
                written.push_back(Written{list[i], scope, layer_of(f.key),
                                          f.node->is_string() ? f.key : fmt::format("{}[{}]", f.key, i)});
            append(into, std::move(list));
        };
        for (const Found& f : r.find_all("set")) take(f, Scope::every_frame, c.set);
        for (const Found& f : r.find_all("test_set")) take(f, Scope::test, c.test_set);
        for (const Found& f : r.find_all("reference_set")) {
            if (c.presentation == Presentation::Single)
                r.fail(f,
                       "a single presentation has no reference: reference_set is not used; put the overrides in "
                       "set or test_set.");
            take(f, Scope::reference, c.reference_set);
        }

        const auto level_key = r.find("level_key");
        if (!level_key)
            r.missing("level_key", "the scene key the procedure's level sets, e.g. \"light.reference.intensity_cd\"");
        c.level_key = doc_.scene_key(level_key->node, level_key->key, r.context());
        c.level_scale = r.choice<LevelScale>("level_scale", parse_level_scale, kScaleNames).value_or(LevelScale::Log10);

        c.level_on = c.task == Task::YesNo ? Role::Test : Role::Reference;
        if (auto v = r.choice<Role>("level_on", parse_role, kRoleNames)) {
            if (c.task == Task::YesNo && *v == Role::Reference)
                r.fail(*r.find("level_on"), "a yes-no task shows the test alone: level_on must be \"test\".");
            c.level_on = *v;
        }
        c.choice = c.level_on == Role::Reference ? ChoiceMapping::ChoseReference : ChoiceMapping::ChoseTest;
        if (auto f = r.find("choice")) {
            if (c.task != Task::TwoAfc)
                r.fail(*f, fmt::format("choice applies to the 2afc task only, not to \"{}\".", to_string(c.task)));
            const std::string text = doc_.string(f->node, f->key, r.context());
            try {
                c.choice = parse_choice_mapping(text);
            } catch (const ProcedureError& e) {
                r.fail(*f, fmt::format("choice {}.", strip_period(e.message())));
            }
        }

        c.test_light = r.string("test_light").value_or("");
        c.reference_light = r.string("reference_light").value_or("");
        c.reference_disc = r.string("reference_disc").value_or("");
        if (!c.reference_disc.empty() && !c.reference_light.empty())
            r.fail(*r.find("reference_disc"),
                   fmt::format("the reference is one thing: give reference_light (\"{}\") or reference_disc (\"{}\"), "
                               "not both.",
                               c.reference_light, c.reference_disc));
        if (!c.reference_disc.empty() && c.presentation == Presentation::Single)
            r.fail(*r.find("reference_disc"), "a single presentation has no reference: reference_disc is not used.");
        if (auto f = r.find("left_position_m"))
            c.left_position_m = doc_.vec3(f->node, f->key, "left_position_m", r.context());
        if (auto f = r.find("right_position_m"))
            c.right_position_m = doc_.vec3(f->node, f->key, "right_position_m", r.context());
        if (c.presentation == Presentation::SideBySide) {
            const std::string_view what = "side-by-side needs both lights and both positions";
            if (c.test_light.empty()) r.missing("test_light", what);
            if (c.reference_light.empty() && c.reference_disc.empty())
                r.missing("reference_light", "side-by-side needs both lights (or a reference_disc) and both positions");
            if (c.test_light == c.reference_light)
                r.fail(*r.find("reference_light"),
                       fmt::format("side-by-side needs two different lights, got \"{}\" twice.", c.test_light));
            if (!c.left_position_m) r.missing("left_position_m", what);
            if (!c.right_position_m) r.missing("right_position_m", what);
        } else {
            for (std::string_view k : {"left_position_m", "right_position_m"})
                if (auto f = r.find(k))
                    r.fail(*f, fmt::format("{} is used by presentation = \"side-by-side\" only, not \"{}\".", k,
                                           to_string(c.presentation)));
        }

        check_conflicts(r, c, written, level_key->key);

        // The procedure.
        const std::vector<Found> tables = r.find_all("procedure");
        if (tables.empty())
            r.missing("procedure",
                      fmt::format("a table with kind = {} and its parameters", quoted_procedure_names(", ", " or ")));
        ProcedureReader pr(doc_, r);
        pr.merge(tables);
        if (!pr.kind())
            doc_.fail(pr.table()->node, pr.table()->key + ".kind",
                      r.context() + fmt::format("the procedure has no kind: give kind = one of {}.",
                                                toml_reader::join_quoted(procedure_kind_names())));
        const ProcedureType& type = procedure_type(*pr.kind());
        if (type.adjusts != (c.task == Task::Adjust))
            r.fail(*pr.kind_at(),
                   type.adjusts ? fmt::format("the {} procedure needs task = \"{}\", not \"{}\".", type.name,
                                              to_string(Task::Adjust), to_string(c.task))
                                : fmt::format("task = \"{}\" needs kind = {}, not \"{}\".", to_string(Task::Adjust),
                                              adjusting_kinds(), type.name));
        if (!type.needs_log10.empty() && c.level_scale != LevelScale::Log10) {
            const auto f = r.find("level_scale");
            r.fail(*f, fmt::format("{}: level_scale must be \"{}\".", type.needs_log10, to_string(LevelScale::Log10)));
        }
        try {
            c.procedure = read_procedure(pr);
            for (std::size_t t = 0; t < c.procedure.tracks(); ++t) (void)make_track(c, t, 0);
        } catch (const ProcedureError& e) {
            pr.fail(e.parameter(), fmt::format("{} {}.", e.parameter(), strip_period(e.message())));
        }
        check_level_scale(pr, c);
        return c;
    }

    // --- Conflicting overrides (docs/protocol-file.md "When two overrides set one key").

    /// Which frames an override applies to.
    enum class Scope : std::uint8_t { every_frame, test, reference };
    /// Where it was written, general to specific.
    enum class Origin : std::uint8_t { defaults, block, condition };
    struct Written {
        SceneOverride o;
        Scope scope = Scope::every_frame;
        Origin layer = Origin::defaults;
        std::string path;  ///< "block[0].test_set[1]"
    };

    static Origin layer_of(const std::string& found_key) {
        if (found_key.starts_with("defaults.")) return Origin::defaults;
        return found_key.find(".condition[") != std::string::npos ? Origin::condition : Origin::block;
    }

    static std::string_view scope_name(Scope s) {
        switch (s) {
            case Scope::every_frame:
                return "set";
            case Scope::test:
                return "test_set";
            case Scope::reference:
                return "reference_set";
        }
        return "set";
    }

    /// Two TOML value texts that mean the same value: equal numbers, or equal
    /// text once the quotes of a string are set aside.
    static bool same_value(std::string_view a, std::string_view b) {
        auto trim = [](std::string_view v) {
            while (!v.empty() && (v.front() == ' ' || v.front() == '\t')) v.remove_prefix(1);
            while (!v.empty() && (v.back() == ' ' || v.back() == '\t')) v.remove_suffix(1);
            if (v.size() >= 2 && (v.front() == '"' || v.front() == '\'') && v.back() == v.front())
                v = v.substr(1, v.size() - 2);
            return v;
        };
        a = trim(a);
        b = trim(b);
        if (a == b) return true;
        auto number = [](std::string_view v) -> std::optional<double> {
            double x = 0.0;
            const auto [ptr, ec] = std::from_chars(v.data(), v.data() + v.size(), x);
            if (ec != std::errc() || ptr != v.data() + v.size()) return std::nullopt;
            return x;
        };
        const auto x = number(a), y = number(b);
        return x && y && *x == *y;
    }

    /// One frame must not take one key from two places that both mean it
    /// (docs/protocol-file.md). By design, a later layer replaces an earlier:
    /// a [[block]] or condition value replaces the [defaults] value of the
    /// same key; in a frame of one role (single, two-interval) the role's
    /// test_set or reference_set replaces `set`. Refused: a block and its
    /// condition, or one list twice, giving one key two values; in a
    /// side-by-side frame (which holds both lights) set, test_set and
    /// reference_set giving one key two values; any override of the key the
    /// procedure's level sets, in the frame the level is on; any override of
    /// a side-by-side light's position_m. In a side-by-side frame a [defaults]
    /// value that a block or condition replaces is dropped, so that the
    /// replacement holds whatever list it is in.
    void check_conflicts(const ConditionReader& r, Condition& c, const std::vector<Written>& written,
                         const std::string& level_key_path) const {
        const bool side_by_side = c.presentation == Presentation::SideBySide;
        auto conflict = [&](const Written& a, const Written& b, const std::string& why) {
            doc_.fail_at_line(b.o.origin.line, b.path,
                              r.context() + fmt::format("{} is set to {} here and to {} by {} (line {}): {} Remove one "
                                                        "of them (docs/protocol-file.md \"When two overrides set one "
                                                        "key\").",
                                                        b.o.key, b.o.value, a.o.value, a.path, a.o.origin.line, why));
        };
        // Frames of the condition, by the scopes that apply to each.
        std::vector<std::vector<Scope>> frames;
        if (side_by_side)
            frames = {{Scope::every_frame, Scope::test, Scope::reference}};
        else if (c.presentation == Presentation::Single)
            frames = {{Scope::every_frame, Scope::test}};
        else
            frames = {{Scope::every_frame, Scope::test}, {Scope::every_frame, Scope::reference}};
        std::set<std::string> dropped;  // paths of [defaults] values a side-by-side frame drops
        for (const auto& scopes : frames) {
            auto applies = [&](const Written& w) {
                return std::find(scopes.begin(), scopes.end(), w.scope) != scopes.end();
            };
            const bool has_level =
                side_by_side || std::find(scopes.begin(), scopes.end(),
                                          c.level_on == Role::Test ? Scope::test : Scope::reference) != scopes.end();
            for (std::size_t j = 0; j < written.size(); ++j) {
                const Written& b = written[j];
                if (!applies(b)) continue;
                if (has_level && b.o.key == c.level_key)
                    doc_.fail_at_line(
                        b.o.origin.line, b.path,
                        r.context() +
                            fmt::format("{} is set to {} here, but it is the level_key ({}): the procedure's level "
                                        "sets it on every trial in the {} frame. Remove this override (docs/protocol-"
                                        "file.md \"When two overrides set one key\").",
                                        b.o.key, b.o.value, level_key_path, side_by_side ? "side-by-side" : to_string(c.level_on)));
                if (side_by_side && (b.o.key == fmt::format("light.{}.position_m", c.test_light) ||
                                     b.o.key == fmt::format("light.{}.position_m", c.reference_light)))
                    doc_.fail_at_line(
                        b.o.origin.line, b.path,
                        r.context() + fmt::format("{} is set to {} here, but a side-by-side frame places its lights "
                                                  "at left_position_m and right_position_m. Remove this override.",
                                                  b.o.key, b.o.value));
                for (std::size_t i = 0; i < j; ++i) {
                    const Written& a = written[i];
                    if (!applies(a) || a.o.key != b.o.key || same_value(a.o.value, b.o.value)) continue;
                    const bool a_default = a.layer == Origin::defaults, b_default = b.layer == Origin::defaults;
                    if (a_default != b_default) {
                        // A block's or condition's value replaces the default.
                        if (side_by_side) dropped.insert(a_default ? a.path : b.path);
                        if (side_by_side || a.scope == b.scope) continue;
                    }
                    if (!side_by_side && a.scope != b.scope) continue;  // the role's list replaces `set`
                    std::string why;
                    if (side_by_side && a.scope != b.scope)
                        why = fmt::format("a side-by-side frame holds both lights, and {} and {} both apply to "
                                          "all of it.",
                                          scope_name(a.scope), scope_name(b.scope));
                    else if (a.layer != b.layer)
                        why = "a condition and its block apply to the same frames.";
                    else
                        why = "one list sets it twice.";
                    conflict(a, b, why);
                }
            }
        }
        if (dropped.empty()) return;
        // Rebuild the lists without the replaced defaults (order kept).
        c.set.clear();
        c.test_set.clear();
        c.reference_set.clear();
        for (const Written& w : written) {
            if (dropped.contains(w.path)) continue;
            (w.scope == Scope::every_frame ? c.set : w.scope == Scope::test ? c.test_set : c.reference_set)
                .push_back(w.o);
        }
    }

    /// Levels that look written for the other scale: on log10 a level above
    /// kMaxLog10Level is 10^9 or more of the key's unit (no light, luminance or
    /// distance in a study is that large: these are linear values); on a linear
    /// scale a negative level of a photometric key (cd, cd/m², lux) cannot be
    /// (these are log10 values).
    void check_level_scale(const ProcedureReader& pr, const Condition& c) const {
        static constexpr double kMaxLog10Level = 9.0;
        const auto ends_with = [&](std::string_view suffix) {
            return c.level_key.size() >= suffix.size() &&
                   c.level_key.compare(c.level_key.size() - suffix.size(), suffix.size(), suffix) == 0;
        };
        const bool photometric = ends_with("_cd") || ends_with("_cd_m2") || ends_with("_lux");
        for (std::string_view key :
             {"start", "levels", "min_level", "max_level", "t_guess", "start_min", "start_max"}) {
            const Found* f = pr.entry(key);
            if (f == nullptr) continue;
            std::vector<double> v;
            if (f->node->is_number())
                v.push_back(f->node->value<double>().value_or(0.0));
            else if (const toml::array* a = f->node->as_array())
                for (const toml::node& x : *a) v.push_back(x.value<double>().value_or(0.0));
            for (const double x : v) {
                if (c.level_scale == LevelScale::Log10 && x > kMaxLog10Level)
                    pr.fail(key, fmt::format("{} has {} on the log10 scale: 10^{} of {}'s unit. These look like linear "
                                             "values: give their log10 (e.g. {} for {}) or set level_scale = "
                                             "\"linear\".",
                                             key, x, x, c.level_key, fmt::format("{:.3g}", std::log10(x)), x));
                if (c.level_scale == LevelScale::Linear && photometric && x < 0.0)
                    pr.fail(key, fmt::format("{} has {} on the linear scale, a negative {}. These look like log10 "
                                             "values: set level_scale = \"log10\" or give the values themselves "
                                             "(e.g. {:.3g} for {}).",
                                             key, x, c.level_key, std::pow(10.0, x), x));
            }
        }
    }

    static void append(std::vector<SceneOverride>& to, std::vector<SceneOverride> from) {
        to.insert(to.end(), std::make_move_iterator(from.begin()), std::make_move_iterator(from.end()));
    }

    static constexpr std::string_view kTaskNames[] = {"2afc", "yes-no", "adjust"};
    static constexpr std::string_view kPresentationNames[] = {"single", "two-interval", "side-by-side"};
    static constexpr std::string_view kScaleNames[] = {"log10", "linear"};
    static constexpr std::string_view kRoleNames[] = {"test", "reference"};

    Document doc_;
    toml::table root_;
    double adaptation_s_ = 0.0;
    text::ErrorList errors_;  // every error found, reported together at the end of parse()
    std::string text_;        // the protocol text (conditions files stored in it: embedded_csv)
};

std::string read_text(const std::filesystem::path& file) {
    // Only up to a limit: /dev/zero given by mistake is refused, not read until
    // the memory runs out.
    text::FileText read = text::read_text_file(file);
    if (!read.ok())
        throw InputError(SourceLocation{file.string(), 0, 0, ""},
                         fmt::format("cannot read the protocol file: {}.", read.error));
    return std::move(read.text);
}

}  // namespace

Protocol load_protocol(const std::filesystem::path& file) {
    const std::string text = read_text(file);
    return Parser(file.string()).parse(text, true);
}

Protocol parse_protocol(std::string_view toml_text, std::string_view file_name) {
    return Parser(std::string(file_name)).parse(toml_text, false);
}

std::string with_conditions_files(std::string_view text, const std::filesystem::path& protocol_file) {
    std::string out(text);
    toml::table root;
    try {
        root = toml::parse(text);
    } catch (const toml::parse_error&) {
        return out;
    }
    const toml::array* blocks = root["block"].as_array();
    if (blocks == nullptr) return out;
    std::set<std::string> done;
    for (const toml::node& b : *blocks) {
        const toml::table* t = b.as_table();
        if (t == nullptr) continue;
        const auto name = (*t)["conditions_file"].value<std::string>();
        if (!name || !done.insert(*name).second) continue;
        const std::filesystem::path csv = std::filesystem::path(*name).is_absolute()
                                              ? std::filesystem::path(*name)
                                              : protocol_file.parent_path() / *name;
        const text::FileText read = text::read_text_file(csv);
        if (!read.ok()) continue;
        if (!out.empty() && out.back() != '\n') out += '\n';
        out += "\n# atonlab: the conditions file below, as it was when the session ran (docs/protocol-file.md)\n";
        out += "#@conditions_file " + *name + "\n";
        for (std::size_t at = 0; at < read.text.size();) {
            const std::size_t end = std::min(read.text.find('\n', at), read.text.size());
            std::string line = read.text.substr(at, end - at);
            if (!line.empty() && line.back() == '\r') line.pop_back();
            out += "#@|" + line + "\n";
            at = end + 1;
        }
    }
    return out;
}

}  // namespace atonlab::protocols
