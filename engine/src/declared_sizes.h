#pragma once
/// \file declared_sizes.h
/// Cheap checks of the sizes a mesh file declares, before any importer
/// allocates for them.
///
/// Why: PLY headers and binary STL state element counts up front, and
/// importers reserve memory for them. A 300-byte file claiming 10^11 vertices
/// must be refused in microseconds, not after a failed multi-gigabyte
/// allocation. Every element needs at least a few bytes, so the declared counts
/// are compared with the file size and with the mesh limits.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "dovetail/collision/mesh.h"

namespace dovetail::engine::detail {

/// Reads the start of `path` (its size is `file_size` bytes) and, for formats
/// that declare counts (PLY, binary STL), returns what is wrong with the
/// declared sizes; for OBJ, which declares nothing, what check_obj_lines
/// (obj_lines.h) finds wrong with its vertex and face lines; nullopt when
/// nothing is wrong or the format is none of these (the importer decides
/// then).
std::optional<std::string> check_declared_sizes(const std::filesystem::path& path,
                                                std::uintmax_t file_size,
                                                const collision::MeshLimits& limits);

}  // namespace dovetail::engine::detail
