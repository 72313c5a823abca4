// The output directory and the files written into it. Bad input must leave nothing behind,
// so the CLI first checks that the directory could be made (check_output_dir), then
// validates everything else, and only then creates it. Files are written atomically so
// that a reader (or a crashed run) never sees half a summary.json.
#pragma once
#include <filesystem>
#include <initializer_list>
#include <stdexcept>
#include <string_view>

namespace papertear::io {

// A file or directory that could not be created or written. One line, naming the path.
struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Throws OutputError if `dir` is not a writable directory and could not be created as one
// (an ancestor is a file, or not writable). Creates nothing.
void check_output_dir(const std::filesystem::path& dir);

// Throws OutputError if, inside an existing `dir`, one of the `files` a command will write is
// a directory (or anything but a regular file), or one of the `dirs` is not a directory: a
// write there would fail only after the whole run. Creates nothing.
void check_output_names(const std::filesystem::path& dir, std::initializer_list<const char*> files,
                        std::initializer_list<const char*> dirs);

// Creates `dir` and its missing parents. Throws OutputError.
void create_output_dir(const std::filesystem::path& dir);

// Writes `content` to a temporary file in the same directory, flushes it to disk and renames
// it over `path`, so `path` holds either its old content or all of the new one. Throws
// OutputError (and removes the temporary file).
void write_file_atomically(const std::filesystem::path& path, std::string_view content);

}  // namespace papertear::io
