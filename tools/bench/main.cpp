// splatfx-bench: benchmarks with the commands that reproduce docs/BENCHMARKS.md.
#include <cstdio>
#include <cstring>

#include "cli.hpp"
#include "commands.hpp"

namespace {
void usage() {
    std::printf("usage: splatfx-bench <command> [options]   (splatfx-bench <command> --help for its options)\n\ncommands:\n");
    for (const BenchCommand& c : kCommands) std::printf("  %-12s %s\n", c.name, c.summary);
}

int benchMain(int argc, char** argv) {
    if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h")) {
        usage();
        return argc < 2 ? 2 : 0;
    }
    for (const BenchCommand& c : kCommands)
        if (!std::strcmp(argv[1], c.name)) return c.run(argc - 1, argv + 1);
    std::fprintf(stderr, "splatfx-bench: unknown command '%s'\n", argv[1]);
    usage();
    return 2;
}
} // namespace

// Any exception a benchmark lets escape (std::bad_alloc from a size the
// machine cannot hold) becomes a message and exit code 1, not an abort.
int main(int argc, char** argv) {
    return cli::guardedMain("splatfx-bench", [&] { return benchMain(argc, argv); });
}
