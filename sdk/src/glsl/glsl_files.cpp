// Embedded GLSL lookup and include expansion (glsl_files.hpp).
#include "glsl/glsl_files.hpp"

#include <algorithm>
#include <cctype>
#include <set>
#include <vector>

namespace splatfx::glsl {

std::string_view file(std::string_view name) {
    const detail::EmbeddedFile* first = detail::kEmbeddedFiles;
    const detail::EmbeddedFile* last = first + detail::kEmbeddedFileCount;
    const auto it =
        std::lower_bound(first, last, name, [](const detail::EmbeddedFile& f, std::string_view n) { return std::string_view(f.name) < n; });
    return it != last && std::string_view(it->name) == name ? std::string_view(it->text) : std::string_view();
}

bool hasFile(std::string_view name) {
    const detail::EmbeddedFile* first = detail::kEmbeddedFiles;
    const detail::EmbeddedFile* last = first + detail::kEmbeddedFileCount;
    return std::any_of(first, last, [&](const detail::EmbeddedFile& f) { return std::string_view(f.name) == name; });
}

namespace {

struct Expander {
    std::initializer_list<Override> overrides;
    std::set<std::string, std::less<>> seen;
    std::vector<std::string> stack; // for messages: the chain of includes
    std::string error;

    bool run(std::string_view name, std::string& out) {
        if (seen.count(name)) return true; // included once per expansion
        seen.insert(std::string(name));
        for (const Override& o : overrides)
            if (o.name == name) {
                out += o.text;
                return true;
            }
        if (!hasFile(name)) {
            error = "GLSL file \"" + std::string(name) + "\" is not embedded (sdk/src/render/gl/glsl)";
            for (auto it = stack.rbegin(); it != stack.rend(); ++it) error += ", included from " + *it;
            return false;
        }
        const std::string_view text = file(name);
        std::size_t pos = 0;
        int line = 1;
        while (pos < text.size()) {
            std::size_t end = text.find('\n', pos);
            end = end == std::string_view::npos ? text.size() : end + 1;
            const std::string_view ln = text.substr(pos, end - pos);
            std::size_t i = 0;
            while (i < ln.size() && (ln[i] == ' ' || ln[i] == '\t')) ++i;
            if (ln.substr(i, 8) == "#include") {
                const std::size_t q0 = ln.find('"', i), q1 = q0 == std::string_view::npos ? q0 : ln.find('"', q0 + 1);
                if (q1 == std::string_view::npos) {
                    error = std::string(name) + ":" + std::to_string(line) + ": #include needs a quoted file name";
                    return false;
                }
                stack.push_back(std::string(name) + ":" + std::to_string(line));
                if (!run(ln.substr(q0 + 1, q1 - q0 - 1), out)) return false;
                stack.pop_back();
                if (!out.empty() && out.back() != '\n') out += '\n';
            } else {
                out += ln;
            }
            pos = end;
            ++line;
        }
        return true;
    }
};

bool wordChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

} // namespace

Result<std::string> expand(std::string_view name, std::initializer_list<Override> overrides) {
    Expander e{overrides, {}, {}, {}};
    std::string out;
    if (!e.run(name, out)) return makeError(e.error);
    return out;
}

std::string substitute(std::string text, std::initializer_list<std::pair<std::string_view, std::string_view>> words) {
    for (const auto& [from, to] : words) {
        std::size_t pos = 0;
        while ((pos = text.find(from, pos)) != std::string::npos) {
            const bool startOk = pos == 0 || !wordChar(text[pos - 1]);
            const bool endOk = pos + from.size() >= text.size() || !wordChar(text[pos + from.size()]);
            if (startOk && endOk) {
                text.replace(pos, from.size(), to);
                pos += to.size();
            } else {
                pos += from.size();
            }
        }
    }
    return text;
}

} // namespace splatfx::glsl
