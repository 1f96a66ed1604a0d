// splatfx/output_set.hpp: a set of output files published into a folder as one unit (splatfx::io).
//
// A render writes many files (frames and an animation, say) that only make
// sense together. OutputSet stages them in a hidden folder beside their
// destination, DIR/.NAME.partial/, and publish() moves them into DIR when the
// whole set is written: each file is checked and complete (write it with
// writeImage / AnimationWriter / writeFileAtomically), and the previous run's
// set stays intact until then. A record, DIR/.NAME.outputs, lists the files
// of the last published set, so a later run removes only files this tool
// wrote (a user's own files in DIR are never touched) and knows what belongs
// together. A run killed before publish() leaves only its staging folder; the
// next begin() for the same name removes it. A run killed during publish()
// (after the set was marked complete) is finished by the next begin(), which
// moves the rest of that set into place first, so a folder never stays mixed.
//
// Two writers cannot corrupt a folder. A set holds DIR/.NAME.lock (flock)
// from begin() to publish(), so a second writer of the same set is refused at
// once, naming the folder. Sets of one folder that differ in name (a render
// farm's range tasks) run at the same time; each checks and moves its files
// under the folder's lock, DIR/.splatfx-outputs-lock, held for milliseconds.
// A file is replaced only if a record in DIR lists it: a file of that name
// that no set wrote is refused, named, at begin() (for the files it is told
// of) and again at publish(). Both locks are removed when released; the
// kernel drops them when a writer dies. Locks need a file system with
// flock (local disks and NFSv4 do; where flock fails, begin() says so).
//
//   auto out = splatfx::OutputSet::begin("out/cow", "cow", {"cow_0000.png"});
//   splatfx::writeImage(out->path("cow_0000.png"), img); out->add("cow_0000.png");
//   if (auto s = out->publish(); !s) fail(s.error());
//
// Threading: one thread at a time per object. Move-only.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "splatfx/result.hpp"

namespace splatfx {

class OutputSet {
public:
    // Creates DIR (and parents) if needed, takes the set's lock (refused at
    // once if another writer holds it) and a fresh staging folder, after
    // finishing or removing a previous run's. `name` is a plain file-name
    // stem (no '/', not "." or ".."); `folder` may not be empty. `planned`:
    // the files the set will hold, checked now so that a run refuses before
    // its work, not after, to overwrite a file no record lists. Errors name
    // the folder (and the file) and the reason.
    static Result<OutputSet> begin(const std::string& folder, const std::string& name, const std::vector<std::string>& planned = {});
    OutputSet(OutputSet&&) noexcept;
    OutputSet& operator=(OutputSet&&) noexcept;
    // Without publish(): removes the staging folder and everything in it.
    ~OutputSet();

    // Where to write `file` (a plain file name) before publish().
    std::string path(const std::string& file) const;
    // Records `file` as part of the set; expects it written at path(file).
    void add(const std::string& file);
    // Checks that every added file is staged and that none would replace a
    // file no record lists, then moves the set into the folder, removes the
    // previous set's files that are not in this one (unless another set's
    // record lists them), writes the record and releases the lock. On
    // failure the message says which file; the next begin() finishes a move
    // that had started. Never succeeds with a file of the set missing.
    Status publish();

    const std::string& folder() const;
    const std::vector<std::string>& files() const;

private:
    struct Impl;
    explicit OutputSet(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> mImpl;
};

} // namespace splatfx
