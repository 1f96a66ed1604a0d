// Private: the registry of scene-file kinds, one row a kind.
//
// An effect kind ("kind" in effects[i]) and a geometry kind ("type" in
// geometry[i]) are each a name and a reader. The readers live one a file in
// kinds/; kinds.cpp holds the two tables, the only place that lists them.
// The order of a table is the order the messages list the names in.
// Adding a kind (docs/scene-format.md, "Adding a kind"): write kinds/<kind>.cpp
// with a reader of the signature below, add its name to the declaration
// line and one row to the table in kinds.cpp.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "scenefile/reader.hpp"

namespace splatfx::scenefile {

// Reads the keys only this kind has from `o` (the common keys are in `e`,
// already read; unknown keys are reported by the caller after it returns),
// reporting problems through c.d. Returns the effect, or nullopt after
// reporting. `pl` is where the effect rides (its anchor's or its own
// motion); kinds that cannot move report e.motion / e.attachTo themselves.
using EffectReaderFn = std::optional<Effect>(Context& c, ObjectReader& o, const EffectCommon& e, const Placement& pl);

// Reads the keys only this geometry type has into `desc` (the common keys
// are read by the caller after it returns).
using GeometryReaderFn = void(Context& c, ObjectReader& o, GeometryDesc& desc);

struct EffectKind {
    std::string_view name;
    EffectReaderFn* read = nullptr;
};

struct GeometryKind {
    std::string_view name;
    GeometryType type = GeometryType::Box;
    GeometryReaderFn* read = nullptr; // nullptr: the type takes only the common keys
};

std::span<const EffectKind> effectKinds();
std::span<const GeometryKind> geometryKinds();

// The row named `name`, or nullptr.
const EffectKind* findEffectKind(std::string_view name);
const GeometryKind* findGeometryKind(std::string_view name);

// The names, in table order (for readChoice and messages).
std::vector<std::string> effectKindNames();
std::vector<std::string> geometryKindNames();

} // namespace splatfx::scenefile
