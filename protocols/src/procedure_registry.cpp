// Looking the registered procedure kinds up (procedures.h).
#include <fmt/format.h>

#include <array>

#include "atonlab/protocols/procedures.h"

namespace atonlab::protocols {

namespace {

using TypeList = std::array<const ProcedureType*, std::size(kProcedureTypes)>;

const TypeList& types() {
    static const TypeList list = [] {
        TypeList out{};
        for (std::size_t i = 0; i < out.size(); ++i) out[i] = &kProcedureTypes[i]();
        return out;
    }();
    return list;
}

}  // namespace

std::span<const ProcedureType* const> procedure_types() {
    return types();
}

const ProcedureType& procedure_type(ProcedureKind kind) noexcept {
    return *types()[static_cast<std::size_t>(kind)];
}

const ProcedureType* find_procedure_type(std::string_view name) noexcept {
    for (const ProcedureType* t : types())
        if (t->name == name) return t;
    return nullptr;
}

std::string quoted_procedure_names(std::string_view separator, std::string_view last) {
    std::string out;
    const TypeList& list = types();
    for (std::size_t i = 0; i < list.size(); ++i) {
        if (i > 0) out += i + 1 == list.size() ? last : separator;
        out += fmt::format("\"{}\"", list[i]->name);
    }
    return out;
}

}  // namespace atonlab::protocols
