// Output sets: lock, stage, mark complete, move, record (output_set.hpp says why).
#include "splatfx/output_set.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <system_error>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "splatfx/image_io.hpp"

namespace splatfx {

namespace fs = std::filesystem;

namespace {

constexpr const char* kRecordHeader = "splatfx-outputs 1";
constexpr const char* kCompleteFile = ".complete"; // inside the staging folder: the set is whole
// The folder's lock (checks, moves, records); not ".X.lock", which is the set X's.
constexpr const char* kFolderLock = ".splatfx-outputs-lock";
constexpr const char* kRecordSuffix = ".outputs";
constexpr const char* kStagingSuffix = ".partial";

// An error code's text, or `fallback` where the call failed without one
// (a message must never read "Success").
std::string reason(const std::error_code& ec, const char* fallback) { return ec ? ec.message() : std::string(fallback); }

bool endsWith(const std::string& s, const std::string& tail) {
    return s.size() > tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

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

// Every file some set of this folder wrote: the records of published sets
// and the completion marks of publishes cut short. `except` (a set's name)
// leaves that set's own record out.
std::set<std::string> recordedFiles(const fs::path& folder, const std::string& except = {}) {
    std::set<std::string> files;
    std::error_code ec;
    for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string n = it->path().filename().string();
        if (n.size() < 2 || n[0] != '.') continue;
        std::vector<std::string> listed;
        if (endsWith(n, kRecordSuffix) && n != "." + except + kRecordSuffix) listed = readRecord(it->path());
        else if (endsWith(n, kStagingSuffix)) listed = readRecord(it->path() / kCompleteFile);
        files.insert(listed.begin(), listed.end());
    }
    return files;
}

// The first of `files` that exists in the folder though no record lists it:
// a file the tool did not write, which it must not replace.
Status refuseForeign(const fs::path& folder, const std::vector<std::string>& files) {
    const std::set<std::string> ours = recordedFiles(folder);
    std::vector<std::string> foreign;
    for (const std::string& f : files) {
        std::error_code ec;
        if (plainName(f) && fs::symlink_status(folder / f, ec).type() != fs::file_type::not_found && !ours.count(f)) foreign.push_back(f);
    }
    if (foreign.empty()) return {};
    std::string list;
    for (std::size_t k = 0; k < foreign.size() && k < 4; ++k) list += (k ? ", '" : "'") + (folder / foreign[k]).string() + "'";
    if (foreign.size() > 4) list += " and " + std::to_string(foreign.size() - 4) + " more";
    const std::string it = foreign.size() > 1 ? "them" : "it";
    return makeError("refusing to overwrite " + list + ": no output record in '" + folder.string() + "' lists " + it + ", so splatfx did not write " +
                     it + "; move " + it + " away or choose another output folder");
}

// An exclusive flock on `path`, created if needed; -1 and `why` when it
// cannot be had (`busy` when another process holds it and wait is false).
// The file is removed by its holder on release, so a lock taken on a file
// that was meanwhile unlinked is retried on the file now at the path.
int takeLock(const fs::path& path, bool wait, bool& busy, std::string& why) {
    busy = false;
    for (;;) {
        const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
        if (fd < 0) {
            why = std::strerror(errno);
            return -1;
        }
        int r;
        while ((r = ::flock(fd, wait ? LOCK_EX : LOCK_EX | LOCK_NB)) != 0 && errno == EINTR) {}
        if (r != 0) {
            busy = errno == EWOULDBLOCK;
            why = busy ? "held by another process" : std::strerror(errno) + std::string(" (output sets need a file system with flock)");
            ::close(fd);
            return -1;
        }
        struct stat held {
        }, now{};
        if (::fstat(fd, &held) == 0 && ::stat(path.c_str(), &now) == 0 && held.st_dev == now.st_dev && held.st_ino == now.st_ino) return fd;
        ::close(fd); // released and removed while we waited: lock the new one
    }
}

void releaseLock(int& fd, const fs::path& path) {
    if (fd < 0) return;
    std::error_code ec;
    fs::remove(path, ec); // while still held: see takeLock
    ::close(fd);
    fd = -1;
}

// Who holds a set's lock, as its holder wrote it ("process N on HOST").
std::string lockHolder(const fs::path& path) {
    std::ifstream in(path);
    std::string line;
    std::getline(in, line);
    return line.empty() ? std::string() : " (" + line + ")";
}

struct FolderLock {
    fs::path path;
    int fd = -1;
    ~FolderLock() { releaseLock(fd, path); }
};

// Waits for the folder's lock: another set holds it only while it checks,
// moves and records its files.
Status lockFolder(const fs::path& folder, FolderLock& lock) {
    lock.path = folder / kFolderLock;
    bool busy = false;
    std::string why;
    lock.fd = takeLock(lock.path, true, busy, why);
    if (lock.fd < 0) return makeError("cannot lock the output folder '" + folder.string() + "' (" + lock.path.string() + "): " + why);
    return {};
}

// Moves a complete staged set into the folder and records it. With
// `resuming` (a publish cut short by a killed run), files already moved are
// skipped and files gone from both places are left out of the record, so
// running it again finishes the set; otherwise every file must be staged.
// Called with the folder locked.
Status publishStaged(const fs::path& folder, const std::string& name, const fs::path& staging, const std::vector<std::string>& staged,
                     bool resuming) {
    std::vector<std::string> files;
    for (const std::string& f : staged) {
        std::error_code ec;
        const fs::path from = staging / f, to = folder / f;
        if (fs::symlink_status(from, ec).type() == fs::file_type::not_found) {
            if (fs::is_regular_file(to, ec)) {
                if (resuming) files.push_back(f); // moved by the run that was cut short
                else return makeError("cannot publish '" + to.string() + "': it is missing from the staging folder '" + staging.string() + "'");
            } else if (!resuming) {
                return makeError("cannot publish '" + f + "': it is neither in the staging folder '" + staging.string() + "' nor in '" +
                                 folder.string() + "'");
            }
            continue;
        }
        ec.clear();
        fs::rename(from, to, ec);
        if (ec || !fs::is_regular_file(to, ec))
            return makeError("cannot move '" + f + "' into '" + folder.string() + "': " + reason(ec, "it is not there afterwards"));
        files.push_back(f);
    }
    // The previous set's files that this one does not replace, and only
    // those no other set's record lists (a farm task's frames a full run also wrote).
    const fs::path record = folder / ("." + name + kRecordSuffix);
    const std::set<std::string> keep(files.begin(), files.end());
    const std::set<std::string> others = recordedFiles(folder, name);
    std::error_code ec;
    for (const std::string& old : readRecord(record))
        if (!keep.count(old) && !others.count(old)) fs::remove(folder / old, ec);
    if (Status s = writeFileAtomically(record.string(), recordText(files)); !s) return s;
    fs::remove_all(staging, ec);
    return {};
}

} // namespace

struct OutputSet::Impl {
    fs::path folder;
    std::string name;
    fs::path staging;
    fs::path lockPath;
    int lock = -1;
    std::vector<std::string> files;
    bool published = false;

    ~Impl() {
        if (!published && !staging.empty()) {
            std::error_code ec;
            fs::remove_all(staging, ec);
        }
        releaseLock(lock, lockPath);
    }
};

Result<OutputSet> OutputSet::begin(const std::string& folder, const std::string& name, const std::vector<std::string>& planned) {
    if (!plainName(name)) return makeError("output name '" + name + "' must be a plain file name (no '/', not '.' or '..')");
    // An empty path is no folder; reading it as "." wrote into wherever the tool was started.
    if (folder.empty()) return makeError("the output folder is empty: name a folder ('.' for the current one)");
    auto impl = std::make_unique<Impl>();
    impl->folder = fs::path(folder);
    impl->name = name;
    std::error_code ec;
    fs::create_directories(impl->folder, ec);
    if (ec || !fs::is_directory(impl->folder, ec))
        return makeError("cannot create output folder '" + folder + "': " + (ec ? ec.message() : std::string("a file of that name exists")));

    // One writer per set: a second is refused at once, before any work.
    impl->lockPath = impl->folder / ("." + name + ".lock");
    bool busy = false;
    std::string why;
    impl->lock = takeLock(impl->lockPath, false, busy, why);
    if (impl->lock < 0) {
        if (busy)
            return makeError("output folder '" + folder + "' is in use: another render is writing the set '" + name + "' there" +
                             lockHolder(impl->lockPath) + "; wait for it to finish or give this run another output folder");
        return makeError("cannot lock the output set '" + name + "' in '" + folder + "' (" + impl->lockPath.string() + "): " + why);
    }
    char host[256] = {};
    if (::gethostname(host, sizeof host - 1) != 0) host[0] = '\0';
    const std::string holder = "process " + std::to_string(::getpid()) + (host[0] ? std::string(" on ") + host : std::string()) + "\n";
    if (::ftruncate(impl->lock, 0) == 0) {
        const ssize_t n = ::pwrite(impl->lock, holder.data(), holder.size(), 0);
        (void)n; // only informs a refused writer; the lock holds without it
    }
    // Not impl->staging until created: a failed begin() must not remove a
    // complete staging folder that a later run can still finish.
    const fs::path staging = impl->folder / ("." + name + kStagingSuffix);

    FolderLock folderLock;
    if (Status s = lockFolder(impl->folder, folderLock); !s) return makeError(s.error());
    // A previous run's staging folder: finish its publish if it was complete, else drop it.
    if (fs::exists(staging, ec)) {
        const std::vector<std::string> staged = readRecord(staging / kCompleteFile);
        if (!staged.empty()) {
            if (Status s = publishStaged(impl->folder, name, staging, staged, true); !s)
                return makeError("finishing an interrupted publish in '" + folder + "': " + s.error());
        } else {
            fs::remove_all(staging, ec);
            if (ec) return makeError("cannot remove the unfinished staging folder '" + staging.string() + "': " + ec.message());
        }
    }
    if (Status s = refuseForeign(impl->folder, planned); !s) return makeError(s.error());
    ec.clear();
    if (!fs::create_directory(staging, ec))
        return makeError("cannot create staging folder '" + staging.string() + "': " + reason(ec, "it exists after it was removed"));
    impl->staging = staging;
    return OutputSet(std::move(impl));
}

OutputSet::OutputSet(std::unique_ptr<Impl> impl) : mImpl(std::move(impl)) {}
OutputSet::OutputSet(OutputSet&&) noexcept = default;
OutputSet& OutputSet::operator=(OutputSet&&) noexcept = default;
OutputSet::~OutputSet() = default;

std::string OutputSet::path(const std::string& file) const { return (mImpl->staging / file).string(); }
void OutputSet::add(const std::string& file) { mImpl->files.push_back(file); }
const std::string& OutputSet::folder() const {
    static_assert(sizeof(fs::path::value_type) == 1, "paths are narrow strings here");
    return mImpl->folder.native();
}
const std::vector<std::string>& OutputSet::files() const { return mImpl->files; }

Status OutputSet::publish() {
    Impl& p = *mImpl;
    if (p.published) return makeError("output set '" + p.name + "' in '" + p.folder.string() + "' was already published");
    std::vector<std::string> unique;
    std::set<std::string> seen;
    for (const std::string& f : p.files)
        if (seen.insert(f).second) unique.push_back(f);
    p.files = std::move(unique);
    for (const std::string& f : p.files) {
        if (!plainName(f)) return makeError("output file '" + f + "' must be a plain file name");
        std::error_code ec;
        if (!fs::is_regular_file(p.staging / f, ec))
            return makeError("cannot publish '" + (p.folder / f).string() + "': it was added to the set but is not in the staging folder '" +
                             p.staging.string() + "'");
    }
    FolderLock folderLock;
    if (Status s = lockFolder(p.folder, folderLock); !s) return s;
    // A file that appeared while the set was rendered is refused too.
    if (Status s = refuseForeign(p.folder, p.files); !s) return s;
    // Complete: from here a killed run is finished by the next begin().
    if (Status s = writeFileAtomically((p.staging / kCompleteFile).string(), recordText(p.files)); !s) return s;
    p.published = true;
    if (Status s = publishStaged(p.folder, p.name, p.staging, p.files, false); !s) return s;
    releaseLock(p.lock, p.lockPath);
    return {};
}

} // namespace splatfx
