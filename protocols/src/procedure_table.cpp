// A condition's procedure table, merged over [defaults], its block and the
// condition itself, and read into a ProcedureSpec (protocol_schema.h) by the
// kind it names (procedures.h).
#include <fmt/format.h>

#include <set>

#include "protocol_schema.h"

namespace atonlab::protocols::detail {

KeyList keys_of(ProcedureKind k) {
    return procedure_type(k).keys;
}

const std::vector<std::string_view>& all_procedure_keys() {
    static const std::vector<std::string_view> all = [] {
        std::set<std::string_view> s;
        for (const ProcedureType* t : procedure_types()) s.insert(t->keys.begin(), t->keys.end());
        return std::vector<std::string_view>(s.begin(), s.end());
    }();
    return all;
}

const std::vector<std::string_view>& procedure_kind_names() {
    static const std::vector<std::string_view> names = [] {
        std::vector<std::string_view> out;
        for (const ProcedureType* t : procedure_types()) out.push_back(t->name);
        return out;
    }();
    return names;
}

std::string adjusting_kinds() {
    std::string out;
    for (const ProcedureType* t : procedure_types())
        if (t->adjusts) out += fmt::format("{}\"{}\"", out.empty() ? "" : " or ", t->name);
    return out;
}

ProcedureSpec read_procedure(const ProcedureReader& r) {
    ProcedureSpec spec;
    spec.kind = *r.kind();
    spec.params = spec.type().read(r, spec.track_starts);
    return spec;
}

}  // namespace atonlab::protocols::detail
