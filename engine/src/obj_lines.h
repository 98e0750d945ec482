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

}  // namespace dovetail::engine::detail
