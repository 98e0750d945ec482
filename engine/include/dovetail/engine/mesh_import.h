#pragma once
/// \file mesh_import.h
/// Reading triangle meshes from any file format assimp understands.
///
/// Why: every part a user brings (OBJ, STL, PLY, OFF, glTF/GLB, ...) enters
/// through this one door, so one place decides what counts as broken input.
/// Node transforms are applied in double precision, triangles are the only
/// primitives kept (points and lines are counted and skipped), and every
/// result passes collision::make_mesh. Files that cannot become a mesh give an
/// ImportError naming the file; declared sizes are checked against the file
/// size and the limits before anything is allocated, and the importer may not
/// read files outside the input file's folder.

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "dovetail/collision/mesh.h"
#include "dovetail/engine/camera.h"

namespace dovetail::engine {

/// Thrown when a file cannot be imported; what() starts with the file's path
/// and says what is wrong.
class ImportError : public collision::MeshError {
 public:
  using collision::MeshError::MeshError;
};

/// How to import a file.
struct ImportOptions {
  /// true: one Mesh for the whole file; false: one part per mesh instance of
  /// every node (a mesh used by two nodes gives two parts).
  bool merge = true;
  /// With merge = false only. false: every part's vertices are in the file's
  /// root frame. true: a part's vertices stay in its node's frame and
  /// ImportedPart::X_RP is the node's rigid pose in the root frame; scale or
  /// shear in the node transform stays in the vertices (the rotation is the
  /// polar factor of the node's 3x3 matrix).
  bool part_frames = false;
  /// Checked before allocating (declared counts) and again by make_mesh.
  collision::MeshLimits limits;
  /// true: the importer (assimp) reads the file in a child process, so that
  /// a crash inside it on a malformed file is an ImportError naming the file
  /// and the signal, and its memory is capped (4 GiB plus 64 times the
  /// file's size). false: in this process, as the fuzz targets read, to see
  /// the importer's own crashes, leaks and memory.
  bool in_child_process = true;
};

/// One imported mesh, in the file's root frame (node transforms applied).
struct ImportedPart {
  /// The node's name (or the mesh's, or "part" when both are empty), made
  /// unique within the file by a suffix `_2`, `_3`, ... in depth-first order.
  /// For a merged import: the file name without folder.
  std::string name;
  /// The node it comes from, numbered in depth-first order: the meshes of
  /// one node (a glTF node's primitives) are parts of the same node.
  std::size_t node = 0;
  /// The names of the nodes above that node (the groups it belongs to: a
  /// sub-assembly), from the root down, as the file names them.
  std::vector<std::string> groups;
  collision::Mesh mesh;
  collision::MeshValidation validation;
  /// Pose of the part's frame in the file's root frame: identity unless
  /// ImportOptions::part_frames (then mesh vertices map to the root frame by
  /// X_RP.apply).
  collision::Transform X_RP;
};

/// Everything an import produced and noticed.
struct ImportReport {
  std::vector<ImportedPart> parts;  ///< one when merged; depth-first node order otherwise
  /// The file's perspective cameras in its root frame, named as the importer
  /// names them (the camera node's name; `nodes[i]` for an unnamed glTF
  /// node), in file order. Orthographic cameras are skipped with a note.
  std::vector<NamedCamera> cameras;
  std::size_t skipped_line_or_point_primitives = 0;  ///< not triangles, left out
  std::vector<std::string> notes;                    ///< things worth telling the user, not errors
  /// Every file the import read, as normalised absolute paths: the input and
  /// what it refers to (glTF buffers, OBJ material libraries), so that a
  /// command can refuse an output that would overwrite one of them.
  std::vector<std::string> files;
};

/// Imports `path`. Throws ImportError (message starts with the path) for a
/// missing, unreadable, empty, truncated or malformed file, for non-finite
/// coordinates, for declared sizes beyond the file or the limits, for a file
/// without triangles, and when the format refers to files outside the input's
/// folder.
ImportReport import_file(const std::filesystem::path& path, const ImportOptions& options = {});

/// Imports `path` merged into one Mesh with the default limits; `validation`
/// (when given) receives what make_mesh found.
collision::Mesh import_mesh(const std::filesystem::path& path,
                            collision::MeshValidation* validation = nullptr);

}  // namespace dovetail::engine
