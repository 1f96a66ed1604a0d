#include "mesh.hpp"

#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "splatfx/image_io.hpp"
#include "splatfx/scene_file.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <assimp/DefaultIOSystem.h>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

namespace scenehost {

splatfx::Aabb Mesh::bounds() const {
    splatfx::Aabb b;
    for (const glm::vec3& p : positions) b.extend(p);
    return b;
}

namespace {

// Budgets for meshes a scene file names (Budgets::meshFileBytes,
// meshElements), checked before assimp allocates: a crafted header can claim
// billions of elements in a few bytes.

// PLY and OFF state their element counts in a text header. A count is
// refused when it exceeds the budget, or when the file is too short to hold
// that many elements at their smallest encoding (ASCII "0 0 0\n" is 6 bytes a
// vertex, binary is 12; a face is at least 4 bytes either way).
// The OFF keyword with its optional prefixes (ST, C, N, 4, n: texture, colour,
// normals, homogeneous, dimension), as assimp's OFF reader accepts it.
bool isOffKeyword(const std::string& word) {
    std::size_t i = word.rfind("ST", 0) == 0 ? 2 : 0;
    for (char prefix : {'C', 'N', '4', 'n'})
        if (i < word.size() && word[i] == prefix) ++i;
    return word.compare(i, std::string::npos, "OFF") == 0;
}

splatfx::Status checkHeaderCounts(const std::string& path, std::uintmax_t fileBytes, const splatfx::Budgets& budgets) {
    std::ifstream in(path, std::ios::binary);
    std::string line;
    if (!std::getline(in, line)) return {};
    if (!line.empty() && line.back() == '\r') line.pop_back();
    struct Claim {
        const char* what;
        std::uint64_t count;
        std::uint64_t minBytes;
    };
    std::vector<Claim> claims;
    // assimp picks its PLY reader by the extension, or by a first word that merely starts with "ply".
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    if (line.rfind("ply", 0) == 0 || ext == ".ply") {
        bool binary = false, ended = false;
        // A header that never ends sends Debian's assimp 5.2 into an endless seek at the end
        // of the file (found by tests/fuzz fuzz_mesh), so it is refused here. Real headers
        // are a few hundred bytes; 64 KiB leaves room for long comment blocks.
        while (!ended && in.tellg() < std::streamoff(64 * 1024) && std::getline(in, line)) {
            while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t')) line.pop_back();
            if (line.rfind("format ", 0) == 0) binary = line.find("binary") != std::string::npos;
            unsigned long long count = 0;
            char name[32] = {};
            if (std::sscanf(line.c_str(), "element %31s %llu", name, &count) == 2) {
                const bool vertex = std::string(name) == "vertex";
                claims.push_back({vertex ? "vertices" : "faces", count, vertex ? (binary ? 12u : 6u) : 4u});
            }
            ended = line == "end_header";
        }
        if (!ended) return splatfx::makeError(path + ": the PLY header has no \"end_header\" line in its first 64 KiB (truncated or not a PLY file)");
    } else if (isOffKeyword(line.substr(0, line.find_first_of(" \t"))) || ext == ".off") {
        // assimp reads an OFF's counts as the first numbers after the keyword, across line
        // breaks (a count alone on a later line is still the face count: found by fuzz_mesh).
        // The first three numbers (vertices, faces, edges; nOFF puts its dimension first) are
        // read the same way, each saturating, so no count assimp would allocate from escapes.
        const std::size_t keyword = line.find("OFF");
        std::string head = keyword == std::string::npos ? line : line.substr(keyword + 3);
        for (std::string more; head.size() < 4096 && std::getline(in, more);) head += "\n" + more;
        std::uint64_t numbers[3] = {};
        int found = 0;
        for (std::size_t i = 0; i < head.size() && found < 3;) {
            const char ch = head[i];
            if (ch == '#') {
                i = head.find('\n', i);
                if (i == std::string::npos) break;
            } else if (std::isdigit(static_cast<unsigned char>(ch))) {
                std::uint64_t v = 0;
                for (; i < head.size() && std::isdigit(static_cast<unsigned char>(head[i])); ++i)
                    v = v > (UINT64_MAX - 9) / 10 ? UINT64_MAX : v * 10 + std::uint64_t(head[i] - '0');
                numbers[found++] = v;
            } else {
                ++i;
            }
        }
        const char* names[3] = {"vertices", "faces", "edges"};
        const std::uint64_t minBytes[3] = {6, 8, 0};
        for (int k = 0; k < found; ++k) claims.push_back({names[k], numbers[k], minBytes[k]});
    }
    for (const Claim& c : claims) {
        if (auto s = splatfx::checkBudget(path + ": the mesh, by its header,", c.count, c.what, budgets.meshElements, "meshElements"); !s) return s;
        if (c.count * c.minBytes > fileBytes)
            return splatfx::makeError(path + ": the header claims " + std::to_string(c.count) + " " + c.what + " but the file has only " +
                                      std::to_string(fileBytes) + " bytes (truncated or crafted)");
    }
    return {};
}

// Every file assimp opens goes through this: the mesh itself and whatever it names (an
// OBJ's mtllib, a glTF's buffers, a Collada's images). Only regular files inside the
// mesh's own folder, each within the file budget, are opened; anything else reads as
// missing. Without it a crafted reference reached any file on the machine, and what it
// found there decided what happened (a CI fuzz run met a 16.9 GB allocation that a second
// machine, with other files, never saw).
class ConfinedIOSystem : public Assimp::DefaultIOSystem {
public:
    ConfinedIOSystem(std::filesystem::path folder, std::uintmax_t maxBytes) : mFolder(std::move(folder)), mMaxBytes(maxBytes) {}

    bool Exists(const char* file) const override { return allowed(file); }

    Assimp::IOStream* Open(const char* file, const char* mode) override {
        const std::string m = mode ? mode : "rb";
        if (m.find_first_of("wa+") != std::string::npos || !allowed(file)) return nullptr;
        return Assimp::DefaultIOSystem::Open(file, mode);
    }

private:
    bool allowed(const char* file) const {
        if (!file || !*file) return false;
        std::error_code ec;
        const std::filesystem::path p = std::filesystem::canonical(file, ec); // symlinks resolved
        if (ec || !std::filesystem::is_regular_file(p, ec)) return false;
        const std::filesystem::path rel = p.lexically_relative(mFolder);
        if (rel.empty() || *rel.begin() == "..") return false;
        const std::uintmax_t bytes = std::filesystem::file_size(p, ec);
        return !ec && bytes <= mMaxBytes;
    }

    std::filesystem::path mFolder;
    std::uintmax_t mMaxBytes;
};

void appendNode(const aiScene* scene, const aiNode* node, const aiMatrix4x4& parent, Mesh& out) {
    const aiMatrix4x4 m = parent * node->mTransformation;
    for (unsigned i = 0; i < node->mNumMeshes; ++i) {
        const aiMesh* mesh = scene->mMeshes[node->mMeshes[i]];
        const std::uint32_t base = std::uint32_t(out.positions.size());
        for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
            const aiVector3D p = m * mesh->mVertices[v];
            out.positions.push_back({p.x, p.y, p.z});
        }
        for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
            const aiFace& face = mesh->mFaces[f];
            if (face.mNumIndices != 3) continue; // points and lines (aiProcess_Triangulate leaves only these)
            for (int k = 0; k < 3; ++k) out.indices.push_back(base + face.mIndices[k]);
        }
    }
    for (unsigned c = 0; c < node->mNumChildren; ++c) appendNode(scene, node->mChildren[c], m, out);
}

// assimp itself: positions and triangle indices, or why not.
splatfx::Result<Mesh> importWithAssimp(const std::string& path, const splatfx::Budgets& budgets) {
    Assimp::Importer importer;
    std::error_code ec;
    importer.SetIOHandler(new ConfinedIOSystem(std::filesystem::canonical(path, ec).parent_path(), budgets.meshFileBytes)); // the importer owns it
    // Validation makes assimp refuse out-of-range indices and other broken structure instead of handing them on.
    const aiScene* scene = importer.ReadFile(path, aiProcess_ValidateDataStructure);
    if (!scene || !scene->mRootNode) return splatfx::makeError(path + ": cannot load mesh: " + importer.GetErrorString());
    // Validation lets a face of no vertices through (a PLY face line that does not parse), and
    // Debian's assimp 5.2 then aborts in Triangulate (found by tests/fuzz fuzz_mesh): such a
    // file is refused before the post-processing runs.
    for (unsigned m = 0; m < scene->mNumMeshes; ++m)
        for (unsigned f = 0; f < scene->mMeshes[m]->mNumFaces; ++f)
            if (scene->mMeshes[m]->mFaces[f].mNumIndices == 0 || !scene->mMeshes[m]->mFaces[f].mIndices)
                return splatfx::makeError(path + ": face " + std::to_string(f) + " of mesh " + std::to_string(m) +
                                          " has no vertices (a malformed face)");
    scene = importer.ApplyPostProcessing(aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_SortByPType);
    if (!scene || !scene->mRootNode) return splatfx::makeError(path + ": cannot load mesh: " + importer.GetErrorString());
    Mesh out;
    appendNode(scene, scene->mRootNode, aiMatrix4x4(), out);
    return out;
}

// assimp runs in a child process. Fuzzing Debian's assimp 5.2 keeps finding files that make
// it corrupt its heap, abort, hang or allocate tens of GB (each session's header checks above
// caught some; the next run found more), so the host no longer trusts it with its own address
// space: the child is held to Budgets::meshImportBytes of new address space and
// meshImportSeconds, and sends back plain arrays that this process checks before using.
// The child leaves with _exit: no atexit handler or static destructor of the parent runs twice.
constexpr std::uint32_t kWireMagic = 0x31485353; // "SSH1"
struct WireHeader {
    std::uint32_t magic = kWireMagic;
    std::uint32_t ok = 0;
    std::uint64_t positions = 0; // or the message's length when !ok
    std::uint64_t indices = 0;
};

bool writeAll(int fd, const void* data, std::size_t bytes) {
    const char* p = static_cast<const char*>(data);
    while (bytes > 0) {
        const ssize_t n = ::write(fd, p, bytes);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return false;
        p += n, bytes -= std::size_t(n);
    }
    return true;
}

// Defined only when a sanitizer runtime is linked (the fuzz and sanitizer builds).
extern "C" __attribute__((weak)) void __sanitizer_set_death_callback(void (*)(void));

[[noreturn]] void childImport(int fd, const std::string& path, const splatfx::Budgets& budgets) {
    // What goes wrong in here is reported by the parent, from the exit status: the child drops
    // the handlers it inherited (a fuzzer's would file the input as its own crash), writes no
    // core file and prints nothing.
    if (__sanitizer_set_death_callback) __sanitizer_set_death_callback(nullptr);
    for (int sig : {SIGSEGV, SIGBUS, SIGABRT, SIGILL, SIGFPE, SIGXCPU, SIGALRM, SIGINT, SIGTERM, SIGUSR1, SIGUSR2}) std::signal(sig, SIG_DFL);
    const rlimit noCore{0, 0};
    setrlimit(RLIMIT_CORE, &noCore);
    if (const int devNull = ::open("/dev/null", O_WRONLY); devNull >= 0) ::dup2(devNull, STDERR_FILENO), ::dup2(devNull, STDOUT_FILENO);
    // New address space, beyond what the child holds now (the parent's mappings, an
    // AddressSanitizer's shadow), is what the budget limits.
    long pages = 0;
    if (std::FILE* statm = std::fopen("/proc/self/statm", "r")) {
        if (std::fscanf(statm, "%ld", &pages) != 1) pages = 0;
        std::fclose(statm);
    }
    const std::uint64_t held = std::uint64_t(pages) * std::uint64_t(sysconf(_SC_PAGESIZE));
    if (pages > 0 && budgets.meshImportBytes < UINT64_MAX - held) {
        const rlimit as{rlim_t(held + budgets.meshImportBytes), rlim_t(held + budgets.meshImportBytes)};
        setrlimit(RLIMIT_AS, &as);
    }
    const rlimit cpu{rlim_t(budgets.meshImportSeconds + 1), rlim_t(budgets.meshImportSeconds + 1)};
    setrlimit(RLIMIT_CPU, &cpu);
    WireHeader h;
    std::string message;
    Mesh mesh;
    const std::string outOfMemory = path + ": the mesh library went over its memory budget of " + std::to_string(budgets.meshImportBytes) +
                                    " bytes (raise Budgets::meshImportBytes)";
    try {
        auto r = importWithAssimp(path, budgets);
        if (r) mesh = std::move(*r), h.ok = 1, h.positions = mesh.positions.size(), h.indices = mesh.indices.size();
        // assimp catches the allocation failure itself and reports its name.
        else message = r.error().find("bad_alloc") != std::string::npos ? outOfMemory : r.error();
    } catch (const std::bad_alloc&) { message = outOfMemory; } catch (const std::exception& e) {
        message = path + ": cannot load mesh: " + e.what();
    }
    if (!h.ok) h.positions = message.size();
    const bool sent = writeAll(fd, &h, sizeof h) && (h.ok ? writeAll(fd, mesh.positions.data(), mesh.positions.size() * sizeof(glm::vec3)) &&
                                                                writeAll(fd, mesh.indices.data(), mesh.indices.size() * sizeof(std::uint32_t))
                                                          : writeAll(fd, message.data(), message.size()));
    _exit(sent ? 0 : 1);
}

// Reads exactly `bytes` from the child by the deadline; false on end of file, error or time out.
bool readAll(int fd, void* data, std::size_t bytes, std::chrono::steady_clock::time_point deadline) {
    char* p = static_cast<char*>(data);
    while (bytes > 0) {
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
        if (left <= 0) return false;
        pollfd pfd{fd, POLLIN, 0};
        const int ready = ::poll(&pfd, 1, int(std::min<long long>(left, 1000)));
        if (ready < 0 && errno == EINTR) continue;
        if (ready < 0) return false;
        if (ready == 0) continue;
        const ssize_t n = ::read(fd, p, bytes);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return false;
        p += n, bytes -= std::size_t(n);
    }
    return true;
}

splatfx::Result<Mesh> importIsolated(const std::string& path, const splatfx::Budgets& budgets) {
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0) return splatfx::makeError(path + ": cannot start the mesh library's process: " + std::strerror(errno));
    std::fflush(nullptr); // nothing buffered is written twice
    const pid_t child = ::fork();
    if (child < 0) {
        const int err = errno;
        ::close(fds[0]), ::close(fds[1]);
        return splatfx::makeError(path + ": cannot start the mesh library's process: " + std::strerror(err));
    }
    if (child == 0) {
        ::close(fds[0]);
        childImport(fds[1], path, budgets);
    }
    ::close(fds[1]);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(std::min<std::uint64_t>(budgets.meshImportSeconds, 1u << 30));
    WireHeader h;
    std::string message;
    Mesh mesh;
    bool received = readAll(fds[0], &h, sizeof h, deadline) && h.magic == kWireMagic;
    if (received && !h.ok) {
        message.resize(std::size_t(std::min<std::uint64_t>(h.positions, 1u << 16)));
        received = readAll(fds[0], message.data(), message.size(), deadline);
    } else if (received) {
        // The counts come from another process: checked before anything is allocated.
        if (auto s = splatfx::checkBudget(path + ": the mesh", std::max(h.positions, h.indices / 3), "vertices or faces", budgets.meshElements,
                                          "meshElements");
            !s) {
            ::kill(child, SIGKILL);
            message = s.error();
        } else {
            mesh.positions.resize(std::size_t(h.positions));
            mesh.indices.resize(std::size_t(h.indices));
            received = readAll(fds[0], mesh.positions.data(), mesh.positions.size() * sizeof(glm::vec3), deadline) &&
                       readAll(fds[0], mesh.indices.data(), mesh.indices.size() * sizeof(std::uint32_t), deadline);
        }
    }
    const bool timedOut = std::chrono::steady_clock::now() >= deadline;
    if (!received) ::kill(child, SIGKILL);
    ::close(fds[0]);
    int status = 0;
    while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {}
    if (!message.empty()) return splatfx::makeError(message);
    if (received && h.ok) return mesh;
    if (timedOut)
        return splatfx::makeError(path + ": the mesh library did not finish within " + std::to_string(budgets.meshImportSeconds) +
                                  " s (raise Budgets::meshImportSeconds)");
    if (WIFSIGNALED(status))
        return splatfx::makeError(path + ": the mesh library crashed on this file (signal " + std::to_string(WTERMSIG(status)) + ": " +
                                  strsignal(WTERMSIG(status)) + "); the file is malformed or crafted");
    return splatfx::makeError(path + ": the mesh library failed on this file (exit status " + std::to_string(WEXITSTATUS(status)) +
                              "; it may have gone over its memory budget of " + std::to_string(budgets.meshImportBytes) +
                              " bytes: raise Budgets::meshImportBytes)");
}

} // namespace

splatfx::Result<Mesh> loadMesh(const std::string& path, const splatfx::Budgets& budgets) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) return splatfx::makeError(path + ": mesh file not found");
    if (!std::filesystem::is_regular_file(path, ec))
        return splatfx::makeError(path + ": not a regular file (a folder, FIFO or device is never read as a mesh)");
    const std::uintmax_t bytes = std::filesystem::file_size(path, ec);
    if (ec) return splatfx::makeError(path + ": cannot read its size: " + ec.message());
    if (auto s = splatfx::checkBudget(path + ": the mesh file", bytes, "bytes", budgets.meshFileBytes, "meshFileBytes"); !s)
        return splatfx::makeError(s.error());
    if (auto s = checkHeaderCounts(path, bytes, budgets); !s) return splatfx::makeError(s.error());
    auto imported = importIsolated(path, budgets);
    if (!imported) return imported;
    Mesh out = std::move(*imported);
    if (out.indices.empty()) return splatfx::makeError(path + ": the file holds no triangles");
    // A face pointing past the vertices (assimp's validation checks this; the arrays crossed a
    // process boundary) would be read out of bounds by the renderer: the file is refused.
    for (std::uint32_t i : out.indices)
        if (i >= out.positions.size())
            return splatfx::makeError(path + ": a face refers to vertex " + std::to_string(i) + " of " + std::to_string(out.positions.size()));
    for (const glm::vec3& p : out.positions)
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            return splatfx::makeError(path + ": the mesh has non-finite vertex positions");
    computeNormals(out);
    return out;
}

splatfx::Result<Mesh> heightmapMesh(const std::string& path, float spacing, float heightScale, const splatfx::Budgets& budgets) {
    auto info = splatfx::readImageInfo(path);
    if (!info) return splatfx::makeError(info.error());
    const std::uint64_t vertices = std::uint64_t(info->width) * std::uint64_t(info->height);
    if (auto s = splatfx::checkBudget(path + " (" + std::to_string(info->width) + "x" + std::to_string(info->height) + ") as a mesh", vertices,
                                      "vertices", budgets.heightmapVertices, "heightmapVertices");
        !s)
        return splatfx::makeError(s.error());
    auto img = splatfx::readImage(path, splatfx::Alpha::Straight);
    if (!img) return splatfx::makeError(img.error());
    const int w = img->width, h = img->height;
    if (w < 2 || h < 2)
        return splatfx::makeError(path + ": a heightmap needs at least 2x2 samples, got " + std::to_string(w) + "x" + std::to_string(h));
    Mesh m;
    m.positions.reserve(std::size_t(w) * std::size_t(h));
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) {
            const float v = img->at(i, j, 0);
            if (!std::isfinite(v)) return splatfx::makeError(path + ": sample (" + std::to_string(i) + ", " + std::to_string(j) + ") is not finite");
            m.positions.push_back(splatfx::heightmapPoint(i, j, w, h, v, spacing, heightScale));
        }
    for (int j = 0; j + 1 < h; ++j)
        for (int i = 0; i + 1 < w; ++i) {
            const std::uint32_t a = std::uint32_t(j * w + i), b = a + 1, c = a + std::uint32_t(w), d = c + 1;
            // Counter-clockwise seen from +y (z grows with j).
            for (std::uint32_t k : {a, c, b, b, c, d}) m.indices.push_back(k);
        }
    computeNormals(m);
    return m;
}

void computeNormals(Mesh& mesh) {
    mesh.normals.assign(mesh.positions.size(), glm::vec3(0.0f));
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const std::uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
        // The cross product's length is twice the area: area-weighted normals.
        const glm::vec3 n = glm::cross(mesh.positions[b] - mesh.positions[a], mesh.positions[c] - mesh.positions[a]);
        mesh.normals[a] += n, mesh.normals[b] += n, mesh.normals[c] += n;
    }
    for (glm::vec3& n : mesh.normals) n = glm::length(n) > 0.0f ? glm::normalize(n) : glm::vec3(0, 1, 0);
}

Mesh fitted(const Mesh& mesh, float size) {
    Mesh out = mesh;
    const splatfx::Aabb b = mesh.bounds();
    if (b.empty() || !(size > 0.0f)) return out;
    const glm::vec3 ext = b.hi - b.lo;
    const float s = size / std::max({ext.x, ext.y, ext.z, 1e-12f});
    const glm::vec3 anchor(0.5f * (b.lo.x + b.hi.x), b.lo.y, 0.5f * (b.lo.z + b.hi.z));
    for (glm::vec3& p : out.positions) p = (p - anchor) * s;
    return out;
}

splatfx::Status saveOff(const std::string& path, const Mesh& mesh, int decimals) {
    const std::string tmp = path + ".tmp";
    std::FILE* f = std::fopen(tmp.c_str(), "w");
    if (!f) return splatfx::makeError(path + ": cannot write");
    std::fprintf(f, "OFF\n%zu %zu 0\n", mesh.positions.size(), mesh.indices.size() / 3);
    for (const glm::vec3& p : mesh.positions) std::fprintf(f, "%.*f %.*f %.*f\n", decimals, p.x, decimals, p.y, decimals, p.z);
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3)
        std::fprintf(f, "3 %u %u %u\n", mesh.indices[t], mesh.indices[t + 1], mesh.indices[t + 2]);
    const bool ok = std::fclose(f) == 0;
    std::error_code ec;
    if (ok) std::filesystem::rename(tmp, path, ec);
    if (!ok || ec) {
        std::filesystem::remove(tmp, ec);
        return splatfx::makeError(path + ": cannot write");
    }
    return {};
}

namespace {

// Flat-shaded quad: its own four vertices so the normals stay sharp.
void quad(Mesh& m, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) {
    const std::uint32_t base = std::uint32_t(m.positions.size());
    const glm::vec3 n = glm::normalize(glm::cross(b - a, d - a));
    for (glm::vec3 p : {a, b, c, d}) m.positions.push_back(p), m.normals.push_back(n);
    for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + i);
}

} // namespace

Mesh planeMesh(glm::vec3 size) {
    Mesh m;
    const float x = 0.5f * size.x, z = 0.5f * size.z;
    quad(m, {-x, 0, z}, {x, 0, z}, {x, 0, -z}, {-x, 0, -z});
    return m;
}

Mesh boxMesh(glm::vec3 size) {
    Mesh m;
    const glm::vec3 h = 0.5f * size;
    const glm::vec3 p[8] = {{-h.x, -h.y, -h.z}, {h.x, -h.y, -h.z}, {h.x, h.y, -h.z}, {-h.x, h.y, -h.z},
                            {-h.x, -h.y, h.z},  {h.x, -h.y, h.z},  {h.x, h.y, h.z},  {-h.x, h.y, h.z}};
    quad(m, p[4], p[5], p[6], p[7]); // +z
    quad(m, p[1], p[0], p[3], p[2]); // -z
    quad(m, p[5], p[1], p[2], p[6]); // +x
    quad(m, p[0], p[4], p[7], p[3]); // -x
    quad(m, p[7], p[6], p[2], p[3]); // +y
    quad(m, p[0], p[1], p[5], p[4]); // -y
    return m;
}

Mesh cylinderMesh(glm::vec3 size, int segments) {
    Mesh m;
    const float r = 0.5f * size.x, h = size.y;
    const float twoPi = 6.2831853f;
    for (int i = 0; i < segments; ++i) {
        const float a0 = twoPi * i / segments, a1 = twoPi * (i + 1) / segments;
        const glm::vec3 d0(std::cos(a0), 0, -std::sin(a0)), d1(std::cos(a1), 0, -std::sin(a1));
        const std::uint32_t base = std::uint32_t(m.positions.size());
        for (glm::vec3 p : {r * d0, r * d1, r * d1 + glm::vec3(0, h, 0), r * d0 + glm::vec3(0, h, 0)}) m.positions.push_back(p);
        for (glm::vec3 n : {d0, d1, d1, d0}) m.normals.push_back(n);
        for (std::uint32_t k : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + k);
        // Caps as fans of their own vertices (flat normals).
        for (int cap = 0; cap < 2; ++cap) {
            const float y = cap ? h : 0.0f;
            const glm::vec3 n(0, cap ? 1.0f : -1.0f, 0);
            const std::uint32_t c = std::uint32_t(m.positions.size());
            for (glm::vec3 p : {glm::vec3(0, y, 0), r * d0 + glm::vec3(0, y, 0), r * d1 + glm::vec3(0, y, 0)})
                m.positions.push_back(p), m.normals.push_back(n);
            if (cap) m.indices.insert(m.indices.end(), {c, c + 1, c + 2});
            else m.indices.insert(m.indices.end(), {c, c + 2, c + 1});
        }
    }
    return m;
}

Mesh sphereMesh(glm::vec3 size, int segments) {
    Mesh m;
    const int rings = segments / 2;
    const float pi = 3.14159265f;
    for (int j = 0; j <= rings; ++j)
        for (int i = 0; i <= segments; ++i) {
            const float th = pi * j / rings, ph = 2.0f * pi * i / segments;
            const glm::vec3 n(std::sin(th) * std::cos(ph), std::cos(th), -std::sin(th) * std::sin(ph));
            m.positions.push_back(0.5f * size * n);
            m.normals.push_back(n);
        }
    for (int j = 0; j < rings; ++j)
        for (int i = 0; i < segments; ++i) {
            const std::uint32_t a = std::uint32_t(j * (segments + 1) + i), b = a + std::uint32_t(segments + 1);
            m.indices.insert(m.indices.end(), {a, b, a + 1, a + 1, b, b + 1});
        }
    return m;
}

} // namespace scenehost
