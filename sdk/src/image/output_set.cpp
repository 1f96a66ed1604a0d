// Output sets: stage, mark complete, move, record (output_set.hpp says why).
#include "splatfx/output_set.hpp"

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <system_error>

#include "splatfx/image_io.hpp"

namespace splatfx {

namespace fs = std::filesystem;

namespace {

constexpr const char* kRecordHeader = "splatfx-outputs 1";
constexpr const char* kCompleteFile = ".complete"; // inside the staging folder: the set is whole

// A record: a header line, then one file name per line.
std::string recordText(const std::vector<std::string>& files) {
    std::string text = std::string(kRecordHeader) + "\n";
    for (const std::string& f : files) text += f + "\n";
    return text;
}

// Files a record lists; a missing or foreign file lists nothing (nothing is removed on its word).
std::vector<std::string> readRecord(const fs::path& path) {
    std::vector<std::string> files;
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) return files;
    std::ifstream in(path);
    std::string line;
    if (!std::getline(in, line) || line != kRecordHeader) return files;
    while (std::getline(in, line))
        if (!line.empty() && line.find('/') == std::string::npos && line != "." && line != "..") files.push_back(line);
    return files;
}

bool plainName(const std::string& n) {
    return !n.empty() && n.find('/') == std::string::npos && n != "." && n != ".." && n.find('\n') == std::string::npos;
}

// Moves a complete staged set into the folder and records it. Idempotent:
// files already moved are skipped, so a publish cut short is finished by
// running it again.
Status publishStaged(const fs::path& folder, const std::string& name, const fs::path& staging, const std::vector<std::string>& files) {
    std::error_code ec;
    for (const std::string& f : files) {
        const fs::path from = staging / f;
        if (!fs::exists(from, ec)) continue; // moved by an earlier, interrupted publish
        fs::rename(from, folder / f, ec);
        if (ec) return makeError("cannot move '" + f + "' into '" + folder.string() + "': " + ec.message());
    }
    // The previous set's files that this one does not replace, and only those.
    const fs::path record = folder / ("." + name + ".outputs");
    const std::set<std::string> keep(files.begin(), files.end());
    for (const std::string& old : readRecord(record))
        if (!keep.count(old)) fs::remove(folder / old, ec);
    if (Status s = writeFileAtomically(record.string(), recordText(files)); !s) return s;
    fs::remove_all(staging, ec);
    return {};
}

} // namespace

struct OutputSet::Impl {
    fs::path folder;
    std::string name;
    fs::path staging;
    std::vector<std::string> files;
    bool published = false;
};

Result<OutputSet> OutputSet::begin(const std::string& folder, const std::string& name) {
    if (!plainName(name)) return makeError("output name '" + name + "' must be a plain file name (no '/', not '.' or '..')");
    auto impl = std::make_unique<Impl>();
    impl->folder = folder.empty() ? fs::path(".") : fs::path(folder);
    impl->name = name;
    impl->staging = impl->folder / ("." + name + ".partial");
    std::error_code ec;
    fs::create_directories(impl->folder, ec);
    if (ec || !fs::is_directory(impl->folder, ec))
        return makeError("cannot create output folder '" + folder + "': " + (ec ? ec.message() : std::string("a file of that name exists")));
    // A previous run's staging folder: finish its publish if it was complete, else drop it.
    if (fs::exists(impl->staging, ec)) {
        const std::vector<std::string> staged = readRecord(impl->staging / kCompleteFile);
        if (!staged.empty()) {
            if (Status s = publishStaged(impl->folder, name, impl->staging, staged); !s)
                return makeError("finishing an interrupted publish in '" + folder + "': " + s.error());
        } else {
            fs::remove_all(impl->staging, ec);
            if (ec) return makeError("cannot remove the unfinished staging folder '" + impl->staging.string() + "': " + ec.message());
        }
    }
    fs::create_directory(impl->staging, ec);
    if (ec) return makeError("cannot create staging folder '" + impl->staging.string() + "': " + ec.message());
    return OutputSet(std::move(impl));
}

OutputSet::OutputSet(std::unique_ptr<Impl> impl) : mImpl(std::move(impl)) {}
OutputSet::OutputSet(OutputSet&&) noexcept = default;
OutputSet& OutputSet::operator=(OutputSet&&) noexcept = default;
OutputSet::~OutputSet() {
    if (mImpl && !mImpl->published) {
        std::error_code ec;
        fs::remove_all(mImpl->staging, ec);
    }
}

std::string OutputSet::path(const std::string& file) const { return (mImpl->staging / file).string(); }
void OutputSet::add(const std::string& file) { mImpl->files.push_back(file); }
const std::string& OutputSet::folder() const {
    static_assert(sizeof(fs::path::value_type) == 1, "paths are narrow strings here");
    return mImpl->folder.native();
}
const std::vector<std::string>& OutputSet::files() const { return mImpl->files; }

Status OutputSet::publish() {
    Impl& p = *mImpl;
    for (const std::string& f : p.files)
        if (!plainName(f)) return makeError("output file '" + f + "' must be a plain file name");
    // Complete: from here a killed run is finished by the next begin().
    if (Status s = writeFileAtomically((p.staging / kCompleteFile).string(), recordText(p.files)); !s) return s;
    p.published = true;
    return publishStaged(p.folder, p.name, p.staging, p.files);
}

} // namespace splatfx
