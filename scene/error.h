// scene/error.h: SceneError, the one exception bad input becomes, and JsonPath, which names
// where in a file the problem is (`objects[3].radius`).
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

namespace shadowlab::scene {

// At most `max` bytes of `text`, cut with "..." and a count: how an error quotes a value from a
// file, which may be megabytes long (a 100 MB key is not echoed whole).
inline std::string excerpt(std::string_view text, std::size_t max = 60) {
    if (text.size() <= max) return std::string(text);
    std::string out(text.substr(0, max > 3 ? max - 3 : 0));
    out += "... (" + std::to_string(text.size()) + " bytes)";
    return out;
}

// The longest error message: longer ones are cut (every value in them is already an excerpt;
// this bounds what a message can be built from, such as a long list of names).
inline constexpr std::size_t kMaxErrorMessage = 2000;

class JsonPath {
public:
    JsonPath() = default;
    JsonPath operator/(const std::string& key) const {
        JsonPath p = *this;
        if (!p.text_.empty()) p.text_.push_back('.');
        p.text_.append(excerpt(key, 40));  // keys come from the file: any length
        return p;
    }
    JsonPath operator/(std::size_t index) const {
        JsonPath p = *this;
        p.text_.push_back('[');
        p.text_.append(std::to_string(index));
        p.text_.push_back(']');
        return p;
    }
    const std::string& str() const { return text_; }
    bool empty() const { return text_.empty(); }

private:
    std::string text_;
};

// "FILE: PATH: WHAT", or "FILE: WHAT" when the problem is not at a JSON path.
class SceneError : public std::runtime_error {
public:
    SceneError(const std::filesystem::path& file, const JsonPath& path, const std::string& what)
        : std::runtime_error(file.string() + ": " + (path.empty() ? "" : path.str() + ": ") +
                             excerpt(what, kMaxErrorMessage)),
          file_(file),
          path_(path.str()) {}
    const std::filesystem::path& file() const { return file_; }
    const std::string& jsonPath() const { return path_; }

private:
    std::filesystem::path file_;
    std::string path_;
};

// Any other problem a user can cause (an unreadable frame, a bad command-line value):
// the message is complete and the program prints it as is.
class InputError : public std::runtime_error {
public:
    explicit InputError(const std::string& what) : std::runtime_error(excerpt(what, kMaxErrorMessage)) {}
};

// A result that could not be written once the work was done (a full disk, a folder that went
// away): a failure, exit 1, not bad input. (An output path known to be unusable before any work
// is an InputError, exit 2.)
class OutputError : public std::runtime_error {
public:
    explicit OutputError(const std::string& what) : std::runtime_error(excerpt(what, kMaxErrorMessage)) {}
};

}  // namespace shadowlab::scene
