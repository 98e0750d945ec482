#pragma once
/// \file scene.h
/// The scene/object layer: named parts with tags, a parent/child transform
/// hierarchy, static or movable parts, and per part a render mesh and a
/// collision mesh; and assembly import, one part per mesh node of a file.
///
/// Why: everything above the collision layer (scripts, the hand, reports)
/// speaks of parts by name. The scene owns those names and the hierarchy, so
/// a sub-assembly moves as one: a part's world pose is its parent's world
/// pose times its local pose, X_WP = X_WQ * X_QP. Parts are flat arrays
/// addressed by PartId (index + generation), never by pointer; meshes are
/// shared (`shared_ptr<const Mesh>`) between instances of the same geometry.

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "dovetail/collision/mesh.h"
#include "dovetail/collision/types.h"
#include "dovetail/engine/camera.h"
#include "dovetail/engine/mesh_import.h"

namespace dovetail::engine {

using collision::Transform;

/// Thrown for a misuse of the scene: a duplicate, empty or unknown part
/// name, a stale handle, a cycle in the hierarchy. what() names the part.
class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Identifies a part of a Scene: slot index and generation, so a handle of a
/// removed part is recognised as stale.
struct PartId {
  std::uint32_t index = std::numeric_limits<std::uint32_t>::max();
  std::uint32_t generation = 0;
  /// Whether the handle refers to some part (it may still be stale).
  bool valid() const { return index != std::numeric_limits<std::uint32_t>::max(); }
  friend bool operator==(const PartId&, const PartId&) = default;
  friend auto operator<=>(const PartId&, const PartId&) = default;
};

/// A part to add to a scene.
struct PartDef {
  std::string name{};               ///< unique in the scene, not empty
  std::vector<std::string> tags{};  ///< free labels ("fastener", "housing")
  std::string parent{};             ///< name of the parent part; empty: the world
  Transform X_QP{};                 ///< local pose: the part in its parent's frame
  bool movable = true;              ///< false: fixed; pairs of two fixed parts are never tested
  /// Geometry to draw; may be null for a group (a sub-assembly node).
  std::shared_ptr<const collision::Mesh> render_mesh{};
  /// Geometry for collisions; null: the render mesh.
  std::shared_ptr<const collision::Mesh> collision_mesh{};
  /// Parts of the same non-empty group are never tested against each other
  /// (the segments of a hand, which overlap at their joints).
  std::string collision_group{};
  /// Display colour (RGB in [0, 1]); none: the renderer's palette.
  std::optional<std::array<float, 3>> color{};
};

/// Named parts in a transform hierarchy.
class Scene {
 public:
  /// Adds a part. Throws SceneError for an empty or duplicate name or an
  /// unknown parent.
  PartId add_part(const PartDef& def);
  /// Removes a part; its children become children of its parent, keeping
  /// their world poses. Throws SceneError for a stale handle.
  void remove_part(PartId part);

  /// The part named `name`, or an invalid handle.
  PartId find(std::string_view name) const;
  /// The part named `name`; throws SceneError naming it when there is none.
  PartId get(std::string_view name) const;
  /// Whether `part` refers to a live part.
  bool contains(PartId part) const;

  /// All live parts, in name order (the deterministic order of the scene).
  std::vector<PartId> parts() const;
  /// Live parts carrying `tag`, in name order.
  std::vector<PartId> parts_with_tag(std::string_view tag) const;
  std::size_t part_count() const { return count_; }
  /// A stamp of the parts' names and poses: it changes whenever a part is
  /// added or removed, re-parented or given a pose. Stamps are unique in the
  /// process, so two scenes with the same stamp (a scene and its copy) have
  /// the same parts, names and poses.
  std::uint64_t revision() const { return revision_; }

  const std::string& name(PartId part) const;
  const std::vector<std::string>& tags(PartId part) const;
  bool has_tag(PartId part, std::string_view tag) const;
  void add_tag(PartId part, const std::string& tag);

  /// The parent, or an invalid handle for a part placed in the world.
  PartId parent(PartId part) const;
  /// Direct children, in name order.
  std::vector<PartId> children(PartId part) const;
  /// Whether `part` is `ancestor` or is attached to it, directly or through
  /// other parts: it moves when `ancestor` does.
  bool descends_from(PartId part, PartId ancestor) const;
  /// Re-parents `part` (an invalid `parent` means the world). With
  /// keep_world_pose the local pose is changed so the part stays where it
  /// is; otherwise the local pose is kept. Throws SceneError on a cycle.
  void set_parent(PartId part, PartId parent, bool keep_world_pose = true);

  /// X_QP, the part in its parent's frame (the world's for a root part).
  const Transform& local_pose(PartId part) const;
  void set_local_pose(PartId part, const Transform& X_QP);
  void set_local_pose(std::string_view name, const Transform& X_QP) {
    set_local_pose(get(name), X_QP);
  }
  /// X_WP, the part P in the world: X_WQ * X_QP with Q its parent, composed
  /// from the root down.
  Transform world_pose(PartId part) const;
  Transform world_pose(std::string_view name) const { return world_pose(get(name)); }
  /// Sets the local pose X_QP so that the part's world pose becomes X_WP.
  void set_world_pose(PartId part, const Transform& X_WP);

  const std::string& collision_group(PartId part) const;
  const std::optional<std::array<float, 3>>& color(PartId part) const;
  /// A display colour drawn in place of the part's own while set (scripts
  /// highlight parts this way); nullopt removes it. Rendering only.
  void set_highlight(PartId part, const std::optional<std::array<float, 3>>& color);
  const std::optional<std::array<float, 3>>& highlight(PartId part) const;
  /// Whether the part is drawn (default true). Rendering only: a hidden part
  /// still collides.
  void set_visible(PartId part, bool visible);
  bool visible(PartId part) const;

  bool movable(PartId part) const;
  void set_movable(PartId part, bool movable);

  const std::shared_ptr<const collision::Mesh>& render_mesh(PartId part) const;
  /// The collision mesh (the render mesh unless another was given); may be null.
  const std::shared_ptr<const collision::Mesh>& collision_mesh(PartId part) const;

  /// Adds a named camera (in the world frame) for rendering. Throws
  /// SceneError for an empty or duplicate name.
  void add_camera(const std::string& name, const Camera& camera);
  /// Named cameras in the order added (an assembly file's own come first).
  const std::vector<NamedCamera>& cameras() const { return cameras_; }

 private:
  struct Slot {
    std::uint32_t generation = 0;
    bool alive = false;
    std::string name;
    std::vector<std::string> tags;
    PartId parent;
    Transform X_QP;
    bool movable = true;
    std::string collision_group;
    std::optional<std::array<float, 3>> color;
    std::optional<std::array<float, 3>> highlight;
    bool visible = true;
    std::shared_ptr<const collision::Mesh> render_mesh;
    std::shared_ptr<const collision::Mesh> collision_mesh;
  };
  const Slot& slot(PartId part) const;
  Slot& slot(PartId part);

  std::vector<Slot> slots_;
  std::vector<std::uint32_t> free_;
  /// (name, index) sorted by name: lookups by binary search, iteration in name order.
  std::vector<std::pair<std::string, std::uint32_t>> by_name_;
  std::size_t count_ = 0;
  std::uint64_t revision_ = 0;
  /// A new revision stamp, after a change of parts, parents or poses.
  void touch();
  std::vector<NamedCamera> cameras_;
};

/// X_AC = X_AB * X_BC.
Transform compose(const Transform& X_AB, const Transform& X_BC);

/// How to load an assembly file.
struct AssemblyOptions {
  /// Limits passed to the importer (merge and part_frames are set by the loader).
  collision::MeshLimits limits;
  /// Metres per file unit; 0: inferred (see docs/engine.md: a file whose
  /// bounding box is larger than kMillimetreThreshold along some axis is in
  /// millimetres, otherwise in metres).
  double units = 0;
  bool movable = true;            ///< movable flag of every loaded part
  std::vector<std::string> tags;  ///< tags given to every loaded part
};

/// A bounding box larger than this (in file units) along some axis means the
/// file is in millimetres, when the units are not declared.
inline constexpr double kMillimetreThreshold = 100.0;

/// Metres per unit of a unit's name, "mm", "cm" or "m"; nullopt for any other.
inline std::optional<double> metres_per_unit(std::string_view unit) {
  if (unit == "mm") return 0.001;
  if (unit == "cm") return 0.01;
  if (unit == "m") return 1.0;
  return std::nullopt;
}

/// What loading an assembly did and noticed.
struct AssemblyReport {
  double units = 1;             ///< metres per file unit used
  bool units_inferred = false;  ///< true when AssemblyOptions::units was 0
  std::size_t parts = 0;
  std::size_t triangles = 0;
  std::size_t shared_meshes = 0;  ///< parts that reuse another part's mesh
  std::size_t skipped_line_or_point_primitives = 0;
  std::vector<std::string> notes;  ///< from the importer and the loader
  std::vector<std::string> files;  ///< every file read (ImportReport::files)
};

/// Loads `path` as a scene: one part per mesh instance of every node, named
/// as the importer names them (unique), placed at the node's pose in the
/// file's root frame (a flat list: intermediate nodes are folded into the
/// parts' poses), scaled to metres. Identical meshes are shared. The file's
/// perspective cameras become the scene's named cameras. Throws
/// ImportError naming the file for anything import_file refuses.
Scene load_assembly(const std::filesystem::path& path, const AssemblyOptions& options = {},
                    AssemblyReport* report = nullptr);

}  // namespace dovetail::engine
