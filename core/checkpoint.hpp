// Checkpoints: a World written to a file and read back, so that a run can stop and later
// continue bit for bit. A Simulation built from a loaded world (Simulation(World, options))
// and one that never stopped agree on every later step's digest and split events, on any
// thread count, because the file holds every bit of the state that the next step reads.
//
// What is stored: the whole papertear::World (core/world.hpp) except the RK4 scratch. Between
// two steps the scratch is determined by the state — the stage state equals (p, v) and the
// force accumulators are zero — so loading rebuilds it with reset_stage_state().
//
// File layout (every integer little-endian and fixed width; float and double as the raw bits
// of their IEEE-754 encoding, so NaN payloads and signed zeros survive):
//
//   offset size  field
//        0    8  magic "\x89PTCK\r\n\x1a\n": the high byte, CR LF and ^Z catch 7-bit and
//                text-mode transfers that would corrupt the binary payload
//        8    4  format version (kCheckpointFormatVersion)
//       12    4  reserved, written as 0
//       16    8  payload length in bytes
//       24    8  FNV-1a 64 of the payload bytes
//       32    …  payload
//
// The payload is a sequence of sections, each opened by a four-character tag, in this order:
//   SCEN  every Scene field, one by one (strings: u64 length + bytes; chars: u8); the lines
//         last: u64 count, each kind, u64 point count + (x, y) pairs, strength, i32 depth,
//         pitch, duty
//   NODE  node count, then each NodeStore column (u64 count + elements)
//   TOPO  LatticeDims, cell_nodes, the 8 colour lists, cell_scale, cell_block, face_strain,
//         face_damage
//   SPRG  SpringTable: 28 rest lengths, 28 stiffnesses, 28 dampings
//   CRSE  CoarseSprings columns
//   BLKS  blocks (lo, hi, strength, intact, first_spring, spring_count)
//   GRIP  grips (velocity), gripped_nodes
//   EVNT  split events
//   CLCK  step, time, dt
//   USER  bytes an application stores beside the world (the CLI keeps its frame plan and
//         the frames measured so far); the library does not interpret them
// and nothing after the last section. Any change to this layout bumps the format version.
//
// Loading refuses, with a CheckpointError that names the reason, anything that is not a
// checkpoint, another format version, a truncated or corrupted file, and contents that are
// not a consistent world (sizes that disagree with the lattice, ids out of range, a scene
// that does not validate, any violated core/invariants.hpp check).
#pragma once
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

#include "core/world.hpp"

namespace papertear {

inline constexpr std::uint32_t kCheckpointFormatVersion = 5;  // 2: the indenter keys; 3: scene lines;
                                                             // 4: material from moduli and density;
                                                             // 5: material.cross_stretch
inline constexpr std::size_t kCheckpointHeaderSize = 32;
inline constexpr std::string_view kCheckpointMagic{"\x89PTCK\r\n\x1a\n", 8};

struct CheckpointError : std::runtime_error {
  enum class Kind {
    NotACheckpoint,  // the magic bytes are wrong
    WrongVersion,    // another format version
    Truncated,       // shorter than its header says, or a read ran past the end
    Corrupted,       // checksum mismatch, or bytes after the payload
    Inconsistent,    // well-formed but not a valid world
    Io,              // the file could not be opened, read or written
  };
  CheckpointError(Kind kind_, const std::string& what) : std::runtime_error(what), kind(kind_) {}
  Kind kind;
};

// A loaded checkpoint: the world (stage state reset, ready for Simulation(World, ...)) and
// the application's bytes stored with it (empty when none were given).
struct CheckpointContents {
  World world;
  std::string user_data;
};

// The file image (header + payload) of a world and optional application bytes.
std::string serialize_world(const World& world, std::string_view user_data = {});
// Reads a file image. Throws CheckpointError; the message starts with "checkpoint: ".
CheckpointContents deserialize_checkpoint(std::string_view bytes);
World deserialize_world(std::string_view bytes);

// Writes the checkpoint to a temporary file in the same directory, flushes it to disk and
// renames it over `path`, so `path` always holds a whole checkpoint (old or new). Throws
// CheckpointError (kind Io) naming the path.
void save_checkpoint(const World& world, const std::string& path, std::string_view user_data = {});
// Reads a checkpoint file. Throws CheckpointError; the message starts with the path.
CheckpointContents read_checkpoint(const std::string& path);
World load_checkpoint(const std::string& path);

// The checksum stored in the header: FNV-1a 64 (offset basis 0xcbf29ce484222325, prime
// 0x100000001b3) over the payload bytes.
std::uint64_t checkpoint_checksum(std::string_view payload);

// Human-readable name of an error kind ("not a checkpoint", "truncated", ...).
const char* checkpoint_error_name(CheckpointError::Kind kind);

}  // namespace papertear
