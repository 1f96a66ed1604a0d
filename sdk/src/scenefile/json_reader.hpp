// Private: reading JSON values with a path for every message.
//
// [SECTION] Diagnostics: errors collected as "<file>: <path>: <what>".
// [SECTION] ObjectReader: an object's keys, each read at most once; the keys
//           nobody asked for are reported as unknown (with a close match).
// [SECTION] Value readers: numbers, integers, vectors, strings, colours,
//           each checking type, finiteness and range.
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

namespace splatfx::scenefile {

using Json = nlohmann::json;

// [SECTION] Diagnostics

class Diagnostics {
public:
    Diagnostics(std::string file, int maxErrors) : mFile(std::move(file)), mMax(maxErrors < 1 ? 1 : maxErrors) {}

    void error(const std::string& path, const std::string& what) {
        if (int(mErrors.size()) < mMax) mErrors.push_back(mFile + ": " + (path.empty() ? "" : path + ": ") + what);
        else mTruncated = true;
    }
    bool ok() const { return mErrors.empty(); }
    bool full() const { return int(mErrors.size()) >= mMax; }
    std::size_t count() const { return mErrors.size(); }
    std::string message() const {
        std::string m;
        for (std::size_t i = 0; i < mErrors.size(); ++i) m += (i ? "\n" : "") + mErrors[i];
        if (mTruncated) m += "\n" + mFile + ": (further problems not listed)";
        return m;
    }
    const std::string& file() const { return mFile; }

private:
    std::string mFile;
    int mMax;
    std::vector<std::string> mErrors;
    bool mTruncated = false;
};

// A short rendering of a value for messages (long values are cut).
std::string brief(const Json& v);
// JSON type name as a person would say it ("a number", "a string", ...).
std::string typeName(const Json& v);
std::string join(const std::string& path, const std::string& key);
std::string index(const std::string& path, std::size_t i);
// Closest of `candidates` to `key` by edit distance, or empty when none is close.
std::string closest(const std::string& key, const std::vector<std::string>& candidates);
// A number as messages write it ("%g").
std::string num(double v);

// [SECTION] Value readers (each returns nullopt after reporting)

std::optional<double> readNumber(Diagnostics& d, const std::string& path, const Json& v, double lo, double hi);
std::optional<std::int64_t> readInt(Diagnostics& d, const std::string& path, const Json& v, std::int64_t lo, std::int64_t hi);
std::optional<bool> readBool(Diagnostics& d, const std::string& path, const Json& v);
std::optional<std::string> readString(Diagnostics& d, const std::string& path, const Json& v);
// [x, y, z]; with allowScalar a single number s means [s, s, s].
std::optional<glm::vec3> readVec3(Diagnostics& d, const std::string& path, const Json& v, double lo, double hi, bool allowScalar = false);
std::optional<glm::ivec3> readIvec3(Diagnostics& d, const std::string& path, const Json& v, int lo, int hi);
// [r, g, b] or [r, g, b, a] (alpha 1 when absent), each in [0, 1].
std::optional<glm::vec4> readColor(Diagnostics& d, const std::string& path, const Json& v, bool allowAlpha);
// One of `choices`; the message lists them.
std::optional<std::string> readChoice(Diagnostics& d, const std::string& path, const Json& v, const std::vector<std::string>& choices);

// [SECTION] ObjectReader

class ObjectReader {
public:
    // Reports and yields an empty reader when v is not an object.
    ObjectReader(Diagnostics& d, std::string path, const Json& v);
    bool valid() const { return mObj != nullptr; }
    const std::string& path() const { return mPath; }
    std::string at(const std::string& key) const { return join(mPath, key); }

    bool has(const std::string& key) const;
    // The value of key (marks it read), or nullptr when absent.
    const Json* get(const std::string& key);
    // Marks a key as known without reading it (it was read elsewhere).
    void touch(const std::string& key) { mKnown.insert(key); }

    // Typed reads: leave `out` unchanged when the key is absent or bad.
    void number(const std::string& key, float& out, double lo, double hi);
    void number(const std::string& key, double& out, double lo, double hi);
    void integer(const std::string& key, int& out, int lo, int hi);
    void seed(const std::string& key, std::uint32_t& out);
    void boolean(const std::string& key, bool& out);
    void string(const std::string& key, std::string& out);
    void vec3(const std::string& key, glm::vec3& out, double lo, double hi, bool allowScalar = false);
    void ivec3(const std::string& key, glm::ivec3& out, int lo, int hi);
    void color3(const std::string& key, glm::vec3& out);

    // Reports every key that was neither read nor touched. Call once, last.
    void finish();

private:
    Diagnostics& mD;
    std::string mPath;
    const Json* mObj = nullptr;
    std::set<std::string> mKnown;
};

} // namespace splatfx::scenefile
