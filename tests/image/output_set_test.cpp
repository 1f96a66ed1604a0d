// Output sets: published whole, never touching files they did not write, a
// killed run finished or cleaned by the next, and a second writer refused.
#include <csignal>
#include <filesystem>
#include <fstream>

#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "gl_fixture.hpp"
#include "splatfx/image_io.hpp"
#include "splatfx/output_set.hpp"

using namespace splatfx;
namespace fs = std::filesystem;

namespace {

fs::path freshFolder(const std::string& name) {
    const fs::path p = fs::path(test::outputDir()) / name;
    fs::remove_all(p);
    return p;
}

void writeText(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }
std::string readText(const fs::path& p) {
    std::ifstream in(p);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

} // namespace

TEST(OutputSet, PublishesTheWholeSetAndRecordsIt) {
    const fs::path dir = freshFolder("publish");
    auto out = OutputSet::begin(dir.string(), "shot");
    ASSERT_TRUE(out) << out.error();
    for (const char* f : {"shot_0000.txt", "shot_0001.txt"}) {
        ASSERT_TRUE(writeFileAtomically(out->path(f), f));
        out->add(f);
        EXPECT_FALSE(fs::exists(dir / f)) << "nothing is in the folder before publish()";
    }
    ASSERT_TRUE(out->publish());
    EXPECT_EQ(readText(dir / "shot_0000.txt"), "shot_0000.txt");
    EXPECT_EQ(readText(dir / "shot_0001.txt"), "shot_0001.txt");
    EXPECT_FALSE(fs::exists(dir / ".shot.partial"));
    EXPECT_EQ(readText(dir / ".shot.outputs"), "splatfx-outputs 1\nshot_0000.txt\nshot_0001.txt\n");
}

TEST(OutputSet, ReplacesOnlyWhatItWrote) {
    const fs::path dir = freshFolder("replace");
    {
        auto out = OutputSet::begin(dir.string(), "shot");
        ASSERT_TRUE(out);
        for (const char* f : {"shot_0000.txt", "shot_0001.txt", "shot_0002.txt"}) {
            ASSERT_TRUE(writeFileAtomically(out->path(f), "old"));
            out->add(f);
        }
        ASSERT_TRUE(out->publish());
    }
    writeText(dir / "shot_0009.txt", "the user's, named like ours");
    writeText(dir / "t_logo.png", "the user's");
    auto out = OutputSet::begin(dir.string(), "shot");
    ASSERT_TRUE(out);
    ASSERT_TRUE(writeFileAtomically(out->path("shot_0000.txt"), "new"));
    out->add("shot_0000.txt");
    ASSERT_TRUE(out->publish());
    EXPECT_EQ(readText(dir / "shot_0000.txt"), "new");
    EXPECT_FALSE(fs::exists(dir / "shot_0001.txt")) << "the previous set's extra files go";
    EXPECT_FALSE(fs::exists(dir / "shot_0002.txt"));
    EXPECT_EQ(readText(dir / "shot_0009.txt"), "the user's, named like ours") << "never delete what the tool did not write";
    EXPECT_EQ(readText(dir / "t_logo.png"), "the user's");
}

TEST(OutputSet, AnUnpublishedSetLeavesNothingAndThePreviousSetStands) {
    const fs::path dir = freshFolder("unpublished");
    {
        auto out = OutputSet::begin(dir.string(), "shot");
        ASSERT_TRUE(out);
        ASSERT_TRUE(writeFileAtomically(out->path("shot_0000.txt"), "complete"));
        out->add("shot_0000.txt");
        ASSERT_TRUE(out->publish());
    }
    {
        auto out = OutputSet::begin(dir.string(), "shot");
        ASSERT_TRUE(out);
        ASSERT_TRUE(writeFileAtomically(out->path("shot_0000.txt"), "half a run"));
        out->add("shot_0000.txt");
        // A failed run returns without publish().
    }
    EXPECT_EQ(readText(dir / "shot_0000.txt"), "complete");
    EXPECT_FALSE(fs::exists(dir / ".shot.partial"));
}

// What a run killed inside publish() leaves: a staging folder marked complete
// with some files already moved. The next begin() finishes the move first.
TEST(OutputSet, APublishCutShortIsFinishedByTheNextRun) {
    const fs::path dir = freshFolder("killed_publish");
    fs::create_directories(dir / ".shot.partial");
    writeText(dir / "shot_0000.txt", "new (moved before the kill)");
    writeText(dir / ".shot.partial/shot_0001.txt", "new (not yet moved)");
    writeText(dir / "shot_0005.txt", "old set");
    writeText(dir / ".shot.outputs", "splatfx-outputs 1\nshot_0000.txt\nshot_0005.txt\n");
    writeText(dir / ".shot.partial/.complete", "splatfx-outputs 1\nshot_0000.txt\nshot_0001.txt\n");
    auto next = OutputSet::begin(dir.string(), "shot");
    ASSERT_TRUE(next) << next.error();
    EXPECT_EQ(readText(dir / "shot_0001.txt"), "new (not yet moved)");
    EXPECT_FALSE(fs::exists(dir / "shot_0005.txt")) << "the old set's file not in the new set goes";
    EXPECT_EQ(readText(dir / ".shot.outputs"), "splatfx-outputs 1\nshot_0000.txt\nshot_0001.txt\n");
}

// A run killed before publish(): its staging folder has no completion mark,
// so the next run removes it and the published set is untouched.
TEST(OutputSet, AStagingFolderOfAKilledRunIsRemovedByTheNextRun) {
    const fs::path dir = freshFolder("killed_run");
    fs::create_directories(dir / ".shot.partial");
    writeText(dir / ".shot.partial/shot_0000.txt", "half written");
    writeText(dir / "shot_0000.txt", "published");
    auto next = OutputSet::begin(dir.string(), "shot");
    ASSERT_TRUE(next);
    EXPECT_EQ(readText(dir / "shot_0000.txt"), "published");
    EXPECT_FALSE(fs::exists(dir / ".shot.partial/shot_0000.txt"));
}

TEST(OutputSet, RefusesNamesThatAreNotPlainFileNames) {
    for (const char* bad : {"", "a/b", "..", "."}) {
        auto out = OutputSet::begin(freshFolder("names").string(), bad);
        ASSERT_FALSE(out) << bad;
        EXPECT_NE(out.error().find("must be a plain file name"), std::string::npos) << out.error();
    }
}

// Two writers of one set (two renders into one folder, a farm mistake): the
// second is refused at once, naming the folder, and the first publishes its
// whole set. The holder is another process, as on a farm.
TEST(OutputSet, ASecondWriterOfTheSameSetIsRefusedAndTheFirstPublishesWhole) {
    const fs::path dir = freshFolder("two_writers");
    int ready[2], go[2];
    ASSERT_EQ(pipe(ready), 0);
    ASSERT_EQ(pipe(go), 0);
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) { // the first writer: holds the set until told to publish
        auto out = OutputSet::begin(dir.string(), "shot", {"shot_0000.txt", "shot_0001.txt"});
        char c = out ? 'y' : 'n';
        if (write(ready[1], &c, 1) != 1 || read(go[0], &c, 1) != 1 || !out) _exit(2);
        for (const char* f : {"shot_0000.txt", "shot_0001.txt"}) {
            if (!writeFileAtomically(out->path(f), "first")) _exit(3);
            out->add(f);
        }
        _exit(out->publish() ? 0 : 4);
    }
    char c = 0;
    ASSERT_EQ(read(ready[0], &c, 1), 1);
    ASSERT_EQ(c, 'y');
    {
        auto second = OutputSet::begin(dir.string(), "shot", {"shot_0000.txt"});
        ASSERT_FALSE(second) << "a second writer of the set must be refused";
        EXPECT_NE(second.error().find("output folder '" + dir.string() + "' is in use: another render is writing the set 'shot' there (process " +
                                      std::to_string(pid)),
                  std::string::npos)
            << second.error();
    }
    EXPECT_TRUE(fs::is_directory(dir / ".shot.partial")) << "the refused writer must not touch the first one's staging";
    ASSERT_EQ(write(go[1], "g", 1), 1);
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
    EXPECT_EQ(readText(dir / "shot_0000.txt"), "first");
    EXPECT_EQ(readText(dir / "shot_0001.txt"), "first");
    EXPECT_EQ(readText(dir / ".shot.outputs"), "splatfx-outputs 1\nshot_0000.txt\nshot_0001.txt\n");
    EXPECT_FALSE(fs::exists(dir / ".shot.lock")) << "a released lock leaves no file";
    // Once released, the set is free again.
    auto later = OutputSet::begin(dir.string(), "shot");
    EXPECT_TRUE(later) << later.error();
    for (int fd : {ready[0], ready[1], go[0], go[1]}) close(fd);
}

// A writer killed while it holds the set: the kernel drops its lock, so the
// next run is not refused, and it removes the dead run's staging folder.
TEST(OutputSet, AKilledWritersLockDiesWithIt) {
    const fs::path dir = freshFolder("killed_writer");
    int ready[2];
    ASSERT_EQ(pipe(ready), 0);
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        auto out = OutputSet::begin(dir.string(), "shot");
        if (!out || !writeFileAtomically(out->path("shot_0000.txt"), "half")) _exit(2);
        if (write(ready[1], "y", 1) != 1) _exit(3);
        pause();
        _exit(0);
    }
    char c = 0;
    ASSERT_EQ(read(ready[0], &c, 1), 1);
    kill(pid, SIGKILL);
    waitpid(pid, nullptr, 0);
    auto next = OutputSet::begin(dir.string(), "shot");
    ASSERT_TRUE(next) << next.error();
    EXPECT_FALSE(fs::exists(dir / ".shot.partial/shot_0000.txt"));
    close(ready[0]), close(ready[1]);
}

// A set never replaces a file that no record lists (the user's own, named
// like an output): refused before any work when begin() is told the names,
// and at publish() for one that appears meanwhile. Nothing is lost.
TEST(OutputSet, NeverOverwritesAFileNoRecordLists) {
    const fs::path dir = freshFolder("foreign");
    fs::create_directories(dir);
    writeText(dir / "t_0000.png", "the user's frame");
    writeText(dir / "t.gif", "the user's GIF");
    {
        auto out = OutputSet::begin(dir.string(), "t", {"t_0000.png", "t_0001.png", "t.gif"});
        ASSERT_FALSE(out);
        EXPECT_NE(out.error().find("refusing to overwrite '" + (dir / "t_0000.png").string() + "', '" + (dir / "t.gif").string() +
                                   "': no output record in '" + dir.string() + "' lists them, so splatfx did not write them"),
                  std::string::npos)
            << out.error();
    }
    {
        auto out = OutputSet::begin(dir.string(), "t"); // not told the names: publish() still checks
        ASSERT_TRUE(out) << out.error();
        ASSERT_TRUE(writeFileAtomically(out->path("t_0001.png"), "ours"));
        out->add("t_0001.png");
        ASSERT_TRUE(writeFileAtomically(out->path("t.gif"), "ours"));
        out->add("t.gif");
        const Status s = out->publish();
        ASSERT_FALSE(s);
        EXPECT_NE(s.error().find("refusing to overwrite '" + (dir / "t.gif").string() + "': no output record"), std::string::npos) << s.error();
    }
    EXPECT_EQ(readText(dir / "t_0000.png"), "the user's frame");
    EXPECT_EQ(readText(dir / "t.gif"), "the user's GIF");
    EXPECT_FALSE(fs::exists(dir / "t_0001.png")) << "a refused set publishes nothing";
    EXPECT_FALSE(fs::exists(dir / ".t.partial"));
    EXPECT_FALSE(fs::exists(dir / ".t.outputs"));
}

// Files another set of the folder wrote (a farm task's frames, which a full
// run or a retried task writes again) may be replaced, and are not removed
// when the set that also wrote them drops them.
TEST(OutputSet, FilesAnotherSetRecordedAreSharedNotForeign) {
    const fs::path dir = freshFolder("shared");
    auto publish = [&](const std::string& set, std::vector<std::string> files, const std::string& text) {
        auto out = OutputSet::begin(dir.string(), set, files);
        if (!out) return Status(makeError(out.error()));
        for (const std::string& f : files) {
            if (Status s = writeFileAtomically(out->path(f), text); !s) return s;
            out->add(f);
        }
        return out->publish();
    };
    ASSERT_TRUE(publish("s.frames-0000-0001", {"s_0000.png", "s_0001.png"}, "task"));
    Status s = publish("s", {"s_0000.png", "s_0001.png", "s_0002.png"}, "full");
    ASSERT_TRUE(s) << s.error();
    EXPECT_EQ(readText(dir / "s_0001.png"), "full");
    s = publish("s", {"s_0000.png"}, "full, shorter");
    ASSERT_TRUE(s) << s.error();
    EXPECT_FALSE(fs::exists(dir / "s_0002.png")) << "only the full run wrote it";
    EXPECT_EQ(readText(dir / "s_0001.png"), "full") << "the task's record still lists it: kept";
}

// A file added to the set but gone from the staging folder (how two writers
// sharing one staging folder published 31 of 40 frames and exited 0): the
// publish fails naming it, and the previous set stands.
TEST(OutputSet, APublishShortOfAFileFailsNamingIt) {
    const fs::path dir = freshFolder("short");
    {
        auto out = OutputSet::begin(dir.string(), "shot");
        ASSERT_TRUE(out);
        ASSERT_TRUE(writeFileAtomically(out->path("shot_0000.txt"), "old"));
        out->add("shot_0000.txt");
        ASSERT_TRUE(out->publish());
    }
    auto out = OutputSet::begin(dir.string(), "shot");
    ASSERT_TRUE(out);
    for (const char* f : {"shot_0000.txt", "shot_0001.txt"}) {
        ASSERT_TRUE(writeFileAtomically(out->path(f), "new"));
        out->add(f);
    }
    fs::remove(out->path("shot_0001.txt"));
    const Status s = out->publish();
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().find("cannot publish '" + (dir / "shot_0001.txt").string() + "': it was added to the set but is not in the staging folder"),
              std::string::npos)
        << s.error();
    EXPECT_EQ(readText(dir / "shot_0000.txt"), "old");
    EXPECT_EQ(readText(dir / ".shot.outputs"), "splatfx-outputs 1\nshot_0000.txt\n");
}

// An empty folder name is no folder (it wrote into the current directory).
TEST(OutputSet, AnEmptyFolderIsRefused) {
    auto out = OutputSet::begin("", "shot");
    ASSERT_FALSE(out);
    EXPECT_NE(out.error().find("the output folder is empty"), std::string::npos) << out.error();
    EXPECT_FALSE(fs::exists(".shot.partial"));
    EXPECT_FALSE(fs::exists(".shot.lock"));
}

// A failed move says why (it read "cannot move ...: Success": the clean-up's
// result had replaced the error).
TEST(OutputSet, AFailedMoveSaysWhy) {
    const fs::path dir = freshFolder("failed_move");
    fs::create_directories(dir / "target" / "inside"); // rename(file, non-empty folder) fails
    const Status s = writeFileAtomically((dir / "target").string(), "bytes");
    ASSERT_FALSE(s);
    EXPECT_EQ(s.error().find("Success"), std::string::npos) << s.error();
    EXPECT_NE(s.error().find("Is a directory"), std::string::npos) << s.error();
}

// A publish cut short that cannot be finished yet (a folder stands where a
// file goes): begin() fails saying why and keeps the complete staging folder,
// so a later run can still finish it.
TEST(OutputSet, AnUnfinishablePublishKeepsItsStagingFolder) {
    const fs::path dir = freshFolder("unfinishable");
    fs::create_directories(dir / ".shot.partial");
    fs::create_directories(dir / "shot_0000.txt" / "inside");
    writeText(dir / ".shot.partial/shot_0000.txt", "complete, not yet moved");
    writeText(dir / ".shot.partial/.complete", "splatfx-outputs 1\nshot_0000.txt\n");
    {
        auto next = OutputSet::begin(dir.string(), "shot");
        ASSERT_FALSE(next);
        EXPECT_NE(next.error().find("finishing an interrupted publish in '" + dir.string() + "': cannot move 'shot_0000.txt'"), std::string::npos)
            << next.error();
        EXPECT_EQ(next.error().find("Success"), std::string::npos) << next.error();
    }
    EXPECT_EQ(readText(dir / ".shot.partial/shot_0000.txt"), "complete, not yet moved");
    fs::remove_all(dir / "shot_0000.txt");
    auto later = OutputSet::begin(dir.string(), "shot");
    ASSERT_TRUE(later) << later.error();
    EXPECT_EQ(readText(dir / "shot_0000.txt"), "complete, not yet moved");
}
