// --set overrides applied to the parsed scene tree before it is read (scene_reader.h; docs/scene-file.md "Overrides with --set").
#include "scene_reader.h"

namespace atonlab::stimuli::scene_reader {

// ---------------------------------------------------------------------------
// The template's tree, changed and restored.

namespace {
/// into[key] = node, moving it (so that it keeps its source).
void move_into(toml::table& into, const toml::key& key, toml::node& node) {
    node.visit([&](auto& concrete) { into.insert_or_assign(key, std::move(concrete)); });
}
}  // namespace

void TreeEdits::save(toml::table& table, std::string_view key) {
    Edit e;
    e.table = &table;
    e.key = toml::key(key);
    if (auto it = table.find(key); it != table.end()) {
        e.key = it->first;  // a copy keeps the key's source
        move_into(e.saved, toml::key("v"), it->second);
    }
    edits_.push_back(std::move(e));
}

void TreeEdits::assign(toml::table& table, std::string_view key, toml::node& value) {
    save(table, key);
    move_into(table, toml::key(key), value);
}

void TreeEdits::erase(toml::table& table, std::string_view key) {
    if (!table.contains(key)) return;
    save(table, key);
    table.erase(key);
}

toml::table& TreeEdits::insert_table(toml::table& parent, std::string_view key) {
    Edit e;
    e.table = &parent;
    e.key = toml::key(key);
    edits_.push_back(std::move(e));
    return *parent.insert(key, toml::table{}).first->second.as_table();
}

void TreeEdits::undo() noexcept {
    // Newest first: a table made for an override goes after the values set in it.
    for (auto e = edits_.rbegin(); e != edits_.rend(); ++e) {
        if (toml::node* old = e->saved.get("v"))
            move_into(*e->table, e->key, *old);
        else
            e->table->erase(e->key.str());
    }
    edits_.clear();
}

// ---------------------------------------------------------------------------
// Overrides.

/// An error about override `o`, at its origin: the protocol line that wrote
/// it, or "--set KEY".
[[noreturn]] void override_error(const SceneOverride& o, const std::string& message) {
    SourceLocation where = o.origin;
    if (where.file.empty() && where.option.empty()) where = SourceLocation::command_line(std::string(kSetOption));
    where.key = o.key;
    throw InputError(std::move(where), message);
}

/// A copy of override `o`'s typed value, in `holder` under "v". A value that
/// was not valid TOML was taken as a string when the override was made (so
/// `colour=red` needs no quotes); `note` then says so, for the type error that
/// usually follows a typo.
toml::node& override_value(const SceneOverride& o, toml::table& holder, std::string& note) {
    if (!o.not_toml().empty())
        note = fmt::format(" (the value \"{}\" is not valid TOML: {}; it was read as a string)", text::echo(o.value),
                           o.not_toml());
    const TomlValue* typed = o.typed();
    if (typed == nullptr)
        override_error(o, fmt::format("the value \"{}\" cannot be read: {}.", text::echo(o.value), o.unreadable()));
    typed->node().visit([&](const auto& concrete) { holder.insert_or_assign("v", concrete); });
    return *holder.get("v");
}

/// Every node of `n` (an overridden value in the tree) is noted as written by
/// the override `typed`: a copied node has no source of its own (toml++ does
/// not copy it), and errors about it or an element of it name the override.
void note_override_nodes(Document& doc, const toml::node& n, const std::string& typed) {
    doc.note_made_for_override(&n, typed);
    if (const toml::table* t = n.as_table())
        for (const auto& [k, v] : *t) note_override_nodes(doc, v, typed);
    else if (const toml::array* a = n.as_array())
        for (const toml::node& e : *a) note_override_nodes(doc, e, typed);
}

bool is_number(const toml::node& n) {
    return n.is_integer() || n.is_floating_point();
}

/// The table that holds the overridden key, created if absent (and remembered
/// so that errors about it name the override).
toml::table& table_for_override(Document& doc, TreeEdits& edits, toml::table& parent, std::string_view name,
                                const SceneOverride& o, const std::string& shown) {
    const std::string& typed = o.key;
    toml::node* n = parent.get(name);
    if (n == nullptr) {
        toml::table& made = edits.insert_table(parent, name);
        doc.note_made_for_override(&made, typed);
        return made;
    }
    if (!n->is_table()) {
        const SourceLocation w = doc.where(n, shown);
        override_error(o, fmt::format("cannot set {}: {} is {} in {}:{}, not a table.", typed, shown,
                                          type_phrase(n->type()), w.file, w.line));
    }
    return *n->as_table();
}

/// The [[light]] or [[disc]] table (`array`: "light", "disc") an override
/// addresses: "ARRAY[INDEX].key" or "ARRAY.NAME.key" (NAME may contain dots; the
/// key after the last dot never does).
std::pair<toml::table*, std::string> element_for_override(const Document& doc, toml::table& root,
                                                          const SceneOverride& o, std::string& key,
                                                          const std::string& array) {
    const std::string written = fmt::format("a {0} key is written {0}.NAME.KEY or {0}[INDEX].KEY.", array);
    toml::node* node = root.get(array);
    if (node == nullptr || !node->is_array() || node->as_array()->empty())
        override_error(o, fmt::format("the scene has no [[{}]] tables to override.", array));
    toml::array& elements = *node->as_array();
    // The addressing is common/'s (element_address), which the analysis reads trials' lights with too.
    const std::optional<ElementAddress> address = element_address(o.key, array);
    if (!address) override_error(o, written);
    key = address->key;

    std::size_t index = 0;
    if (address->index) {
        index = *address->index;
        if (index >= elements.size())
            override_error(o, fmt::format("there is no {0}[{1}]: the scene has {2} {0}{3} ({0}[0] to {0}[{4}]).",
                                              array, index, elements.size(), elements.size() == 1 ? "" : "s",
                                              elements.size() - 1));
    } else {
        const std::string& name = address->name;
        std::vector<std::string> known;
        bool found = false;
        for (std::size_t i = 0; i < elements.size(); ++i) {
            std::string element_name = fmt::format("{}{}", array, i);
            if (const toml::table* t = elements.get(i)->as_table())
                if (const toml::node* n = t->get("name"); n != nullptr && n->is_string())
                    element_name = n->as_string()->get();
            if (element_name == name && !found) {
                index = i;
                found = true;
            }
            known.push_back(element_name);
        }
        if (!found)
            override_error(o, fmt::format("no {} is named \"{}\"; the {}s are {}.", array, text::echo(name), array,
                                              join(known, "\"")));
    }
    toml::node* element = elements.get(index);
    if (!element->is_table()) {
        const SourceLocation w = doc.where(element, fmt::format("{}[{}]", array, index));
        override_error(o, fmt::format("{}[{}] in {}:{} is not a table.", array, index, w.file, w.line));
    }
    return {element->as_table(), fmt::format("{}[{}]", array, index)};
}

void apply_override(Document& doc, toml::table& root, const SceneOverride& o, TreeEdits& edits) {
    const std::string& k = o.key;
    toml::table* target = nullptr;
    std::string key;         // the key inside *target
    std::string schema_key;  // canonical dotted path, e.g. "light[0].intensity_cd"

    const auto unknown = [&](std::string_view section, KeyList allowed, std::string_view leaf) {
        override_error(o, fmt::format("unknown key '{}' in [{}].{} Allowed keys: {}.", text::echo(leaf),
                                      text::echo(section),
                                      did_you_mean(leaf, allowed), join(allowed)));
    };

    if (k == "light" || k.starts_with("light.") || k.starts_with("light[")) {
        auto [table, path] = element_for_override(doc, root, o, key, "light");
        if (!contains(kLightKeys, key)) unknown("[light]", kLightKeys, key);
        target = table;
        schema_key = path + "." + key;
    } else if (k == "disc" || k.starts_with("disc.") || k.starts_with("disc[")) {
        auto [table, path] = element_for_override(doc, root, o, key, "disc");
        if (!contains(kDiscKeys, key)) unknown("[disc]", kDiscKeys, key);
        target = table;
        schema_key = path + "." + key;
    } else if (k.starts_with("profiles.")) {
        // profiles.KIND.NAME.KEY (NAME may contain dots)
        const std::string rest = k.substr(9);
        const auto kind_end = rest.find('.');
        const auto last_dot = rest.rfind('.');
        if (kind_end == std::string::npos || last_dot == kind_end)
            override_error(o, "a profile key is written profiles.vertical.NAME.KEY or profiles.horizontal.NAME.KEY.");
        const std::string kind = rest.substr(0, kind_end);
        const std::string name = rest.substr(kind_end + 1, last_dot - kind_end - 1);
        key = rest.substr(last_dot + 1);
        if (!contains(kProfileKinds, kind))
            override_error(o, fmt::format("unknown profile kind '{}'; it must be 'vertical' or 'horizontal'.", kind));
        const KeyList allowed = kind == "vertical" ? KeyList(kVerticalKeys) : KeyList(kHorizontalKeys);
        if (!contains(allowed, key)) unknown(fmt::format("profiles.{}.{}", kind, name), allowed, key);
        toml::table& profiles = table_for_override(doc, edits, root, "profiles", o, "profiles");
        toml::table& kinds = table_for_override(doc, edits, profiles, kind, o, "profiles." + kind);
        target = &table_for_override(doc, edits, kinds, name, o, fmt::format("profiles.{}.{}", kind, name));
        schema_key = fmt::format("profiles.{}.{}.{}", kind, name, key);
    } else {
        const auto dot = k.find('.');
        const std::string section = k.substr(0, dot);
        if (!contains(kSections, section))
            override_error(o, fmt::format("unknown key '{}'; a scene has the tables {}.", text::echo(k),
                                          join(kSections)));
        if (dot == std::string::npos || dot + 1 == k.size())
            override_error(o, fmt::format("an override takes a key inside [{}], e.g. {}.{}.", section, section,
                                          section == "display" ? "width_px" : "yaw_deg"));
        key = k.substr(dot + 1);
        const KeyList allowed = section == "display"       ? KeyList(kDisplayKeys)
                                : section == "camera"      ? KeyList(kCameraKeys)
                                : section == "environment" ? KeyList(kEnvironmentKeys)
                                : section == "glare"       ? glare_keys()
                                : section == "tonemap"     ? KeyList(kTonemapKeys)
                                                           : eye_keys();
        if (!contains(allowed, key)) unknown(section, allowed, key);
        target = &table_for_override(doc, edits, root, section, o, section);
        schema_key = k;
    }

    std::string note;
    toml::table holder;
    toml::node* value = &override_value(o, holder, note);

    // The new value must have the type of the one it replaces (integers and
    // floats are interchangeable); values the file leaves at their default are
    // type-checked by the schema afterwards.
    if (const toml::node* old = target->get(key)) {
        const bool same = old->type() == value->type() || (is_number(*old) && is_number(*value));
        if (!same) {
            const SourceLocation w = doc.where(old, schema_key);
            const std::string from =
                w.from_command_line() ? std::string("an earlier --set") : fmt::format("{}:{}", w.file, w.line);
            override_error(o, fmt::format("expected {} like the value it replaces ({}), got {}{}.",
                                          is_number(*old) ? std::string_view("a number") : type_phrase(old->type()),
                                          from, type_phrase(value->type()), note));
        }
    }
    for (const auto& group : exclusive_groups()) {
        if (std::find(group.begin(), group.end(), key) == group.end()) continue;
        for (std::string_view other : group)
            if (other != key) edits.erase(*target, other);
    }
    doc.note_override(k, schema_key, o.origin);
    doc.note_string_fallback(k, note);
    edits.assign(*target, key, *value);
    note_override_nodes(doc, *target->get(key), k);
}

}  // namespace atonlab::stimuli::scene_reader
