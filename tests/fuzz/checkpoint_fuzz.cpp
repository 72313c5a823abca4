// libFuzzer target for the checkpoint loader (core/checkpoint.hpp). Whatever the bytes,
// deserialize_checkpoint must either return a world that passed its checks or throw
// CheckpointError: no crash, no read out of bounds, no unbounded allocation (AddressSanitizer
// watches), no other exception.
//
// The payload checksum would stop almost every mutation at the header, so the first input
// byte picks the mode: even, the rest is a whole file; odd, the rest is a payload and gets a
// valid header here, which lets the fuzzer reach the section readers and consistency checks.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "core/checkpoint.hpp"

namespace {

void put_le(std::string& out, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xffu));
}

std::string with_header(std::string_view payload) {
  std::string out(papertear::kCheckpointMagic);
  put_le(out, papertear::kCheckpointFormatVersion, 4);
  put_le(out, 0, 4);
  put_le(out, payload.size(), 8);
  put_le(out, papertear::checkpoint_checksum(payload), 8);
  out.append(payload);
  return out;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string_view rest(reinterpret_cast<const char*>(data) + 1, size - 1);
  const std::string bytes = (data[0] & 1) ? with_header(rest) : std::string(rest);
  try {
    const papertear::CheckpointContents c = papertear::deserialize_checkpoint(bytes);
    // Accepted: every payload byte was read as a field, so writing the world again gives
    // the same payload (the header's reserved word is not compared).
    const std::string again = papertear::serialize_world(c.world, c.user_data);
    if (std::string_view(again).substr(papertear::kCheckpointHeaderSize) !=
        std::string_view(bytes).substr(papertear::kCheckpointHeaderSize))
      __builtin_trap();
  } catch (const papertear::CheckpointError&) {
  }
  return 0;
}
