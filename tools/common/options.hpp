// tools/common/options.hpp: the tools' command lines through CLI11, with the
// strict checks of cli.hpp.
//
// What it is: options whose values go through cli::parseInt, parseReal,
// parseSize, a table of names or any check returning a splatfx::Status, so every number is
// parsed whole and range-checked and a bad one is refused with the message
// docs/ERRORS.md promises ("--frames expects a whole number in [5, 100000],
// got '12abc'"); CLI11's own conversions (which accept "0x10", "010" as
// octal and "true" as 1) never see them. parse() runs the parser and turns
// --help and errors into an exit code.
// What it does not do: option tables beyond CLI11's (each tool builds its
// own CLI::App), locale handling (numbers are C-locale).
//
//   CLI::App app{"A level of N effects ...", "splatfx-bench scheduling"};
//   cli::addNumber(app, "--effects", count, 20, 100000, "effects in the level");
//   if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
//
// Threading: build and parse on one thread; the options write into the
// caller's variables, which must outlive parse().
#pragma once

#include <algorithm>
#include <concepts>
#include <cstdio>
#include <functional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli.hpp"

namespace cli {

// "--frames" from CLI11's name list ("-f,--frames"): the spelling messages use.
inline std::string longName(const std::string& names) {
    const size_t comma = names.rfind(',');
    return comma == std::string::npos ? names : names.substr(comma + 1);
}

// An option taking one value that check(option, text) accepts (stores) or
// refuses with a message, which is printed as it is.
inline CLI::Option* addChecked(CLI::App& app, const std::string& names, std::function<splatfx::Status(const std::string&, const std::string&)> check,
                               const std::string& help, const std::string& typeName = "VALUE") {
    const std::string option = longName(names);
    CLI::Option* o = app.add_option_function<std::string>(
        names,
        [option, check = std::move(check)](const std::string& text) {
            if (splatfx::Status s = check(option, text); !s) throw CLI::ValidationError(s.error());
        },
        help);
    o->type_name(typeName)->multi_option_policy(CLI::MultiOptionPolicy::TakeLast); // given twice: the last wins
    return o;
}

// A whole number (integral T: cli::parseInt) or a finite number
// (floating-point T: cli::parseReal) in [lo, hi]; the help shows the range
// and the default.
template <class T>
requires std::integral<T> || std::floating_point<T> CLI::Option*
addNumber(CLI::App& app, const std::string& names, T& out, std::type_identity_t<T> lo, std::type_identity_t<T> hi, const std::string& help) {
    const std::string range = " [" + detail::show(lo) + ", " + detail::show(hi) + "], default " + detail::show(out);
    auto check = [&out, lo, hi](const std::string& option, const std::string& text) {
        if constexpr (std::is_integral_v<T>) return parseInt(option, text, lo, hi, out);
        else return parseReal(option, text, lo, hi, out);
    };
    return addChecked(app, names, check, help + range, std::is_integral_v<T> ? "N" : "X");
}

// One of a few names, each standing for a value of `out`; any other text is
// refused as "<refusal>, got '<text>'" (refusal e.g. "--alpha expects auto,
// coverage or density").
template <class T>
CLI::Option* addOneOf(CLI::App& app, const std::string& names, T& out, std::vector<std::pair<std::string, T>> table, const std::string& refusal,
                      const std::string& help) {
    auto check = [&out, table = std::move(table), refusal](const std::string&, const std::string& text) -> splatfx::Status {
        for (const auto& [name, value] : table)
            if (name == text) {
                out = value;
                return {};
            }
        return splatfx::makeError(refusal + ", got " + detail::quoted(text));
    };
    return addChecked(app, names, check, help, "NAME");
}

// "WxH", each side a whole number in [lo, hi] (cli::parseSize).
inline CLI::Option* addSize(CLI::App& app, const std::string& names, int& width, int& height, int lo, int hi, const std::string& help) {
    const std::string range =
        " (each side in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]), default " + std::to_string(width) + "x" + std::to_string(height);
    return addChecked(
        app, names,
        [&width, &height, lo, hi](const std::string& option, const std::string& text) { return parseSize(option, text, lo, hi, width, height); },
        help + range, "WxH");
}

// `count` (1 to 4) whole numbers in [lo, hi] after one option ("--dims X Y Z",
// "--size W H"), each checked as cli::parseInt checks one.
inline CLI::Option* addInts(CLI::App& app, const std::string& names, int* values, int count, int lo, int hi, const std::string& help,
                            const std::string& typeName) {
    const std::string option = longName(names);
    std::string defaults;
    for (int k = 0; k < count; ++k) defaults += (k ? " " : "") + std::to_string(values[k]);
    CLI::Option* o = app.add_option_function<std::vector<std::string>>(
        names,
        [option, values, count, lo, hi](const std::vector<std::string>& texts) {
            int parsed[4] = {};
            for (int k = 0; k < count; ++k)
                if (splatfx::Status s = parseInt(option, texts[size_t(k)], lo, hi, parsed[k]); !s) throw CLI::ValidationError(s.error());
            std::copy(parsed, parsed + count, values);
        },
        help + " (each in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]), default " + defaults);
    o->expected(count)->type_name(typeName)->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
    return o;
}

// Parses argv (argv[0] is the program or subcommand name). Returns -1 when the
// caller goes on; 0 after printing the help (--help, -h); 2 after printing
// "<name>: <why> (try --help)" on stderr, name being the app's.
inline int parse(CLI::App& app, int argc, const char* const* argv) {
    try {
        app.parse(argc, argv);
        return -1;
    } catch (const CLI::CallForHelp&) {
        std::fputs(app.help().c_str(), stdout);
        return 0;
    } catch (const CLI::CallForAllHelp&) {
        std::fputs(app.help("", CLI::AppFormatMode::All).c_str(), stdout);
        return 0;
    } catch (const CLI::ParseError& e) {
        std::fprintf(stderr, "%s: %s (try --help)\n", app.get_name().c_str(), e.what());
        return 2;
    }
}

} // namespace cli
