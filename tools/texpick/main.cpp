// splatfx-texpick: cut a texture set for splatfx out of a photograph. See docs/texpick.md.
#include <cstdio>

#include "cli.hpp"
#include "texpick.hpp"

int main(int argc, char** argv) {
    return cli::guardedMain(texpick::kToolName, [&] {
        auto options = texpick::parseOptions(argc, argv);
        if (!options) {
            // An empty message means --help was printed.
            if (options.error().empty()) return 0;
            std::fprintf(stderr, "%s: %s\n", texpick::kToolName, options.error().c_str());
            return 2;
        }
        return texpick::run(*options);
    });
}
