#include "tools/render/image.hpp"

#include <png.h>

#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <string>

#include "core/input_file.hpp"
#include "tools/output_files.hpp"

namespace papertear::render {

namespace {

void append_bytes(png_structp png, png_bytep data, png_size_t length) {
  auto* out = static_cast<std::vector<std::uint8_t>*>(png_get_io_ptr(png));
  out->insert(out->end(), data, data + length);
}

void flush_nothing(png_structp) {}

// libpng's error callback may not return; it keeps the message and jumps back to the
// setjmp in write_rows (no C++ object with a destructor lives between the two).
struct PngErrorText {
  char text[256] = "unknown error";
};

void png_fail(png_structp png, png_const_charp message) {
  auto* err = static_cast<PngErrorText*>(png_get_error_ptr(png));
  std::snprintf(err->text, sizeof err->text, "%s", message);
  png_longjmp(png, 1);
}

void png_warn(png_structp, png_const_charp) {}

bool write_rows(png_structp png, png_infop info, const Image& image, std::vector<std::uint8_t>* out) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_write_fn(png, out, append_bytes, flush_nothing);
  png_set_IHDR(png, info, png_uint_32(image.width), png_uint_32(image.height), 8, PNG_COLOR_TYPE_RGB,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  // Level 3 with the "sub" and "up" filters: frames are large and written often; this is
  // several times faster than the defaults for a few percent more bytes.
  png_set_compression_level(png, 3);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB | PNG_FILTER_UP);
  png_write_info(png, info);
  for (int y = 0; y < image.height; ++y) png_write_row(png, const_cast<png_bytep>(image.pixel(0, y)));
  png_write_end(png, nullptr);
  return true;
}

}  // namespace

std::vector<std::uint8_t> encode_png(const Image& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgb.size() != std::size_t(image.width) * std::size_t(image.height) * 3)
    throw RenderError("PNG: image size does not match its pixel data");
  std::vector<std::uint8_t> out;
  out.reserve(image.rgb.size() / 2);
  PngErrorText err;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &err, png_fail, png_warn);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  const bool ok = info && write_rows(png, info, image, &out);
  png_destroy_write_struct(&png, &info);
  if (!ok) throw RenderError(std::string("PNG encoding failed: ") + err.text);
  return out;
}

Image decode_png(std::span<const std::uint8_t> png) {
  png_image header;
  std::memset(&header, 0, sizeof header);
  header.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&header, png.data(), png.size()))
    throw RenderError(std::string("not a readable PNG: ") + header.message);
  header.format = PNG_FORMAT_RGB;
  Image image(int(header.width), int(header.height));
  if (!png_image_finish_read(&header, nullptr, image.rgb.data(), 0, nullptr)) {
    std::string why = header.message;
    png_image_free(&header);
    throw RenderError("cannot decode PNG: " + why);
  }
  return image;
}

Image read_png(const std::filesystem::path& path) {
  std::string bytes;
  try {
    bytes = read_input_file(path.string(), kPrintImageKind);
  } catch (const InputFileError& e) {
    throw RenderError(e.what());
  }
  try {
    return decode_png({reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()});
  } catch (const RenderError& e) {
    throw RenderError("'" + path.string() + "': " + e.what());
  }
}

void write_png(const std::filesystem::path& path, const Image& image) {
  const std::vector<std::uint8_t> png = encode_png(image);
  io::write_file_atomically(path, std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
}

}  // namespace papertear::render
