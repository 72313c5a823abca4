// Reading TOML configuration strictly: every key must be known, every value must have the
// expected type, and an error names where it happened (file:line:column, or the --set
// argument that produced the value) and what was expected. Scene files use these helpers;
// the renderer uses the same ones for its sections ([render], [camera], ...), so that every
// section of a scene file fails the same way.
//
// Errors are thrown as papertear::SceneError, one line each:
//   "scenes/paper.toml:4:9: sheet.density: expected a number, got a string"
//   "scenes/paper.toml:7:1: unknown key 'sheet.cels' (did you mean 'sheet.cells'?)"
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <toml++/toml.h>

#include "core/scene.hpp"

namespace papertear::io {

// Optimal-string-alignment distance: insertions, deletions, substitutions and swaps of two
// neighbouring characters each cost 1 ("rnu" -> "run" is one typo, not two).
std::size_t edit_distance(std::string_view a, std::string_view b);

// The known dotted key a mistyped `key` most likely meant, or nothing if none is close.
// Tried in order: a near spelling of the whole key; a near spelling of its leading
// section(s) with the rest kept ("rendr.width" -> "render.width"); a known key with the same
// last component in another section ("steps" -> "run.steps").
std::optional<std::string> nearest_key(std::string_view key, std::span<const std::string> known);

// Where a node came from: "file:line:column", the command-line argument that made it (a
// source name starting with "--", such as "--set key=value"), or "" when the node has no
// source (built in code).
std::string where(const toml::node& node);

// Throws SceneError "<where>: <key>: <problem>" (the location part left out when unknown).
[[noreturn]] void fail_at(const toml::node& node, std::string_view key, std::string_view problem);

// "an integer", "a string", "an array", ...: the node's type for error messages.
std::string type_phrase(const toml::node& node);

// Checks that every key in `table` (named `prefix` + "." + key, or just key at the top) is
// in `known`, descending into sub-tables that known keys live under. A known key's value is
// not descended into, so `known` may list whole sections ("render") that another reader
// checks. Throws SceneError for the first unknown key, with the nearest known key suggested.
void check_known_keys(const toml::table& table, std::string_view prefix,
                      std::span<const std::string> known);

// Typed readers. `key` is the dotted name used in the error. Each throws SceneError when the
// node has another type or an impossible value; numbers must be finite (TOML allows nan and
// inf literals), and integers are accepted where a number is expected.
double read_number(const toml::node& node, std::string_view key);
std::int64_t read_integer(const toml::node& node, std::string_view key);
int read_int(const toml::node& node, std::string_view key);  // range of int
std::uint64_t read_unsigned(const toml::node& node, std::string_view key);
bool read_bool(const toml::node& node, std::string_view key);
std::string read_string(const toml::node& node, std::string_view key);
char read_letter(const toml::node& node, std::string_view key);  // a one-letter string
std::array<double, 2> read_number2(const toml::node& node, std::string_view key);
std::array<double, 3> read_number3(const toml::node& node, std::string_view key);
std::array<int, 3> read_int3(const toml::node& node, std::string_view key);

// The table at `key` in `parent`, or nullptr if absent; throws if present but not a table.
const toml::table* find_table(const toml::table& parent, std::string_view key,
                              std::string_view dotted_name);

}  // namespace papertear::io
