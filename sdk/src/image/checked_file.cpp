#include "checked_file.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace splatfx::detail {

namespace fs = std::filesystem;

std::unique_ptr<CheckedFile> CheckedFile::create(const std::string& path, std::string& why) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) {
        why = std::strerror(errno);
        return nullptr;
    }
    return std::unique_ptr<CheckedFile>(new CheckedFile(fd, path));
}

CheckedFile::CheckedFile(int fd, std::string path) : IOProxy(path, Write), mFd(fd), mPath(std::move(path)) {}

CheckedFile::~CheckedFile() {
    if (mFd >= 0) ::close(mFd);
}

size_t CheckedFile::pwrite(const void* buf, size_t size, int64_t offset) {
    if (!mFailure.empty() || mFd < 0) return 0;
    const char* p = static_cast<const char*>(buf);
    size_t done = 0;
    while (done < size) {
        const ssize_t n = ::pwrite(mFd, p + done, size - done, off_t(offset + std::int64_t(done)));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            mFailure = n < 0 ? std::strerror(errno) : "the device accepted no more bytes";
            break;
        }
        done += size_t(n);
    }
    mSize = std::max(mSize, offset + std::int64_t(done));
    return done;
}

size_t CheckedFile::write(const void* buf, size_t size) {
    const size_t n = pwrite(buf, size, m_pos);
    m_pos += std::int64_t(n);
    return n;
}

bool CheckedFile::seek(int64_t offset) {
    if (offset < 0) return false;
    m_pos = offset;
    return true;
}

Status CheckedFile::finish() {
    if (mFd >= 0) {
        if (mFailure.empty() && ::fsync(mFd) != 0) mFailure = std::strerror(errno);
        if (::close(mFd) != 0 && mFailure.empty()) mFailure = std::strerror(errno);
        mFd = -1;
    }
    if (!mFailure.empty()) return makeError("writing '" + mPath + "' failed: " + mFailure);
    return {};
}

std::string temporaryNameFor(const std::string& target) {
    const fs::path t(target);
    // Keep the extension: OpenImageIO picks the format from it.
    std::string name = ".tmp-";
    name += t.stem().string();
    name += "-";
    name += std::to_string(::getpid());
    name += t.extension().string();
    return (t.parent_path() / name).string();
}

Status publishTemporary(const std::string& tmp, const std::string& target) {
    std::error_code ec;
    fs::rename(tmp, target, ec);
    if (ec) {
        const std::string why = ec.message(); // before the clean-up's result replaces it (it read "Success")
        fs::remove(tmp, ec);
        return makeError("cannot move '" + tmp + "' to '" + target + "': " + why);
    }
    // The rename is durable only once the folder is synced.
    const fs::path parent = fs::path(target).parent_path();
    const int dir = ::open(parent.empty() ? "." : parent.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dir >= 0) {
        ::fsync(dir);
        ::close(dir);
    }
    return {};
}

} // namespace splatfx::detail
