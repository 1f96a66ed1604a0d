// Output sets (issue 13): published whole, never touching files they did not
// write, and a killed run finished or cleaned by the next.
#include <filesystem>
#include <fstream>

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
