#pragma once
/// \file png_writer.h
/// Encoding RGBA pixels as PNG with libpng, kept out of the public headers.

#include <cstdint>
#include <filesystem>
#include <span>

namespace dovetail::engine {

/// Writes `rgba` (row by row from the top, `width * height * 4` bytes) to
/// `path` as an 8-bit RGBA PNG without time stamps, so the same pixels give
/// the same file. Throws RenderError naming the path on any failure.
void write_rgba_png(std::span<const std::uint8_t> rgba, int width, int height,
                    const std::filesystem::path& path);

}  // namespace dovetail::engine
