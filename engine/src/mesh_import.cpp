#include "dovetail/engine/mesh_import.h"

#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include "declared_sizes.h"
#include "folder_io_system.h"
#include "import_process.h"
#include "obj_lines.h"

namespace dovetail::engine {

namespace fs = std::filesystem;
using collision::MeshLimits;
using collision::TriangleIndices;
using collision::Vec3;

namespace {

/// Affine 3x4 part of a node transform, in double: p_root = M * [p_node; 1].
using Affine = Eigen::Matrix<double, 3, 4>;

[[noreturn]] void fail(const fs::path& path, const std::string& what) {
  throw ImportError(path.string() + ": " + what);
}

std::string plural(std::size_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

/// Everything about the file itself that can be told before any importer runs.
std::uintmax_t check_file(const fs::path& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) {
    if (ec && ec != std::errc::no_such_file_or_directory) {
      fail(path, "cannot be accessed: " + ec.message());
    }
    fail(path, "file not found");
  }
  if (fs::is_directory(status)) fail(path, "is a directory, not a mesh file");
  if (!fs::is_regular_file(status)) fail(path, "is not a regular file");
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) fail(path, "cannot read its size: " + ec.message());
  if (size == 0) fail(path, "file is empty");
  std::ifstream probe(path, std::ios::binary);
  if (!probe) fail(path, std::string("cannot be opened for reading: ") + std::strerror(errno));
  return size;
}

Affine to_affine(const aiMatrix4x4& m) {
  Affine a;
  for (unsigned r = 0; r < 3; ++r) {
    for (unsigned c = 0; c < 4; ++c) a(r, c) = static_cast<double>(m[r][c]);
  }
  return a;
}

/// X_RN composed: parent-to-root times node-to-parent, in double.
Affine compose(const Affine& X_RQ, const Affine& X_QN) {
  Affine X_RN;
  X_RN.leftCols<3>() = X_RQ.leftCols<3>() * X_QN.leftCols<3>();
  X_RN.col(3) = X_RQ.leftCols<3>() * X_QN.col(3) + X_RQ.col(3);
  return X_RN;
}

Vec3 apply(const Affine& X, const aiVector3D& v) {
  const double x = v.x, y = v.y, z = v.z;
  return Vec3(X(0, 0) * x + X(0, 1) * y + X(0, 2) * z + X(0, 3),
              X(1, 0) * x + X(1, 1) * y + X(1, 2) * z + X(1, 3),
              X(2, 0) * x + X(2, 1) * y + X(2, 2) * z + X(2, 3));
}

/// One use of a mesh by a node, with the node's transform to the file's root.
struct Instance {
  const aiNode* node = nullptr;
  std::size_t node_number = 0;  ///< the node's place in depth-first order
  unsigned mesh = 0;
  Affine X_RN;
};

/// Depth-first (pre-order) list of every mesh instance; iterative so that a
/// deep hierarchy cannot exhaust the stack, and each node visited once.
std::vector<Instance> collect_instances(const fs::path& path, const aiScene& scene) {
  std::vector<Instance> instances;
  struct Pending {
    const aiNode* node;
    Affine X_RQ;  ///< the node's parent Q in the root
  };
  std::vector<Pending> stack{{scene.mRootNode, Affine::Identity()}};
  std::set<const aiNode*> visited;
  while (!stack.empty()) {
    const Pending top = stack.back();
    stack.pop_back();
    if (top.node == nullptr) continue;
    if (!visited.insert(top.node).second)
      fail(path, "node hierarchy contains a cycle or a shared node");
    const std::size_t node_number = visited.size() - 1;
    const Affine X_RN = compose(top.X_RQ, to_affine(top.node->mTransformation));
    for (unsigned k = 0; k < top.node->mNumMeshes; ++k) {
      const unsigned mesh = top.node->mMeshes[k];
      if (mesh >= scene.mNumMeshes) {
        fail(path, "node '" + std::string(top.node->mName.C_Str()) + "' refers to mesh " +
                       std::to_string(mesh) + " of " + std::to_string(scene.mNumMeshes));
      }
      instances.push_back({top.node, node_number, mesh, X_RN});
    }
    for (unsigned k = top.node->mNumChildren; k > 0; --k) {
      stack.push_back({top.node->mChildren[k - 1], X_RN});
    }
  }
  return instances;
}

/// Transform of `node` to the file's root: its own composed with its
/// ancestors' (the hierarchy is known to be acyclic by now).
Affine node_to_root(const aiNode& node) {
  Affine X_RN = to_affine(node.mTransformation);
  for (const aiNode* parent = node.mParent; parent != nullptr; parent = parent->mParent) {
    X_RN = compose(to_affine(parent->mTransformation), X_RN);
  }
  return X_RN;
}

/// The file's perspective cameras in its root frame, named uniquely (`_2`,
/// `_3`, ... for repeated names; `camera` for an empty one).
///
/// Of the formats read (check_format), only glTF and GLB carry cameras, so
/// two quirks of assimp 5.2's glTF importer are undone: its "horizontal"
/// angle is yfov x aspect ratio (so the vertical one is that over the
/// aspect ratio), and it copies the camera node's translation into the
/// camera's own position (assimp issue 5054), although the node transform
/// places the camera too.
void collect_cameras(const aiScene& scene, ImportReport& report) {
  // Assimp ties a camera to the node of the same name. With repeated names
  // the k-th camera of a name takes the k-th node of that name, depth first.
  std::map<std::string, std::vector<const aiNode*>> nodes_named;
  std::vector<const aiNode*> stack{scene.mRootNode};
  while (!stack.empty()) {
    const aiNode* node = stack.back();
    stack.pop_back();
    nodes_named[node->mName.C_Str()].push_back(node);
    for (unsigned k = node->mNumChildren; k > 0; --k) stack.push_back(node->mChildren[k - 1]);
  }
  std::map<std::string, std::size_t> taken;
  std::set<std::string> used;
  for (unsigned i = 0; i < scene.mNumCameras; ++i) {
    const aiCamera& camera = *scene.mCameras[i];
    const std::vector<const aiNode*>& candidates = nodes_named[camera.mName.C_Str()];
    const std::size_t nth = taken[camera.mName.C_Str()]++;
    const aiNode* node = nth < candidates.size() ? candidates[nth] : nullptr;
    const std::string base =
        camera.mName.length > 0 ? std::string(camera.mName.C_Str()) : std::string("camera");
    std::string name = base;
    for (std::size_t k = 2; used.count(name) != 0; ++k) {
      name = base;
      name += '_';
      name += std::to_string(k);
    }
    if (!(camera.mHorizontalFOV > 0)) {
      report.notes.push_back("skipped orthographic camera '" + name + "'");
      continue;
    }
    const Affine X_RN = node != nullptr ? node_to_root(*node) : Affine::Identity();
    aiVector3D position = camera.mPosition;
    if (node != nullptr) {
      const aiMatrix4x4& m = node->mTransformation;
      if (position == aiVector3D(m.a4, m.b4, m.c4)) position = aiVector3D(0, 0, 0);
    }
    const Vec3 eye = apply(X_RN, position);
    const collision::Mat3 R = X_RN.leftCols<3>();
    const Vec3 look = R * Vec3(camera.mLookAt.x, camera.mLookAt.y, camera.mLookAt.z);
    const Vec3 up = R * Vec3(camera.mUp.x, camera.mUp.y, camera.mUp.z);
    const double aspect = camera.mAspect > 0 ? camera.mAspect : 1.0;
    Camera out;
    out.eye = eye;
    out.target = eye + look.normalized();
    out.up = up;
    // assimp 5.2: the glTF importer hands over yfov x aspect.
    out.fov_y_degrees = camera.mHorizontalFOV / aspect * 180 / std::numbers::pi;
    if (!out.eye.allFinite() || !out.target.allFinite() || !out.up.allFinite() ||
        !(out.up.squaredNorm() > 0) || !(out.fov_y_degrees > 0 && out.fov_y_degrees < 180)) {
      report.notes.push_back("skipped camera '" + name +
                             "' with a degenerate pose or field of view");
      continue;
    }
    used.insert(name);
    report.cameras.emplace_back(name, out);
  }
}

/// Splits X_RN into a rigid pose X_RP (the polar rotation of its 3x3 part,
/// with determinant +1, and its translation) and returns what is left for the
/// vertices, R_RP^T * A with no translation: identity when A is a rotation.
Affine split_rigid(const Affine& X_RN, collision::Transform& X_RP) {
  const collision::Mat3 A = X_RN.leftCols<3>();
  const Eigen::JacobiSVD<collision::Mat3> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
  collision::Mat3 U = svd.matrixU();
  const collision::Mat3 V = svd.matrixV();
  if ((U * V.transpose()).determinant() < 0) U.col(2) = -U.col(2);
  X_RP.R = U * V.transpose();
  X_RP.t = X_RN.col(3);
  Affine rest = Affine::Zero();
  const collision::Mat3 left = X_RP.R.transpose() * A;
  // A rotation up to rounding keeps the file's vertices bit for bit.
  rest.leftCols<3>() =
      (left - collision::Mat3::Identity()).norm() < 1e-9 ? collision::Mat3::Identity() : left;
  return rest;
}

/// Vertices and triangles of one part being assembled.
struct Geometry {
  std::vector<Vec3> vertices;
  std::vector<TriangleIndices> triangles;
};

/// Counts of what one mesh holds, for limits and notes.
struct FaceCounts {
  std::size_t triangles = 0;
  std::size_t lines_or_points = 0;
  std::size_t polygons = 0;  ///< more than 3 corners left after triangulation
};

FaceCounts count_faces(const aiMesh& mesh) {
  FaceCounts counts;
  for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
    const unsigned n = mesh.mFaces[f].mNumIndices;
    if (n == 3) {
      ++counts.triangles;
    } else if (n < 3) {
      ++counts.lines_or_points;
    } else {
      ++counts.polygons;
    }
  }
  return counts;
}

/// Appends the triangles of `mesh` transformed by X_RN; all the mesh's
/// vertices are appended when it has at least one triangle.
void append(const fs::path& path, const aiMesh& mesh, const Affine& X_RN, Geometry& out) {
  const std::size_t offset = out.vertices.size();
  // Vertices at exactly the same position are one (the first), so that faces
  // that share a corner share its index: a weld by equality, never by
  // distance, so no real vertex, however near another, is lost.
  std::vector<Vec3> local(mesh.mNumVertices);
  for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
    local[v] = Vec3(mesh.mVertices[v].x, mesh.mVertices[v].y, mesh.mVertices[v].z);
  }
  const std::vector<std::uint32_t> welded = collision::welded_ids(local);
  std::vector<std::uint32_t> index(mesh.mNumVertices);
  for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
    if (welded[v] == v) {
      index[v] = static_cast<std::uint32_t>(out.vertices.size() - offset);
      out.vertices.push_back(apply(X_RN, mesh.mVertices[v]));
    } else {
      index[v] = index[welded[v]];  // an earlier vertex, already placed
    }
  }
  // A mirroring transform turns the winding; swap to keep normals outward.
  const bool mirrored = X_RN.leftCols<3>().determinant() < 0;
  for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
    const aiFace& face = mesh.mFaces[f];
    if (face.mNumIndices != 3) continue;
    TriangleIndices t{};
    for (unsigned k = 0; k < 3; ++k) {
      if (face.mIndices[k] >= mesh.mNumVertices) {
        fail(path, "mesh '" + std::string(mesh.mName.C_Str()) + "' face " + std::to_string(f) +
                       " refers to vertex " + std::to_string(face.mIndices[k]) + " of " +
                       std::to_string(mesh.mNumVertices));
      }
      t[k] = static_cast<std::uint32_t>(offset + index[face.mIndices[k]]);
    }
    if (mirrored) std::swap(t[1], t[2]);
    out.triangles.push_back(t);
  }
}

/// Raw scene straight from the reader: coordinates must be finite and sizes
/// within the limits before the post-processing steps work on them. Returns
/// the number of triangles with a repeated vertex position, which the
/// post-processing removes.
std::size_t check_raw_scene(const fs::path& path, const aiScene& scene, const MeshLimits& limits) {
  std::size_t repeated = 0;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh* mesh = scene.mMeshes[m];
    if (mesh == nullptr) fail(path, "mesh " + std::to_string(m) + " is missing");
    std::string name = std::to_string(m);
    if (mesh->mName.length > 0) name.assign(1, '\'').append(mesh->mName.C_Str()).append(1, '\'');
    if (mesh->mNumVertices > limits.max_vertices) {
      fail(path, "mesh " + name + " has " + std::to_string(mesh->mNumVertices) +
                     " vertices, over the limit of " + std::to_string(limits.max_vertices));
    }
    if (mesh->mNumFaces > limits.max_triangles) {
      fail(path, "mesh " + name + " has " + std::to_string(mesh->mNumFaces) +
                     " faces, over the limit of " + std::to_string(limits.max_triangles));
    }
    if (mesh->mVertices == nullptr) {
      if (mesh->mNumVertices > 0) fail(path, "mesh " + name + " has no vertex positions");
      continue;
    }
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D& p = mesh->mVertices[v];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        fail(path, "mesh " + name + " vertex " + std::to_string(v) + " is not finite (" +
                       std::to_string(p.x) + ", " + std::to_string(p.y) + ", " +
                       std::to_string(p.z) + ")");
      }
    }
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3 || face.mIndices == nullptr) continue;
      const unsigned i = face.mIndices[0], j = face.mIndices[1], k = face.mIndices[2];
      if (i >= mesh->mNumVertices || j >= mesh->mNumVertices || k >= mesh->mNumVertices) continue;
      const aiVector3D &a = mesh->mVertices[i], &b = mesh->mVertices[j], &c = mesh->mVertices[k];
      if (a == b || b == c || a == c) ++repeated;
    }
  }
  return repeated;
}

std::string refused_message(const detail::FolderIOSystem& io) {
  std::string text = "refers to ";
  for (std::size_t i = 0; i < io.refused().size(); ++i) {
    if (i > 0) text += ", ";
    text.append(1, '\'').append(io.refused()[i]).append(1, '\'');
  }
  return text + " outside the model's folder, which is not read";
}

[[noreturn]] void fail_import(const fs::path& path, const Assimp::Importer& importer,
                              const detail::FolderIOSystem& io) {
  std::string what = importer.GetErrorString();
  if (!io.refused().empty()) {
    fail(path, refused_message(io) + (what.empty() ? "" : " (" + what + ")"));
  }
  if (what.empty()) what = "unknown reason";
  if (what.find("mNumMeshes is 0") != std::string::npos) {
    fail(path, "cannot be read as a mesh: the importer found no mesh in it (is it a " +
                   path.extension().string() + " file?)");
  }
  fail(path, "cannot be read as a mesh: " + what);
}

std::string part_base_name(const Instance& instance, const aiScene& scene) {
  std::string name = instance.node->mName.C_Str();
  if (name.empty()) name = scene.mMeshes[instance.mesh]->mName.C_Str();
  if (name.empty()) name = "part";
  return name;
}

collision::Mesh validate(Geometry geometry, std::string source, const MeshLimits& limits,
                         collision::MeshValidation& validation) {
  try {
    return collision::make_mesh(std::move(geometry.vertices), std::move(geometry.triangles),
                                std::move(source), limits, &validation);
  } catch (const ImportError&) {
    throw;
  } catch (const collision::MeshError& e) {
    throw ImportError(e.what());
  }
}

ImportReport import_scene(const fs::path& path, const aiScene& scene, const ImportOptions& options,
                          std::vector<std::string> notes) {
  ImportReport report;
  report.notes = std::move(notes);
  if (scene.mRootNode == nullptr) fail(path, "has no scene graph");
  if (scene.mNumMeshes == 0) fail(path, "contains no meshes");

  const std::vector<Instance> instances = collect_instances(path, scene);
  std::vector<bool> referenced(scene.mNumMeshes, false);
  std::size_t polygons = 0;

  // Sizes first, so an instanced mesh cannot multiply past the limits.
  std::size_t total_vertices = 0;
  std::size_t total_triangles = 0;
  std::vector<const Instance*> with_triangles;
  for (const Instance& instance : instances) {
    referenced[instance.mesh] = true;
    const aiMesh& mesh = *scene.mMeshes[instance.mesh];
    const FaceCounts counts = count_faces(mesh);
    report.skipped_line_or_point_primitives += counts.lines_or_points;
    polygons += counts.polygons;
    if (counts.triangles == 0) continue;
    with_triangles.push_back(&instance);
    const std::size_t vertices =
        options.merge ? total_vertices + mesh.mNumVertices : std::size_t{mesh.mNumVertices};
    const std::size_t triangles =
        options.merge ? total_triangles + counts.triangles : counts.triangles;
    if (vertices > options.limits.max_vertices) {
      fail(path, "node instances add up to more than " +
                     std::to_string(options.limits.max_vertices) + " vertices, over the limit");
    }
    if (triangles > options.limits.max_triangles) {
      fail(path, "node instances add up to more than " +
                     std::to_string(options.limits.max_triangles) + " triangles, over the limit");
    }
    total_vertices = vertices;
    total_triangles = triangles;
  }

  if (report.skipped_line_or_point_primitives > 0) {
    report.notes.push_back("skipped " +
                           plural(report.skipped_line_or_point_primitives,
                                  "point or line primitive", "point or line primitives") +
                           " (only triangles take part in collisions)");
  }
  if (polygons > 0) {
    report.notes.push_back("skipped " + plural(polygons, "polygon", "polygons") +
                           " that could not be triangulated");
  }
  const std::size_t unreferenced =
      static_cast<std::size_t>(std::count(referenced.begin(), referenced.end(), false));
  if (unreferenced > 0) {
    report.notes.push_back("ignored " + plural(unreferenced, "mesh", "meshes") +
                           " not placed by any node");
  }
  if (with_triangles.empty()) {
    fail(path, "contains no triangles" +
                   (report.skipped_line_or_point_primitives > 0
                        ? " (only " +
                              plural(report.skipped_line_or_point_primitives,
                                     "point or line primitive", "point or line primitives") +
                              ")"
                        : std::string()));
  }

  if (options.merge) {
    Geometry geometry;
    geometry.vertices.reserve(total_vertices);
    geometry.triangles.reserve(total_triangles);
    for (const Instance* instance : with_triangles) {
      append(path, *scene.mMeshes[instance->mesh], instance->X_RN, geometry);
    }
    ImportedPart part;
    part.name = path.filename().string();
    part.mesh = validate(std::move(geometry), path.string(), options.limits, part.validation);
    report.parts.push_back(std::move(part));
    collect_cameras(scene, report);
    return report;
  }

  std::set<std::string> used_names;
  for (const Instance* instance : with_triangles) {
    const std::string base = part_base_name(*instance, scene);
    std::string name = base;
    for (std::size_t k = 2; used_names.count(name) != 0; ++k) name = base + "_" + std::to_string(k);
    used_names.insert(name);
    Geometry geometry;
    ImportedPart part;
    Affine X_geometry = instance->X_RN;
    if (options.part_frames) X_geometry = split_rigid(instance->X_RN, part.X_RP);
    append(path, *scene.mMeshes[instance->mesh], X_geometry, geometry);
    part.name = name;
    part.node = instance->node_number;
    for (const aiNode* up = instance->node->mParent; up != nullptr; up = up->mParent) {
      part.groups.insert(part.groups.begin(), up->mName.C_Str());
    }
    part.mesh =
        validate(std::move(geometry), path.string() + "#" + name, options.limits, part.validation);
    report.parts.push_back(std::move(part));
  }
  collect_cameras(scene, report);
  return report;
}

}  // namespace

/// The formats Dovetail reads: each reader assimp has is attack surface, so only
/// those of parts and assemblies are let through, chosen by the file's
/// extension (assimp would otherwise guess a reader from the content).
void check_format(const fs::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (const char* known : {".obj", ".stl", ".ply", ".gltf", ".glb"}) {
    if (extension == known) return;
  }
  fail(path, (extension.empty() ? std::string("has no extension")
                                : "is a format Dovetail does not read ('" + extension + "')") +
                 "; meshes are read from .obj, .stl, .ply, .gltf and .glb files");
}

namespace {

bool is_obj(const fs::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension == ".obj";
}

/// assimp's part of an import: the file read, checked and turned into parts.
ImportReport read_with_assimp(const fs::path& path, const ImportOptions& options) {
  // The folder resolved as the file system does: "link/../x" is x beside
  // the link's target, not beside the link, as a textual normalisation would
  // have it. The file keeps its name, so a linked mesh finds its companion
  // files (materials, buffers) beside the link.
  std::error_code ec;
  fs::path absolute = fs::absolute(path);
  const fs::path folder = fs::weakly_canonical(absolute.parent_path(), ec);
  absolute = ec ? absolute.lexically_normal() : folder / absolute.filename();
  Assimp::Importer importer;
  // The importer owns and deletes the IO system; `io` stays valid while it lives.
  auto* io = new detail::FolderIOSystem(absolute.parent_path());
  importer.SetIOHandler(io);
  std::vector<std::string> renamed;
  if (is_obj(path)) {
    if (std::optional<detail::UniqueObjects> unique = detail::obj_with_unique_objects(absolute)) {
      io->substitute(absolute, std::move(unique->text));
      renamed = std::move(unique->notes);
    }
  }
  importer.SetPropertyBool(AI_CONFIG_PP_FD_REMOVE, true);
  // Zero-area triangles are found exactly by make_mesh; assimp's area test uses
  // an absolute threshold that would drop real triangles of small parts.
  importer.SetPropertyBool(AI_CONFIG_PP_FD_CHECKAREA, false);
  // Only positions matter for collisions (and cameras for pictures); dropping
  // the rest leaves positions alone, which `append` welds by equality.
  importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS,
                              aiComponent_NORMALS | aiComponent_TANGENTS_AND_BITANGENTS |
                                  aiComponent_COLORS | aiComponent_TEXCOORDS |
                                  aiComponent_BONEWEIGHTS | aiComponent_ANIMATIONS |
                                  aiComponent_TEXTURES | aiComponent_LIGHTS);

  const aiScene* scene = nullptr;
  std::size_t repeated = 0;
  unsigned raw_meshes = 0;
  try {
    // Read and validate the structure only, check coordinates and sizes, then
    // post-process: FindInvalidData would silently delete a mesh with a NaN
    // vertex, and a broken file must be an error instead.
    scene = importer.ReadFile(absolute.string(), aiProcess_ValidateDataStructure);
    if (scene == nullptr) fail_import(path, importer, *io);
    repeated = check_raw_scene(path, *scene, options.limits);
    raw_meshes = scene->mNumMeshes;
    scene = importer.ApplyPostProcessing(aiProcess_Triangulate | aiProcess_ValidateDataStructure |
                                         aiProcess_FindDegenerates | aiProcess_FindInvalidData |
                                         aiProcess_SortByPType | aiProcess_RemoveComponent);
    if (scene == nullptr) fail_import(path, importer, *io);
  } catch (const ImportError&) {
    throw;
  } catch (const std::bad_alloc&) {
    fail(path, "ran out of memory while reading");
  } catch (const std::exception& e) {
    fail(path, std::string("cannot be read as a mesh: ") + e.what());
  } catch (...) {
    fail(path, "cannot be read as a mesh: unknown failure in the importer");
  }

  if (scene->mNumMeshes == 0 && raw_meshes > 0 && repeated > 0) {
    fail(path, "contains no usable triangles: every face repeats a vertex");
  }
  std::vector<std::string> notes = std::move(renamed);
  if (!io->refused().empty()) notes.push_back(refused_message(*io));
  if (repeated > 0) {
    notes.push_back(
        "removed " +
        plural(repeated, "triangle with a repeated vertex", "triangles with a repeated vertex") +
        " while reading");
  }
  ImportReport report = import_scene(path, *scene, options, std::move(notes));
  report.files = io->opened();
  return report;
}

}  // namespace

ImportReport import_file(const fs::path& path, const ImportOptions& options) {
  const std::uintmax_t size = check_file(path);
  check_format(path);
  if (std::optional<std::string> wrong = detail::check_declared_sizes(path, size, options.limits)) {
    fail(path, *wrong);
  }
  if (!options.in_child_process) return read_with_assimp(path, options);
  // What a legitimate import needs is some tens of times the size of what it
  // reads; the cap stops a file that talks assimp into allocating tens of
  // gigabytes. A .gltf names its buffers, files beside it: the folder's
  // files count.
  std::uintmax_t reads = size;
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension == ".gltf") {
    std::error_code ec;
    const fs::path folder = path.has_parent_path() ? path.parent_path() : fs::path(".");
    for (auto it = fs::directory_iterator(folder, ec); !ec && it != fs::directory_iterator();
         it.increment(ec)) {
      std::error_code kind;
      if (it->is_regular_file(kind)) reads += it->file_size(kind);
    }
  }
  constexpr std::uintmax_t kGiB = std::uintmax_t{1} << 30;
  const std::uintmax_t budget = 4 * kGiB + std::min<std::uintmax_t>(reads, 16 * kGiB) * 64;
  return detail::import_in_child(
      path, [&] { return read_with_assimp(path, options); }, budget);
}

collision::Mesh import_mesh(const fs::path& path, collision::MeshValidation* validation) {
  ImportReport report = import_file(path, {});
  if (validation != nullptr) *validation = report.parts.front().validation;
  return std::move(report.parts.front().mesh);
}

}  // namespace dovetail::engine
