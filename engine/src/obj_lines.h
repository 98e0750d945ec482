#pragma once
/// \file obj_lines.h
/// An OBJ file's vertex and face lines, checked before assimp reads it.
///
/// Why: assimp's OBJ reader drops a vertex line it cannot read ("v 0 x 0",
/// "v 0 1") without a word, and the faces after it then fail with "vertex
/// index out of range", naming neither the line nor the cause. Counting the
/// lines also refuses a file with more vertices or faces than the limits
/// before anything is allocated for them.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "dovetail/collision/mesh.h"

namespace dovetail::engine::detail {

/// Reads the OBJ file `path` line by line and returns the first thing wrong,
/// starting "line N: ", or nullopt. Checked, where assimp would drop a line
/// or fail without saying where: a vertex line `v` starts at the beginning
/// of its line with three numbers (x y z; what follows, a weight or a
/// colour, is not read), none of them starting with its decimal point
/// (".5": assimp 5.2 drops the line, and the faces after it then silently
/// name the wrong vertices); a face line `f` starts at the beginning of its line
/// and names each corner by a vertex number, 1 to the file's vertex count,
/// or -1 to minus the count so far (relative), optionally followed by
/// /texture/normal numbers, and nothing else (no comment after it); the
/// numbers of vertex and face lines are within `limits`. Everything else
/// (texture coordinates, normals, groups, materials, comment lines) is left
/// to the importer.
std::optional<std::string> check_obj_lines(const std::filesystem::path& path,
                                           const collision::MeshLimits& limits);

/// An OBJ file's text with repeated object names made unique, and a note per
/// renamed object.
struct UniqueObjects {
  std::string text;
  std::vector<std::string> notes;
};

/// The OBJ file `path` with each object line `o NAME` whose NAME an earlier
/// `o` or `g` line used renamed to NAME_2, NAME_3, ... (the first such name
/// no `o` or `g` line of the file uses); nullopt when no name repeats, the
/// usual case, or the file cannot be read (the importer then says why).
///
/// Why: assimp's OBJ reader gives a repeated object name the earlier object
/// of that name and keeps adding faces to the mesh it was filling, so two
/// washers, or a washer and the pin read after it, became one part under one
/// name. Renamed, each object is a node of its own, as in every other format.
/// Only the name changes; every other byte, and so every line number, stays.
std::optional<UniqueObjects> obj_with_unique_objects(const std::filesystem::path& path);

}  // namespace dovetail::engine::detail
