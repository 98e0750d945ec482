#include "dovetail/engine/scene.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <map>
#include <utility>

namespace dovetail::engine {

namespace fs = std::filesystem;
using collision::Mesh;
using collision::Vec3;

namespace {

std::string in_quotes(std::string_view name) { return "'" + std::string(name) + "'"; }

bool name_less(const std::pair<std::string, std::uint32_t>& entry, std::string_view name) {
  return entry.first < name;
}

}  // namespace

Transform compose(const Transform& X_AB, const Transform& X_BC) {
  Transform X_AC;
  X_AC.R = X_AB.R * X_BC.R;
  X_AC.t = X_AB.apply(X_BC.t);
  return X_AC;
}

const Scene::Slot& Scene::slot(PartId part) const {
  if (!part.valid() || part.index >= slots_.size() || !slots_[part.index].alive ||
      slots_[part.index].generation != part.generation) {
    throw SceneError("scene: stale or invalid part handle (index " + std::to_string(part.index) +
                     ", generation " + std::to_string(part.generation) + ")");
  }
  return slots_[part.index];
}

Scene::Slot& Scene::slot(PartId part) {
  return const_cast<Slot&>(static_cast<const Scene&>(*this).slot(part));
}

bool Scene::contains(PartId part) const {
  return part.valid() && part.index < slots_.size() && slots_[part.index].alive &&
         slots_[part.index].generation == part.generation;
}

PartId Scene::find(std::string_view name) const {
  const auto it = std::lower_bound(by_name_.begin(), by_name_.end(), name, name_less);
  if (it == by_name_.end() || it->first != name) return {};
  return {it->second, slots_[it->second].generation};
}

PartId Scene::get(std::string_view name) const {
  const PartId part = find(name);
  if (!part.valid()) throw SceneError("scene: no part named " + in_quotes(name));
  return part;
}

PartId Scene::add_part(const PartDef& desc) {
  if (desc.name.empty()) throw SceneError("scene: a part needs a name");
  const auto at = std::lower_bound(by_name_.begin(), by_name_.end(), desc.name, name_less);
  if (at != by_name_.end() && at->first == desc.name) {
    throw SceneError("scene: duplicate part name " + in_quotes(desc.name));
  }
  PartId parent;
  if (!desc.parent.empty()) {
    parent = find(desc.parent);
    if (!parent.valid()) {
      throw SceneError("scene: part " + in_quotes(desc.name) + " has an unknown parent " +
                       in_quotes(desc.parent));
    }
  }
  std::uint32_t index = 0;
  if (!free_.empty()) {
    index = free_.back();
    free_.pop_back();
  } else {
    index = static_cast<std::uint32_t>(slots_.size());
    slots_.emplace_back();
  }
  Slot& s = slots_[index];
  s.alive = true;
  s.name = desc.name;
  s.tags = desc.tags;
  s.parent = parent;
  s.X_QP = desc.X_QP;
  s.movable = desc.movable;
  s.collision_group = desc.collision_group;
  s.color = desc.color;
  s.render_mesh = desc.render_mesh;
  s.collision_mesh = desc.collision_mesh ? desc.collision_mesh : desc.render_mesh;
  by_name_.insert(at, {desc.name, index});
  ++count_;
  touch();
  return {index, s.generation};
}

void Scene::remove_part(PartId part) {
  const Slot& removed = slot(part);
  const PartId grandparent = removed.parent;
  for (const PartId child : children(part)) set_parent(child, grandparent, true);
  Slot& s = slot(part);
  const auto at = std::lower_bound(by_name_.begin(), by_name_.end(), s.name, name_less);
  by_name_.erase(at);
  const std::uint32_t generation = s.generation + 1;
  s = Slot{};
  s.generation = generation;
  free_.push_back(part.index);
  --count_;
  touch();
}

std::vector<PartId> Scene::parts() const {
  std::vector<PartId> out;
  out.reserve(by_name_.size());
  for (const auto& [name, index] : by_name_) out.push_back({index, slots_[index].generation});
  return out;
}

std::vector<PartId> Scene::parts_with_tag(std::string_view tag) const {
  std::vector<PartId> out;
  for (const PartId part : parts()) {
    if (has_tag(part, tag)) out.push_back(part);
  }
  return out;
}

const std::string& Scene::name(PartId part) const { return slot(part).name; }
const std::vector<std::string>& Scene::tags(PartId part) const { return slot(part).tags; }

bool Scene::has_tag(PartId part, std::string_view tag) const {
  const auto& t = slot(part).tags;
  return std::find(t.begin(), t.end(), tag) != t.end();
}

void Scene::add_tag(PartId part, const std::string& tag) {
  if (!has_tag(part, tag)) slot(part).tags.push_back(tag);
}

PartId Scene::parent(PartId part) const { return slot(part).parent; }

std::vector<PartId> Scene::children(PartId part) const {
  slot(part);
  std::vector<PartId> out;
  for (const PartId p : parts()) {
    if (slots_[p.index].parent == part) out.push_back(p);
  }
  return out;
}

bool Scene::descends_from(PartId part, PartId ancestor) const {
  for (PartId p = part; p.valid(); p = slot(p).parent) {
    if (p == ancestor) return true;
  }
  return false;
}

void Scene::set_parent(PartId part, PartId parent, bool keep_world_pose) {
  const Transform X_WP = world_pose(part);
  if (parent.valid() && descends_from(parent, part)) {
    throw SceneError("scene: making " + in_quotes(name(parent)) + " the parent of " +
                     in_quotes(name(part)) + " would make a cycle");
  }
  slot(part).parent = parent;
  touch();
  if (keep_world_pose) set_world_pose(part, X_WP);
}

const Transform& Scene::local_pose(PartId part) const { return slot(part).X_QP; }
void Scene::set_local_pose(PartId part, const Transform& X_QP) {
  slot(part).X_QP = X_QP;
  touch();
}

Transform Scene::world_pose(PartId part) const {
  const Slot& leaf = slot(part);
  if (!leaf.parent.valid()) return leaf.X_QP;  // the common case: a part in the world
  // Iterative, root first, so a deep chain cannot exhaust the stack; chains
  // of up to 16 parts without an allocation.
  std::array<const Slot*, 16> near;
  std::vector<const Slot*> deep;
  std::size_t depth = 0;
  for (PartId p = part; p.valid(); p = slot(p).parent) {
    if (depth == near.size()) deep.assign(near.begin(), near.end());
    if (depth < near.size())
      near[depth] = &slot(p);
    else
      deep.push_back(&slot(p));
    ++depth;
  }
  const Slot* const* chain = depth <= near.size() ? near.data() : deep.data();
  Transform X_WP = chain[depth - 1]->X_QP;  // the root, in the world
  for (std::size_t k = depth - 1; k > 0; --k) X_WP = compose(X_WP, chain[k - 1]->X_QP);
  return X_WP;
}

void Scene::set_world_pose(PartId part, const Transform& X_WP) {
  const PartId parent = slot(part).parent;
  slot(part).X_QP = parent.valid() ? compose(world_pose(parent).inverse(), X_WP) : X_WP;
  touch();
}

void Scene::touch() {
  static std::atomic<std::uint64_t> last{0};
  revision_ = last.fetch_add(1, std::memory_order_relaxed) + 1;
}

bool Scene::movable(PartId part) const { return slot(part).movable; }
const std::string& Scene::collision_group(PartId part) const { return slot(part).collision_group; }
const std::optional<std::array<float, 3>>& Scene::color(PartId part) const {
  return slot(part).color;
}
void Scene::set_movable(PartId part, bool movable) { slot(part).movable = movable; }
void Scene::set_highlight(PartId part, const std::optional<std::array<float, 3>>& color) {
  slot(part).highlight = color;
}
const std::optional<std::array<float, 3>>& Scene::highlight(PartId part) const {
  return slot(part).highlight;
}
void Scene::set_visible(PartId part, bool visible) { slot(part).visible = visible; }
bool Scene::visible(PartId part) const { return slot(part).visible; }

const std::shared_ptr<const Mesh>& Scene::render_mesh(PartId part) const {
  return slot(part).render_mesh;
}
const std::shared_ptr<const Mesh>& Scene::collision_mesh(PartId part) const {
  return slot(part).collision_mesh;
}

namespace {

/// Bounds of all parts in the file's root frame, in file units.
collision::Bounds assembly_bounds(const std::vector<ImportedPart>& parts) {
  collision::Bounds b{Vec3::Constant(INFINITY), Vec3::Constant(-INFINITY)};
  for (const ImportedPart& part : parts) {
    for (const Vec3& p : part.mesh.vertices) {
      const Vec3 p_R = part.X_RP.apply(p);
      b.min = b.min.cwiseMin(p_R);
      b.max = b.max.cwiseMax(p_R);
    }
  }
  return b;
}

/// Key of a mesh's exact content, for sharing identical meshes.
std::string mesh_key(const Mesh& mesh) {
  std::string key;
  key.resize(mesh.vertices.size() * sizeof(double) * 3 +
             mesh.triangles.size() * sizeof(collision::TriangleIndices));
  char* out = key.data();
  for (const Vec3& v : mesh.vertices) {
    std::memcpy(out, v.data(), sizeof(double) * 3);
    out += sizeof(double) * 3;
  }
  for (const auto& t : mesh.triangles) {
    std::memcpy(out, t.data(), sizeof(t));
    out += sizeof(t);
  }
  return key;
}

}  // namespace

void Scene::add_camera(const std::string& name, const Camera& camera) {
  if (name.empty()) throw SceneError("scene: a camera needs a name");
  for (const NamedCamera& c : cameras_) {
    if (c.first == name) throw SceneError("scene: duplicate camera name '" + name + "'");
  }
  cameras_.emplace_back(name, camera);
}

Scene load_assembly(const fs::path& path, const AssemblyOptions& options, AssemblyReport* report) {
  ImportOptions import_options;
  import_options.merge = false;
  import_options.part_frames = true;
  import_options.limits = options.limits;
  ImportReport imported = import_file(path, import_options);

  AssemblyReport summary;
  summary.notes = imported.notes;
  summary.files = imported.files;
  summary.skipped_line_or_point_primitives = imported.skipped_line_or_point_primitives;
  if (!(options.units >= 0) || !std::isfinite(options.units)) {
    throw ImportError(path.string() + ": units must be a positive number of metres per unit");
  }
  summary.units = options.units;
  if (options.units == 0) {
    const collision::Bounds b = assembly_bounds(imported.parts);
    const double extent = (b.max - b.min).maxCoeff();
    summary.units_inferred = true;
    summary.units = extent > kMillimetreThreshold ? 0.001 : 1.0;
    summary.notes.push_back("units inferred: largest extent " + std::to_string(extent) +
                            (summary.units == 1.0 ? " file units, read as metres"
                                                  : " file units, read as millimetres"));
  }

  Scene scene;
  std::map<std::string, std::shared_ptr<const Mesh>> shared;
  for (ImportedPart& part : imported.parts) {
    Mesh mesh = std::move(part.mesh);
    if (summary.units != 1.0) {
      for (Vec3& v : mesh.vertices) v *= summary.units;
    }
    std::string key = mesh_key(mesh);
    auto it = shared.find(key);
    if (it == shared.end()) {
      it = shared.emplace(std::move(key), std::make_shared<const Mesh>(std::move(mesh))).first;
    } else {
      ++summary.shared_meshes;
    }
    PartDef desc;
    desc.name = part.name;
    desc.tags = options.tags;
    desc.X_QP = part.X_RP;
    desc.X_QP.t *= summary.units;
    desc.movable = options.movable;
    desc.render_mesh = it->second;
    scene.add_part(desc);
    summary.triangles += it->second->triangle_count();
    ++summary.parts;
  }
  for (auto& [name, camera] : imported.cameras) {
    camera.eye *= summary.units;
    camera.target *= summary.units;
    scene.add_camera(name, camera);
  }
  if (report != nullptr) *report = std::move(summary);
  return scene;
}

}  // namespace dovetail::engine
