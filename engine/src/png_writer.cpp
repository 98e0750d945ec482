#include "png_writer.h"

#include <png.h>

#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <string>
#include <system_error>
#include <vector>

#include "dovetail/engine/render.h"

namespace dovetail::engine {

namespace {

/// Where libpng's error callback leaves its message before jumping back.
struct PngFailure {
  char message[256] = {};
};

void on_png_error(png_structp png, png_const_charp message) {
  auto* failure = static_cast<PngFailure*>(png_get_error_ptr(png));
  std::snprintf(failure->message, sizeof failure->message, "%s", message);
  png_longjmp(png, 1);
}

void on_png_warning(png_structp, png_const_charp) {}

/// Encodes the rows into `file`. libpng reports errors by longjmp, so this
/// frame holds nothing with a destructor.
bool encode(std::FILE* file, png_bytepp rows, int width, int height, PngFailure* failure) {
  png_structp png =
      png_create_write_struct(PNG_LIBPNG_VER_STRING, failure, on_png_error, on_png_warning);
  if (png == nullptr) {
    std::snprintf(failure->message, sizeof failure->message, "cannot create the PNG encoder");
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (info == nullptr) {
    png_destroy_write_struct(&png, nullptr);
    std::snprintf(failure->message, sizeof failure->message, "cannot create the PNG encoder");
    return false;
  }
  if (setjmp(png_jmpbuf(png)) != 0) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_init_io(png, file);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8,
               PNG_COLOR_TYPE_RGB_ALPHA, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  png_write_image(png, rows);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

}  // namespace

void write_rgba_png(std::span<const std::uint8_t> rgba, int width, int height,
                    const std::filesystem::path& path) {
  const std::string name = path.string();
  if (width <= 0 || height <= 0 ||
      rgba.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4) {
    throw RenderError(name + ": cannot be written: the image has no pixels or a wrong size");
  }
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw RenderError(name + ": cannot be written: is a directory");
  }

  std::vector<png_bytep> rows(static_cast<std::size_t>(height));
  const std::size_t stride = static_cast<std::size_t>(width) * 4;
  for (std::size_t y = 0; y < rows.size(); ++y) {
    // libpng takes non-const rows but only reads them when writing.
    rows[y] = const_cast<png_bytep>(rgba.data() + y * stride);
  }

  std::FILE* file = std::fopen(name.c_str(), "wb");
  if (file == nullptr) {
    throw RenderError(name + ": cannot be written: " + std::strerror(errno));
  }
  PngFailure failure;
  bool ok = encode(file, rows.data(), width, height, &failure);
  std::string reason = failure.message;
  if (ok && (std::fflush(file) != 0 || std::ferror(file) != 0)) {
    ok = false;
    reason = std::strerror(errno);
  }
  if (std::fclose(file) != 0 && ok) {
    ok = false;
    reason = std::strerror(errno);
  }
  if (!ok) {
    // A partial picture is removed; a device or pipe written to is left alone.
    if (std::filesystem::is_regular_file(path, ec)) std::filesystem::remove(path, ec);
    throw RenderError(name + ": write failed: " + reason);
  }
}

}  // namespace dovetail::engine
