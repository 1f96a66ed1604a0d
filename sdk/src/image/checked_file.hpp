// Output files whose every write is checked (private to the image module).
//
// OpenImageIO's writers ignore a failed write (a full disk gives a truncated
// or empty file and a successful close()), so every image and animation goes
// through CheckedFile: an OpenImageIO IOProxy over a file descriptor that
// records the first failed write, and a finish() that fsyncs and closes and
// reports it. Files are written under a temporary name beside the target and
// renamed into place only when complete (publishTemporary).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include <OpenImageIO/filesystem.h>

#include "splatfx/result.hpp"

namespace splatfx::detail {

class CheckedFile final : public OIIO::Filesystem::IOProxy {
public:
    // Creates (truncates) path for writing. On failure returns null and sets why.
    static std::unique_ptr<CheckedFile> create(const std::string& path, std::string& why);
    ~CheckedFile() override;

    const char* proxytype() const override { return "splatfx-checked"; }
    size_t write(const void* buf, size_t size) override;
    size_t pwrite(const void* buf, size_t size, int64_t offset) override;
    bool seek(int64_t offset) override;
    size_t size() const override { return std::size_t(mSize); }
    void close() override {} // finish() closes: OpenImageIO's close must not hide a failure

    // fsync and close; the first failed write, fsync or close, or OK.
    Status finish();
    const std::string& path() const { return mPath; }

private:
    CheckedFile(int fd, std::string path);
    int mFd = -1;
    std::string mPath;
    std::int64_t mSize = 0;
    std::string mFailure; // the first failure, with strerror
};

// The temporary name beside target used while it is written: hidden, and
// unique to this process.
std::string temporaryNameFor(const std::string& target);
// Renames tmp onto target and fsyncs the folder; removes tmp on failure.
Status publishTemporary(const std::string& tmp, const std::string& target);

} // namespace splatfx::detail
