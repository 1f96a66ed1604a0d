// samples/common/sample_options.hpp: the samples' command-line options, through CLI11.
//
// Numbers are read whole and range-checked by the samples themselves: a bad
// one is refused with a message naming the option, its range and the text
// ("--frames expects a whole number in [1, 100000], got '12abc'"). CLI11's
// own number conversion is not used for them: it reads "010" as octal,
// "0x10" as hex and "true" as 1. Samples use the public SDK API only; this
// header needs nothing from tools/.
//
//   CLI::App app{"the paper's fire", "campfire"};
//   samples::addNumber(app, "--frames", frames, 1, 100000, "frames to render headless");
//   if (const int code = samples::parseCommandLine(app, argc, argv); code >= 0) return code;
//
// Threading: build and parse on one thread.
#pragma once

#include <charconv>
#include <cmath>
#include <cstdio>
#include <exception>
#include <new>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>

#include <CLI/CLI.hpp>

namespace samples {

namespace option_text {
template <class T>
std::string show(T value) {
    if constexpr (std::is_integral_v<T>) return std::to_string(value);
    char digits[32];
    std::snprintf(digits, sizeof digits, "%g", double(value));
    return digits;
}

// The whole text as one T (an optional '+'; a finite value for floating point).
template <class T>
bool readAll(std::string_view text, T& value) {
    if (text.size() > 1 && text.front() == '+' && text[1] != '-') text.remove_prefix(1);
    if (text.empty() || text.front() == ' ' || text.front() == '+') return false;
    const char* end = text.data() + text.size();
    std::from_chars_result r{};
    if constexpr (std::is_floating_point_v<T>) r = std::from_chars(text.data(), end, value, std::chars_format::general);
    else r = std::from_chars(text.data(), end, value, 10);
    if constexpr (std::is_floating_point_v<T>)
        if (!std::isfinite(value)) return false;
    return r.ec == std::errc() && r.ptr == end;
}
} // namespace option_text

// A whole number (integral T) or a finite number (floating-point T) in [lo, hi].
template <class T>
CLI::Option* addNumber(CLI::App& app, const std::string& name, T& out, std::type_identity_t<T> lo, std::type_identity_t<T> hi,
                       const std::string& help) {
    const std::string expects = name + (std::is_integral_v<T> ? " expects a whole number in [" : " expects a number in [") + option_text::show(lo) +
                                ", " + option_text::show(hi) + "], got '";
    CLI::Option* option = app.add_option_function<std::string>(
        name,
        [&out, expects, lo, hi](const std::string& text) {
            T value{};
            if (!option_text::readAll(text, value) || value < lo || value > hi) throw CLI::ValidationError(expects + text + "'");
            out = value;
        },
        help + " (" + option_text::show(lo) + " to " + option_text::show(hi) + ", default " + option_text::show(out) + ")");
    option->type_name(std::is_integral_v<T> ? "N" : "X")->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
    return option;
}

// "WxH", each side a whole number in [lo, hi].
inline CLI::Option* addSize(CLI::App& app, const std::string& name, int& width, int& height, int lo, int hi, const std::string& help) {
    const std::string expects =
        name + " expects WxH with each side a whole number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got '";
    CLI::Option* option = app.add_option_function<std::string>(
        name,
        [&width, &height, expects, lo, hi](const std::string& text) {
            const size_t x = text.find('x');
            int w = 0, h = 0;
            if (x == std::string::npos || !option_text::readAll(std::string_view(text).substr(0, x), w) ||
                !option_text::readAll(std::string_view(text).substr(x + 1), h) || w < lo || w > hi || h < lo || h > hi)
                throw CLI::ValidationError(expects + text + "' (e.g. 640x480)");
            width = w;
            height = h;
        },
        help + " (default " + std::to_string(width) + "x" + std::to_string(height) + ")");
    option->type_name("WxH")->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
    return option;
}

// Parses argv: -1 when the sample goes on; 0 after printing the help; 2
// after printing "<sample>: <why> (try --help)" (CLI11's App::exit prints both).
inline int parseCommandLine(CLI::App& app, int argc, const char* const* argv) {
    app.failure_message([](const CLI::App* failed, const CLI::Error& e) { return failed->get_name() + ": " + e.what() + " (try --help)\n"; });
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) { return app.exit(e) == 0 ? 0 : 2; }
    return -1;
}

// Runs body() (the exit code); an exception escaping it becomes "<sample>: ..."
// and exit code 1 instead of an abort (std::bad_alloc at a huge --size, say).
template <class Body>
int runGuarded(const char* name, Body&& body) noexcept {
    try {
        return body();
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "%s: out of memory; ask for a smaller --size or fewer frames\n", name);
    } catch (const std::exception& e) { std::fprintf(stderr, "%s: %s\n", name, e.what()); } catch (...) {
        std::fprintf(stderr, "%s: unknown exception\n", name);
    }
    return 1;
}

} // namespace samples
