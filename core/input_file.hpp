// Reading a file that a user named: a scene, a sweep, a checkpoint, a print image. Such
// files are downloaded, generated or mistyped, and papertear runs unattended on batch
// systems, where a hang costs a job array its whole wall-clock limit. So every read here is
// bounded: only regular files are accepted (a FIFO, device, socket or directory is refused
// before anything waits on it), the open cannot block, and the read stops at a size cap per
// kind of file. A read either returns the whole file or throws; there is no third outcome.
#pragma once
#include <cstdint>
#include <stdexcept>
#include <string>

namespace papertear {

// The message is one line: "<path>: <what is wrong>".
struct InputFileError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// What is being read: the name used in messages and the default size cap.
struct InputKind {
  const char* name;        // "scene file", "checkpoint", ...
  std::uint64_t cap_bytes;  // larger files are refused unless PAPERTEAR_MAX_INPUT_MB says more
};

// 16 MiB of TOML is far beyond any scene or sweep a person writes; a checkpoint holds the
// whole lattice (about 200 bytes per cell), so its cap follows the largest sheet the scene
// limits allow; a print image is a PNG of at most a few thousand pixels square.
inline constexpr InputKind kSceneFileKind{"scene file", std::uint64_t(16) << 20};
inline constexpr InputKind kSweepFileKind{"sweep file", std::uint64_t(16) << 20};
inline constexpr InputKind kCheckpointKind{"checkpoint", std::uint64_t(16) << 30};
inline constexpr InputKind kPrintImageKind{"print image", std::uint64_t(64) << 20};
inline constexpr InputKind kPointResultKind{"point result", std::uint64_t(16) << 20};  // sweep --collect

// The environment variable that raises (or lowers) every cap, in MiB.
inline constexpr const char* kInputCapVariable = "PAPERTEAR_MAX_INPUT_MB";

// The cap in force for `kind`: its default, or PAPERTEAR_MAX_INPUT_MB when that is set to a
// positive whole number. Throws InputFileError for a malformed value.
std::uint64_t input_cap_bytes(const InputKind& kind);

// The whole content of the regular file `path`. Throws InputFileError naming the path when
// it does not exist, is not a regular file, is larger than the cap, or cannot be read.
std::string read_input_file(const std::string& path, const InputKind& kind);

}  // namespace papertear
