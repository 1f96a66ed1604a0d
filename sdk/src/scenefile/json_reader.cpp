// Private: JSON value readers with paths in every message (see json_reader.hpp).
#include "scenefile/json_reader.hpp"

#include <algorithm>
#include <cstdio>

namespace splatfx::scenefile {

std::string brief(const Json& v) {
    std::string s = v.dump(-1, ' ', false, Json::error_handler_t::replace);
    if (s.size() > 40) s = s.substr(0, 37) + "...";
    return s;
}

std::string typeName(const Json& v) {
    switch (v.type()) {
    case Json::value_t::null: return "null";
    case Json::value_t::object: return "an object";
    case Json::value_t::array: return "an array";
    case Json::value_t::string: return "a string";
    case Json::value_t::boolean: return "a boolean";
    case Json::value_t::number_integer:
    case Json::value_t::number_unsigned:
    case Json::value_t::number_float: return "a number";
    default: return "an unsupported value";
    }
}

std::string join(const std::string& path, const std::string& key) { return path.empty() ? key : path + "." + key; }
std::string index(const std::string& path, std::size_t i) { return path + "[" + std::to_string(i) + "]"; }

namespace {

std::size_t editDistance(const std::string& a, const std::string& b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        std::size_t diag = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t up = row[j];
            const bool same = std::tolower(static_cast<unsigned char>(a[i - 1])) == std::tolower(static_cast<unsigned char>(b[j - 1]));
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (same ? 0 : 1)});
            diag = up;
        }
    }
    return row[b.size()];
}

std::string range(double lo, double hi) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "[%g, %g]", lo, hi);
    return buf;
}

} // namespace

std::string closest(const std::string& key, const std::vector<std::string>& candidates) {
    std::string best;
    std::size_t bestD = std::max<std::size_t>(2, key.size() / 3) + 1;
    for (const std::string& c : candidates) {
        const std::size_t dist = editDistance(key, c);
        if (dist < bestD) bestD = dist, best = c;
    }
    return best;
}

std::optional<double> readNumber(Diagnostics& d, const std::string& path, const Json& v, double lo, double hi) {
    if (!v.is_number()) {
        d.error(path, "expected a number in " + range(lo, hi) + ", got " + typeName(v) + " " + brief(v));
        return std::nullopt;
    }
    const double x = v.get<double>();
    if (!std::isfinite(x)) {
        d.error(path, "expected a finite number, got " + brief(v));
        return std::nullopt;
    }
    if (x < lo || x > hi) {
        d.error(path, "expected a number in " + range(lo, hi) + ", got " + num(x));
        return std::nullopt;
    }
    return x;
}

std::optional<std::int64_t> readInt(Diagnostics& d, const std::string& path, const Json& v, std::int64_t lo, std::int64_t hi) {
    const std::string want = "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    if (!v.is_number()) {
        d.error(path, want + ", got " + typeName(v) + " " + brief(v));
        return std::nullopt;
    }
    std::int64_t x = 0;
    if (v.is_number_unsigned()) {
        const std::uint64_t u = v.get<std::uint64_t>();
        if (u > std::uint64_t(hi)) {
            d.error(path, want + ", got " + brief(v));
            return std::nullopt;
        }
        x = std::int64_t(u);
    } else if (v.is_number_integer()) {
        x = v.get<std::int64_t>();
    } else {
        const double f = v.get<double>();
        if (!std::isfinite(f) || f != std::floor(f) || std::fabs(f) > 9.0e15) {
            d.error(path, want + ", got " + brief(v));
            return std::nullopt;
        }
        x = std::int64_t(f);
    }
    if (x < lo || x > hi) {
        d.error(path, want + ", got " + std::to_string(x));
        return std::nullopt;
    }
    return x;
}

std::optional<bool> readBool(Diagnostics& d, const std::string& path, const Json& v) {
    if (!v.is_boolean()) {
        d.error(path, "expected true or false, got " + typeName(v) + " " + brief(v));
        return std::nullopt;
    }
    return v.get<bool>();
}

std::optional<std::string> readString(Diagnostics& d, const std::string& path, const Json& v) {
    if (!v.is_string()) {
        d.error(path, "expected a string, got " + typeName(v) + " " + brief(v));
        return std::nullopt;
    }
    std::string s = v.get<std::string>();
    if (s.size() > 4096) {
        d.error(path, "expected a string of at most 4096 characters, got " + std::to_string(s.size()));
        return std::nullopt;
    }
    return s;
}

std::optional<glm::vec3> readVec3(Diagnostics& d, const std::string& path, const Json& v, double lo, double hi, bool allowScalar) {
    if (allowScalar && v.is_number()) {
        const auto s = readNumber(d, path, v, lo, hi);
        if (!s) return std::nullopt;
        return glm::vec3(float(*s));
    }
    if (!v.is_array() || v.size() != 3) {
        d.error(path, std::string("expected ") + (allowScalar ? "a number or " : "") + "an array of 3 numbers in " + range(lo, hi) + ", got " +
                          typeName(v) + " " + brief(v));
        return std::nullopt;
    }
    glm::vec3 out;
    for (int i = 0; i < 3; ++i) {
        const auto x = readNumber(d, index(path, i), v[i], lo, hi);
        if (!x) return std::nullopt;
        out[i] = float(*x);
    }
    return out;
}

std::optional<glm::ivec3> readIvec3(Diagnostics& d, const std::string& path, const Json& v, int lo, int hi) {
    if (!v.is_array() || v.size() != 3) {
        d.error(path,
                "expected an array of 3 integers in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + typeName(v) + " " + brief(v));
        return std::nullopt;
    }
    glm::ivec3 out;
    for (int i = 0; i < 3; ++i) {
        const auto x = readInt(d, index(path, i), v[i], lo, hi);
        if (!x) return std::nullopt;
        out[i] = int(*x);
    }
    return out;
}

std::optional<glm::vec4> readColor(Diagnostics& d, const std::string& path, const Json& v, bool allowAlpha) {
    if (!v.is_array() || !(v.size() == 3 || (allowAlpha && v.size() == 4))) {
        d.error(path, std::string("expected a colour [r, g, b") + (allowAlpha ? "(, a)" : "") + "] with values in [0, 1], got " + typeName(v) + " " +
                          brief(v));
        return std::nullopt;
    }
    glm::vec4 out(1.0f);
    for (std::size_t i = 0; i < v.size(); ++i) {
        const auto x = readNumber(d, index(path, i), v[i], 0.0, 1.0);
        if (!x) return std::nullopt;
        out[int(i)] = float(*x);
    }
    return out;
}

std::optional<std::string> readChoice(Diagnostics& d, const std::string& path, const Json& v, const std::vector<std::string>& choices) {
    std::string list;
    for (std::size_t i = 0; i < choices.size(); ++i) list += (i ? ", " : "") + ("\"" + choices[i] + "\"");
    if (!v.is_string()) {
        d.error(path, "expected one of " + list + ", got " + typeName(v) + " " + brief(v));
        return std::nullopt;
    }
    const std::string s = v.get<std::string>();
    if (std::find(choices.begin(), choices.end(), s) != choices.end()) return s;
    const std::string near = closest(s, choices);
    d.error(path, "unknown value " + brief(v) + (near.empty() ? "" : " (did you mean \"" + near + "\"?)") + "; expected one of " + list);
    return std::nullopt;
}

ObjectReader::ObjectReader(Diagnostics& d, std::string path, const Json& v) : mD(d), mPath(std::move(path)) {
    if (v.is_object()) mObj = &v;
    else d.error(mPath, "expected an object {...}, got " + typeName(v) + " " + brief(v));
}

bool ObjectReader::has(const std::string& key) const { return mObj && mObj->contains(key); }

const Json* ObjectReader::get(const std::string& key) {
    mKnown.insert(key);
    if (!mObj) return nullptr;
    auto it = mObj->find(key);
    return it == mObj->end() ? nullptr : &*it;
}

void ObjectReader::number(const std::string& key, float& out, double lo, double hi) {
    if (const Json* v = get(key))
        if (auto x = readNumber(mD, at(key), *v, lo, hi)) out = float(*x);
}
void ObjectReader::number(const std::string& key, double& out, double lo, double hi) {
    if (const Json* v = get(key))
        if (auto x = readNumber(mD, at(key), *v, lo, hi)) out = *x;
}
void ObjectReader::integer(const std::string& key, int& out, int lo, int hi) {
    if (const Json* v = get(key))
        if (auto x = readInt(mD, at(key), *v, lo, hi)) out = int(*x);
}
void ObjectReader::seed(const std::string& key, std::uint32_t& out) {
    if (const Json* v = get(key))
        if (auto x = readInt(mD, at(key), *v, 0, 4294967295LL)) out = std::uint32_t(*x);
}
void ObjectReader::boolean(const std::string& key, bool& out) {
    if (const Json* v = get(key))
        if (auto x = readBool(mD, at(key), *v)) out = *x;
}
void ObjectReader::string(const std::string& key, std::string& out) {
    if (const Json* v = get(key))
        if (auto x = readString(mD, at(key), *v)) out = *x;
}
void ObjectReader::vec3(const std::string& key, glm::vec3& out, double lo, double hi, bool allowScalar) {
    if (const Json* v = get(key))
        if (auto x = readVec3(mD, at(key), *v, lo, hi, allowScalar)) out = *x;
}
void ObjectReader::ivec3(const std::string& key, glm::ivec3& out, int lo, int hi) {
    if (const Json* v = get(key))
        if (auto x = readIvec3(mD, at(key), *v, lo, hi)) out = *x;
}
void ObjectReader::color3(const std::string& key, glm::vec3& out) {
    if (const Json* v = get(key))
        if (auto x = readColor(mD, at(key), *v, false)) out = glm::vec3(*x);
}

void ObjectReader::finish() {
    if (!mObj) return;
    const std::vector<std::string> known(mKnown.begin(), mKnown.end());
    for (auto it = mObj->begin(); it != mObj->end(); ++it) {
        if (mKnown.count(it.key())) continue;
        const std::string near = closest(it.key(), known);
        std::string list;
        for (std::size_t i = 0; i < known.size(); ++i) list += (i ? ", " : "") + known[i];
        mD.error(at(it.key()), "unknown key" + (near.empty() ? std::string() : " (did you mean \"" + near + "\"?)") + "; keys allowed here: " + list);
    }
}

std::string num(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

} // namespace splatfx::scenefile
