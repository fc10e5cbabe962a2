// scene/json_input.h: guards for JSON read from a file, applied before any parser builds or
// walks a tree from it: a nesting limit (parsers and printers that recurse would overflow the
// stack on a few megabytes of "[[[["), and a bounded description of a value for error messages.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace shadowlab::scene {

// Arrays and objects nested deeper than this are refused. Scenes, grids and glTF files nest a
// handful of levels (glTF extras a few more); 64 is far above that and far below what a
// recursive parser's stack holds.
inline constexpr int kMaxJsonDepth = 64;

// Throws SceneError(file, {}, "...nested deeper than 64 levels near line L, column C") when
// `text` nests arrays/objects deeper than kMaxJsonDepth. Strings are skipped (brackets inside
// them do not count); the text need not be valid JSON otherwise (the parser says what else is
// wrong).
void checkJsonNesting(const std::filesystem::path& file, std::string_view text);
// The same check: what is wrong ("arrays and objects are nested deeper than..."), or "".
std::string jsonNestingProblem(std::string_view text);

// An upper estimate of the memory nlohmann::json takes for the tree of `text`, from a count of
// its values, members and string bytes (each value 16 bytes, twice over for a growing array's
// spare capacity; an array's or object's own allocation; a member's map node and key; a
// string's allocation). Measured trees of scenes and worst-case files (a million empty objects,
// five million numbers) take 5 to 13.5 times their text; this estimate stays above them.
std::uint64_t jsonTreeBytes(std::string_view text);

// Parses `text` from `file` as JSON after checkJsonNesting: syntax errors and number overflow
// become SceneError with the line and column. For files other than scenes (grids).
nlohmann::json parseJsonText(const std::filesystem::path& file, std::string_view text);

// `file` read with readInputFile (a folder, a FIFO or a device refused before it is opened, so
// that no read waits for a writer; at most kMaxJsonFileBytes) and parsed with parseJsonText.
// Throws InputFileError for the file, SceneError for its text.
nlohmann::json readJsonFile(const std::filesystem::path& file);
// The same, or null where it throws: for probing what a folder holds (which kind of shard).
nlohmann::json readJsonFileOrNull(const std::filesystem::path& file);

// "line L, column C" of a byte offset.
std::string lineColumn(std::string_view text, std::size_t byte);

// At most about `max` characters describing `value` (strings, arrays and objects cut with
// "..."), without printing the whole of a large value.
std::string describeJson(const nlohmann::json& value, std::size_t max = 60);

}  // namespace shadowlab::scene
