// scene/input_file.h: the one way every input file is opened (scenes, meshes and what they name,
// frames, grids, stability cases, sweep journals). Only regular files are read: a folder, a named
// pipe (which would block forever), a device such as /dev/zero (which never ends) or a socket is
// refused by stat() before it is opened; symlinks are followed and their target checked. The size
// is known and bounded before a byte is read, and no more than that size is ever read.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "scene/error.h"

namespace shadowlab::scene {

// Size bounds by kind of input, each far above any real file of its kind and below what a
// machine that renders it would have to spare: a JSON file is parsed into a DOM of about ten
// times its size, a mesh's arrays are about its size again.
inline constexpr std::uint64_t kMaxJsonFileBytes = 256ull << 20;   // scenes, grids, glTF JSON
inline constexpr std::uint64_t kMaxMeshFileBytes = 4ull << 30;     // OBJ, GLB, glTF buffers
inline constexpr std::uint64_t kMaxFrameFileBytes = 16ull << 30;   // EXR Frames (64 Mpixels x 32 channels)
inline constexpr std::uint64_t kMaxJournalFileBytes = 1ull << 30;  // a sweep's results.jsonl

// A problem with one input file: what() is "FILE: PROBLEM"; problem() is the part after the
// name, for callers that name the file inside a longer context (a mesh named by a scene).
class InputFileError : public InputError {
public:
    InputFileError(const std::filesystem::path& file, const std::string& problem)
        : InputError(file.string() + ": " + problem), file_(file), problem_(problem) {}
    const std::filesystem::path& file() const { return file_; }
    const std::string& problem() const { return problem_; }

private:
    std::filesystem::path file_;
    std::string problem_;
};

// `file`'s extension ("." included) in lower case: every reader and writer tells a format by it,
// and "MODEL.GLB" is a .glb.
std::string lowercaseExtension(const std::filesystem::path& file);

// Checks that `file` is a regular file (after following symlinks) of at most `maxBytes` bytes,
// for readers that must open it themselves (OpenImageIO); returns its size. Throws InputFileError.
std::uint64_t checkInputFile(const std::filesystem::path& file, std::uint64_t maxBytes);

// Reads the whole of a regular file of at most `maxBytes` bytes: checked as above, opened
// without blocking, checked again on the open descriptor (the file cannot be swapped for a pipe
// in between) and read up to the size stat() gave. Throws InputFileError.
std::string readInputFile(const std::filesystem::path& file, std::uint64_t maxBytes);

// Whether `file` exists at all (for optional inputs such as an OBJ's material library).
bool inputFileExists(const std::filesystem::path& file);

}  // namespace shadowlab::scene
