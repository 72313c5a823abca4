// 8-bit sRGB images and their PNG encoding (libpng). Encoding is deterministic: the same
// pixels always give the same bytes (no timestamps or other metadata are written).
#pragma once
#include <cstdint>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <vector>

namespace papertear::render {

struct RenderError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;  // row-major from the top row, 3 bytes per pixel

  Image() = default;
  Image(int w, int h) : width(w), height(h), rgb(std::size_t(w) * std::size_t(h) * 3, 0) {}
  std::uint8_t* pixel(int x, int y) { return rgb.data() + (std::size_t(y) * std::size_t(width) + std::size_t(x)) * 3; }
  const std::uint8_t* pixel(int x, int y) const {
    return rgb.data() + (std::size_t(y) * std::size_t(width) + std::size_t(x)) * 3;
  }
};

std::vector<std::uint8_t> encode_png(const Image& image);
// Throws RenderError for data that is not a PNG; any PNG colour type is converted to RGB.
Image decode_png(std::span<const std::uint8_t> png);
Image read_png(const std::filesystem::path& path);
// Written atomically (tools/output_files.hpp); throws io::OutputError naming the path.
void write_png(const std::filesystem::path& path, const Image& image);

}  // namespace papertear::render
