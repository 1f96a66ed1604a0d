// Run records (run_record.hpp says why).
#include "run_record.hpp"

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace render {

namespace fs = std::filesystem;

namespace {
constexpr const char* kHeader = "splatfx-render-run 1";
}

std::string contentHash(const std::string& bytes) {
    std::uint64_t h = 0xcbf29ce484222325ull;
    for (unsigned char c : bytes) h = (h ^ c) * 0x100000001b3ull;
    char text[17];
    std::snprintf(text, sizeof text, "%016llx", (unsigned long long)h);
    return text;
}

splatfx::Result<std::string> hashFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    if (in) bytes << in.rdbuf();
    if (!in || in.bad()) return splatfx::makeError("cannot read '" + path + "' to hash it");
    return contentHash(bytes.str());
}

// Lines: the header; "set NAME VALUE" per setting; "frame INDEX HASH FILE" per
// frame (values and files last: they may hold spaces).
std::string recordText(const RunSettings& settings, const std::map<std::string, std::pair<int, std::string>>& frames) {
    std::string text = std::string(kHeader) + "\n";
    for (const auto& [k, v] : settings) text += "set " + k + " " + v + "\n";
    for (const auto& [file, f] : frames) text += "frame " + std::to_string(f.first) + " " + f.second + " " + file + "\n";
    return text;
}

std::vector<RunRecord> readRunRecords(const std::string& folder) {
    std::vector<RunRecord> records;
    std::error_code ec;
    for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string n = it->path().filename().string();
        if (n.size() < 6 || n[0] != '.' || n.compare(n.size() - 4, 4, ".run") != 0 || !it->is_regular_file(ec)) continue;
        std::ifstream in(it->path());
        std::string line;
        if (!std::getline(in, line) || line != kHeader) continue;
        RunRecord r;
        r.path = it->path().string();
        bool ok = true;
        while (ok && std::getline(in, line)) {
            std::istringstream words(line);
            std::string kind;
            words >> kind;
            if (kind == "set") {
                std::string k, v;
                ok = bool(words >> k) && bool(std::getline(words >> std::ws, v));
                r.settings.emplace_back(k, v);
            } else if (kind == "frame") {
                int index = -1;
                std::string file, hash;
                ok = bool(words >> index >> hash) && bool(std::getline(words >> std::ws, file)) && !file.empty();
                r.frames[file] = {index, hash};
            } else {
                ok = false;
            }
        }
        if (ok) records.push_back(std::move(r));
    }
    return records;
}

std::string settingsDiffer(const RunSettings& record, const RunSettings& wanted) {
    for (const auto& [k, v] : wanted) {
        const std::string* had = nullptr;
        for (const auto& [rk, rv] : record)
            if (rk == k) had = &rv;
        if (!had) return "no " + k + " (this sequence: " + v + ")";
        if (*had != v) return k + " " + *had + " (this sequence: " + v + ")";
    }
    return {};
}

} // namespace render
