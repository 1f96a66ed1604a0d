#include "splatfx/budget.hpp"

#include <charconv>

namespace splatfx {
namespace {

struct Field {
    const char* name;
    std::uint64_t Budgets::*member;
};
constexpr Field kFields[] = {
    {"effectCells", &Budgets::effectCells},         {"solverCells", &Budgets::solverCells},
    {"sampledTexels", &Budgets::sampledTexels},     {"textureLayers", &Budgets::textureLayers},
    {"meshElements", &Budgets::meshElements},       {"meshFileBytes", &Budgets::meshFileBytes},
    {"meshImportBytes", &Budgets::meshImportBytes}, {"meshImportSeconds", &Budgets::meshImportSeconds},
    {"fogShaderBytes", &Budgets::fogShaderBytes},   {"heightmapVertices", &Budgets::heightmapVertices},
    {"lightingBytes", &Budgets::lightingBytes},     {"volumeBytes", &Budgets::volumeBytes},
};

} // namespace

std::vector<std::string> budgetNames() {
    std::vector<std::string> out;
    for (const Field& f : kFields) out.emplace_back(f.name);
    return out;
}

Status checkBudget(std::string_view what, std::uint64_t estimate, std::string_view unit, std::uint64_t budget, std::string_view field) {
    if (estimate <= budget) return {};
    return makeError(std::string(what) + " needs " + std::to_string(estimate) + " " + std::string(unit) + ", over the budget of " +
                     std::to_string(budget) + " (raise Budgets::" + std::string(field) + ")");
}

Status setBudget(Budgets& budgets, std::string_view assignment) {
    const std::size_t eq = assignment.find('=');
    const std::string_view name = assignment.substr(0, eq);
    std::string names;
    for (const Field& f : kFields) names += std::string(names.empty() ? "" : ", ") + f.name;
    if (eq == std::string_view::npos) return makeError("a budget is NAME=N, got '" + std::string(assignment) + "' (names: " + names + ")");
    const std::string_view number = assignment.substr(eq + 1);
    for (const Field& f : kFields) {
        if (name != f.name) continue;
        std::uint64_t v = 0;
        const auto [end, ec] = std::from_chars(number.data(), number.data() + number.size(), v);
        if (ec != std::errc() || end != number.data() + number.size() || number.empty() || v == 0)
            return makeError("budget " + std::string(name) + " expects a whole number >= 1, got '" + std::string(number) + "'");
        if (f.member == &Budgets::effectCells && v > kMaxVoxels)
            return makeError("budget effectCells is at most kMaxVoxels (" + std::to_string(kMaxVoxels) + "), got " + std::to_string(v));
        budgets.*f.member = v;
        return {};
    }
    return makeError("unknown budget '" + std::string(name) + "' (names: " + names + ")");
}

} // namespace splatfx
