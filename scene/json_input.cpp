// scene/json_input.cpp: the nesting limit and bounded descriptions (see json_input.h).
#include "scene/json_input.h"

#include "scene/error.h"
#include "scene/input_file.h"
#include "scene/memory.h"

namespace shadowlab::scene {

namespace {

// Appends a bounded description of `v` to `out`, stopping once out passes `max`. Recursion is
// bounded by kMaxJsonDepth: every value described was parsed after checkJsonNesting.
void describeInto(const nlohmann::json& v, std::size_t max, std::string& out, int depth) {
    if (out.size() > max) return;
    if (v.is_string()) {
        const std::string& s = v.get_ref<const std::string&>();
        out += nlohmann::json(s.substr(0, max + 1)).dump();
    } else if (v.is_array() || v.is_object()) {
        if (depth > kMaxJsonDepth) {
            out += "...";
            return;
        }
        out += v.is_array() ? '[' : '{';
        bool first = true;
        for (auto it = v.begin(); it != v.end(); ++it) {
            if (out.size() > max) break;
            if (!first) out += ',';
            first = false;
            if (v.is_object()) out += nlohmann::json(it.key().substr(0, max + 1)).dump() + ':';
            describeInto(*it, max, out, depth + 1);
        }
        out += v.is_array() ? ']' : '}';
    } else {
        out += v.dump();
    }
}

std::string parserMessage(const std::exception& e) {
    std::string what = e.what();
    // nlohmann's messages start "[json.exception.parse_error.101] parse error at line..."
    if (const auto pos = what.find("] "); pos != std::string::npos) what = what.substr(pos + 2);
    return what;
}

}  // namespace

std::string lineColumn(std::string_view text, std::size_t byte) {
    std::size_t line = 1, column = 1;
    for (std::size_t i = 0; i < byte && i < text.size(); ++i) {
        if (text[i] == '\n') {
            ++line;
            column = 1;
        } else {
            ++column;
        }
    }
    return "line " + std::to_string(line) + ", column " + std::to_string(column);
}

std::string jsonNestingProblem(std::string_view text) {
    int depth = 0;
    bool inString = false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (inString) {
            if (c == '\\')
                ++i;
            else if (c == '"')
                inString = false;
            continue;
        }
        if (c == '"') {
            inString = true;
        } else if (c == '[' || c == '{') {
            if (++depth > kMaxJsonDepth)
                return "arrays and objects are nested deeper than " + std::to_string(kMaxJsonDepth) + " levels near " +
                       lineColumn(text, i);
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
    return {};
}

void checkJsonNesting(const std::filesystem::path& file, std::string_view text) {
    if (const std::string problem = jsonNestingProblem(text); !problem.empty()) throw SceneError(file, {}, problem);
}

std::uint64_t jsonTreeBytes(std::string_view text) {
    std::uint64_t values = 0, containers = 0, members = 0, strings = 0, stringBytes = 0;
    bool inString = false, inScalar = false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (inString) {
            ++stringBytes;
            if (c == '\\')
                ++i;
            else if (c == '"')
                inString = false;
            continue;
        }
        const bool scalarChar = (c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') || c == '-' || c == '+' || c == '.' ||
                                (c >= 'A' && c <= 'Z');
        if (scalarChar && !inScalar) ++values;
        inScalar = scalarChar;
        if (c == '"') {
            inString = true;
            ++strings;
            ++values;
        } else if (c == '[' || c == '{') {
            ++containers;
            ++values;
        } else if (c == ':') {
            ++members;
        }
    }
    return 32 * values + 64 * containers + 96 * members + 48 * strings + stringBytes;
}

nlohmann::json parseJsonText(const std::filesystem::path& file, std::string_view text) {
    checkJsonNesting(file, text);
    if (const std::uint64_t tree = jsonTreeBytes(text), available = availableMemoryBytes();
        available != 0 && tree > available)
        throw SceneError(file, {},
                         "parsing it needs about " + std::to_string(tree >> 20) + " MiB, more than the " +
                             std::to_string(available >> 20) + " MiB available");
    try {
        return nlohmann::json::parse(text.begin(), text.end());
    } catch (const nlohmann::json::parse_error& e) {
        throw SceneError(
            file, {}, "invalid JSON near " + lineColumn(text, e.byte == 0 ? 0 : e.byte - 1) + ": " + parserMessage(e));
    } catch (const nlohmann::json::exception& e) {
        throw SceneError(file, {}, "invalid JSON: " + parserMessage(e) + " (numbers must be finite)");
    }
}

nlohmann::json readJsonFile(const std::filesystem::path& file) {
    return parseJsonText(file, readInputFile(file, kMaxJsonFileBytes));
}

nlohmann::json readJsonFileOrNull(const std::filesystem::path& file) {
    try {
        return readJsonFile(file);
    } catch (const std::exception&) {
        return nullptr;
    }
}

std::string describeJson(const nlohmann::json& value, std::size_t max) {
    std::string out;
    describeInto(value, max, out, 0);
    if (out.size() > max) out = out.substr(0, max > 3 ? max - 3 : 0) + "...";
    return out;
}

}  // namespace shadowlab::scene
