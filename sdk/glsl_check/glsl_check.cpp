// Build-time GLSL check (sdk/CMakeLists.txt, target splatfx_glsl_check):
// assembles every program variant the GL passes can ask for exactly as they
// do (glsl/programs.hpp: the files, the #defines, the generated fog and
// footprint includes) and compiles and links each with glslangValidator, the
// Khronos reference front end, as desktop GLSL 4.50 core. Any error fails
// the build with the variant's name and the compiler's message.
//
//   splatfx_glsl_check_tool /usr/bin/glslangValidator build/sdk/glsl_check
//
// Fogs: none, each term kind alone (both cell modes, 1 and 3 variables), and
// the paper's three figures (several terms). Footprints: the default and a
// Gaussian one with other table sizes (the constants differ).
#include <algorithm>
#include <atomic>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "glsl/glsl_files.hpp"
#include "glsl/programs.hpp"
#include "render/gl/transparent_bindings.hpp"
#include "splatfx/fog.hpp"
#include "splatfx/footprint.hpp"

namespace {

using namespace splatfx;

struct Job {
    std::string name;                      // the variant, for messages
    std::vector<glsl::StageSource> stages; // complete sources
};

std::vector<std::pair<std::string, FogDesc>> sampleFogs() {
    std::vector<std::pair<std::string, FogDesc>> fogs;
    auto one = [&](const char* name, FogTerm t) {
        FogDesc d;
        d.terms.push_back(FogTerm::constant(1.0));
        d.terms.push_back(std::move(t));
        fogs.push_back({name, d});
    };
    FogDesc constant;
    constant.terms.push_back(FogTerm::constant(0.1));
    fogs.push_back({"constant", constant});
    one("cosine", FogTerm::cosine(0.2, 3.0, {0.0, 1.0, 0.2}, 0.5));
    one("cosine product", FogTerm::cosineProduct(0.1, 2.0, {1.0, 0.0, 0.0}, 0.0, 1.0, {0.0, 0.0, 1.0}, 0.3));
    one("1D polynomial, zero outside", FogTerm::polynomial1D(0.5, 1, {1.0, 0.0, -0.5}, 4.0, FogCellMode::ZeroOutside));
    FogTerm multi;
    multi.kind = FogTermKind::Polynomial;
    multi.cellHalfSize = {200.0, 150.0, 250.0};
    multi.monomials = {{0.02, 0, 0, 0}, {-0.005, 2, 1, 0}, {0.003, 1, 1, 1}, {0.002, 0, 0, 4}, {0.001, 3, 0, 2}};
    one("3-variable polynomial, periodic", multi);
    multi.cellMode = FogCellMode::ZeroOutside;
    one("3-variable polynomial, zero outside", multi);
    one("point", FogTerm::point(0.3, {0.5, 0.2, -2.0}, 1.0, 2.0));
    one("line", FogTerm::line(0.3, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 1.0, 2.0));
    one("sphere", FogTerm::sphere(0.3, {1.0, 0.0, 0.0}, 2.0, 1.0, 2.0));
    fogs.push_back({"paper fig. 6 (cosines)", paperFig6Fog()});
    fogs.push_back({"paper fig. 7 (1D polynomials, periodic)", paperFig7Fog()});
    fogs.push_back({"paper fig. 8 (constant and points)", paperFig8Fog()});
    return fogs;
}

// glslangValidator's value of `#define name N` in an embedded file, or -1.
int defineIn(std::string_view file, const std::string& name) {
    const std::string text(glsl::file(file));
    const std::string key = "#define " + name + " ";
    const std::size_t at = text.find(key);
    return at == std::string::npos ? -1 : std::atoi(text.c_str() + at + key.size());
}

} // namespace

int main(int argc, char** argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: %s <glslangValidator> <output folder>\n", argv[0]);
        return 2;
    }
    const std::string validator = argv[1], out = argv[2];
    int failures = 0;

    // The bindings the GL backend binds against the ones the GLSL declares.
    const std::pair<const char*, int> bindings[] = {{"SPLATFX_NODE_BINDING", gl::detail::kTransparentNodeBinding},
                                                    {"SPLATFX_COUNTER_BINDING", gl::detail::kTransparentCounterBinding},
                                                    {"SPLATFX_HEAD_UNIT", gl::detail::kTransparentHeadImageUnit}};
    for (const auto& [name, value] : bindings)
        if (defineIn("transparent_lists.glsl", name) != value) {
            std::fprintf(stderr, "glsl check: transparent_lists.glsl's %s is %d, render/gl/transparent_bindings.hpp binds %d\n", name,
                         defineIn("transparent_lists.glsl", name), value);
            ++failures;
        }

    std::vector<std::pair<std::string, std::string>> fogs; // (name, fogGlsl source)
    for (const auto& [name, desc] : sampleFogs()) {
        auto fog = Fog::create(desc);
        auto src = fog ? fogGlsl(*fog) : Result<FogGlsl>(makeError(fog.error()));
        if (!src) {
            std::fprintf(stderr, "glsl check: sample fog \"%s\": %s\n", name.c_str(), src.error().c_str());
            return 1;
        }
        fogs.push_back({name, src->source});
    }
    const Footprint footprints[] = {Footprint(FootprintDesc{}),
                                    Footprint({.kernel = Kernel::Gaussian, .partialRadialSize = 16, .partialDepthSize = 40})};

    std::vector<Job> jobs;
    for (int p = 0; p < int(glsl::ProgramId::Count); ++p) {
        const auto id = glsl::ProgramId(p);
        const int binding = id == glsl::ProgramId::Splat ? 2 : 3; // Renderer's and FragmentListPass's partial-table units
        glsl::forEachVariant(id, [&](const std::array<int, glsl::kMaxDefines>& values) {
            const unsigned gen = glsl::generatedParts(id, values);
            std::vector<std::pair<std::size_t, std::size_t>> data; // (fog, footprint) pairs
            if (gen & glsl::kFogTerms)
                for (std::size_t f = 0; f < fogs.size(); ++f) data.push_back({f, 0});
            if (gen & glsl::kPartialConstants)
                for (std::size_t k = (gen & glsl::kFogTerms) ? 1 : 0; k < std::size(footprints); ++k) data.push_back({0, k});
            if (data.empty()) data.push_back({0, 0});
            for (const auto& [f, k] : data) {
                const std::string partial = (gen & glsl::kPartialConstants) ? partialGlsl(footprints[k], binding) : std::string();
                const glsl::ProgramKey key{id, values, 0};
                auto stages = glsl::programSources(
                    key, {.fog = (gen & glsl::kFogTerms) ? std::string_view(fogs[f].second) : std::string_view(), .partial = partial});
                std::string name = glsl::variantName(key);
                if (gen & glsl::kFogTerms) name += ", fog \"" + fogs[f].first + "\"";
                if (gen & glsl::kPartialConstants) name += k ? ", Gaussian footprint" : ", default footprint";
                if (!stages) {
                    std::fprintf(stderr, "glsl check: %s\n", stages.error().c_str());
                    ++failures;
                    continue;
                }
                jobs.push_back({name, std::move(*stages)});
            }
        });
    }

    std::atomic<std::size_t> next{0};
    std::mutex printing;
    std::atomic<int> failed{0};
    auto work = [&] {
        for (std::size_t j; (j = next++) < jobs.size();) {
            const Job& job = jobs[j];
            std::string cmd = "'" + validator + "' -l";
            for (const glsl::StageSource& s : job.stages) {
                const char* ext = s.stage == glsl::Stage::Vertex ? "vert" : s.stage == glsl::Stage::Fragment ? "frag" : "comp";
                const std::string path = out + "/v" + std::to_string(j) + "." + ext;
                std::ofstream(path, std::ios::binary) << s.text;
                cmd += " '" + path + "'";
            }
            cmd += " 2>&1";
            std::string log;
            FILE* pipe = popen(cmd.c_str(), "r");
            if (!pipe) {
                std::lock_guard lock(printing);
                std::fprintf(stderr, "glsl check: cannot run %s\n", validator.c_str());
                ++failed;
                continue;
            }
            char buf[4096];
            for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, pipe)) > 0;) log.append(buf, n);
            const int rc = pclose(pipe);
            // glslangValidator prints each file's name; anything else is a diagnostic.
            std::string diag;
            for (std::size_t pos = 0; pos < log.size();) {
                std::size_t end = log.find('\n', pos);
                end = end == std::string::npos ? log.size() : end + 1;
                const std::string ln = log.substr(pos, end - pos);
                if (ln.find(out) != 0 && ln != "\n") diag += ln;
                pos = end;
            }
            if (rc != 0 || !diag.empty()) {
                std::lock_guard lock(printing);
                std::fprintf(stderr, "glsl check: %s (files %s/v%zu.*):\n%s\n", job.name.c_str(), out.c_str(), j, log.c_str());
                ++failed;
            }
        }
    };
    std::vector<std::thread> threads;
    const unsigned n = std::clamp(std::thread::hardware_concurrency(), 1u, 4u);
    for (unsigned t = 0; t < n; ++t) threads.emplace_back(work);
    for (std::thread& t : threads) t.join();
    failures += failed;
    if (failures) {
        std::fprintf(stderr, "glsl check: %d of %zu program variants failed\n", failures, jobs.size());
        std::remove((out + "/checked.stamp").c_str());
        return 1;
    }
    std::ofstream(out + "/checked.stamp") << jobs.size() << " program variants compiled and linked by " << validator << "\n";
    std::printf("glsl check: %zu program variants compiled and linked (glslangValidator, GLSL 4.50 core)\n", jobs.size());
    return 0;
}
