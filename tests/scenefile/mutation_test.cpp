// Deterministic corpus replay and mutation (CPU, always run): the corpus and
// every sample scene parse as they are, and thousands of mutated variants
// (byte flips, truncations, deletions, duplicated spans, hostile tokens) each
// give a scene or a message naming the file; none may crash or throw. The
// libFuzzer target (fuzz_scene_file) explores further when clang is there.
#include <filesystem>
#include <fstream>
#include <random>

#include <gtest/gtest.h>

#include "sanitized.hpp"
#include "splatfx/scene_file.hpp"

namespace {

namespace fs = std::filesystem;

std::vector<fs::path> seeds() {
    std::vector<fs::path> out;
    for (const auto& e : fs::directory_iterator(SPLATFX_SCENEFILE_CORPUS)) out.push_back(e.path());
    const fs::path samples = fs::path(SPLATFX_SOURCE_DIR) / "samples";
    for (const auto& e : fs::directory_iterator(samples))
        if (fs::is_regular_file(e.path() / "scene.json")) {
#if !SPLATFX_WITH_VDB
            // Kind "vdb" needs splatfx::vdb; a build without it refuses those samples (SceneFileVdb says how).
            std::ifstream in(e.path() / "scene.json");
            const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
            if (text.find("\"kind\": \"vdb\"") != std::string::npos) continue;
#endif
            out.push_back(e.path() / "scene.json");
        }
    std::sort(out.begin(), out.end());
    return out;
}

std::string read(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string mutate(const std::string& s, std::mt19937& rng) {
    static const char* tokens[] = {"null", "-1", "1e999", "0", "[]", "{}", "\"\"", "1e9", "true", "[1e9, 1e9, 1e9]", "\"x\"", ",", ":", "\"kind\""};
    std::string t = s;
    const int edits = 1 + int(rng() % 3);
    for (int e = 0; e < edits && !t.empty(); ++e) {
        const std::size_t at = rng() % t.size();
        switch (rng() % 5) {
        case 0: t[at] = char(rng() % 256); break;
        case 1: t.resize(at); break;
        case 2: t.erase(at, 1 + rng() % 16); break;
        case 3: t.insert(at, t.substr(rng() % t.size(), 1 + rng() % 32)); break;
        default: t.insert(at, tokens[rng() % (sizeof tokens / sizeof *tokens)]); break;
        }
    }
    return t;
}

TEST(SceneFileCorpus, EverySeedParses) {
    for (const fs::path& p : seeds()) {
        splatfx::Materials m(splatfx::Footprint{});
        auto r = splatfx::parseSceneFile(read(p), p.string(), m);
        EXPECT_TRUE(r.ok()) << p << ": " << (r ? "" : r.error());
    }
}

TEST(SceneFileCorpus, MutationsNeverCrashAndAlwaysExplain) {
    std::mt19937 rng(20240601u); // fixed: the same inputs on every run
    int rejected = 0, accepted = 0;
    for (const fs::path& p : seeds()) {
        const std::string text = read(p);
        // Solver-heavy samples cost more per parse; 60 variants each keeps the test to a few seconds
        // (12 sanitized, where fuzz_scene_file runs 10000 under the same sanitizers).
        for (int i = 0; i < splatfx::test::count(60, 12); ++i) {
            const std::string m = mutate(text, rng);
            splatfx::Materials materials(splatfx::Footprint{});
            auto r = splatfx::parseSceneFile(m, p.string(), materials);
            if (r) {
                ++accepted;
                continue;
            }
            ++rejected;
            ASSERT_FALSE(r.error().empty());
            ASSERT_EQ(r.error().rfind(p.string(), 0), 0u) << "message must start with the file name:\n" << r.error() << "\ninput:\n" << m;
        }
    }
    EXPECT_GT(rejected, 0);
    EXPECT_GT(accepted, 0); // some mutations are harmless (e.g. inside a title), and those must still load
}

} // namespace
