#include "dovetail/collision/model.h"

#include <array>
#include <stdexcept>
#include <string>
#include <utility>

#include "polygon/aabb_tree.h"
#include "polygon/boxtree.h"
#include "polygon/brute_force.h"
#include "polygon/dop_tree.h"
#include "polygon/obb_tree.h"

namespace dovetail::collision {

namespace {

constexpr std::array<Method, 8> kMethods = {Method::kBoxtree, Method::kDop6,  Method::kDop14,
                                            Method::kDop18,   Method::kDop26, Method::kAabb,
                                            Method::kObb,     Method::kBrute};
constexpr std::array<std::string_view, 8> kNames = {"boxtree", "dop6", "dop14", "dop18",
                                                    "dop26",   "aabb", "obb",   "brute"};

/// A CollisionModel over one structure type; queries require both models to
/// be of the same Method.
template <typename Structure>
class StructureModel final : public CollisionModel {
 public:
  template <typename... Args>
  StructureModel(Method method, std::shared_ptr<const Mesh> mesh, Args&&... args)
      : CollisionModel(method, std::move(mesh)),
        structure_(this->mesh(), std::forward<Args>(args)...) {}

  ModelInfo info() const override {
    ModelInfo info;
    if constexpr (requires { structure_.node_count(); }) {
      info.nodes = structure_.node_count();
      info.leaves = structure_.leaf_count();
      info.depth = structure_.depth();
    }
    info.bytes = structure_.bytes();
    info.bytes_per_triangle = static_cast<double>(info.bytes) / mesh().triangle_count();
    return info;
  }

  const StructureModel& same_method(const CollisionModel& b) const {
    if (b.method() != method()) {
      throw std::invalid_argument("collide: models of methods " +
                                  std::string(method_name(method())) + " and " +
                                  std::string(method_name(b.method())) + " cannot be paired");
    }
    return static_cast<const StructureModel&>(b);
  }

  CollideResult collide(const CollisionModel& b, const Transform& X_AB,
                        const CollideRequest& request) const override {
    return structure_.collide(mesh(), same_method(b).structure_, b.mesh(), X_AB, request);
  }

  std::unique_ptr<SplitQuery> split(const CollisionModel& b, const Transform& X_AB,
                                    const CollideRequest& request) const override {
    return structure_.split(mesh(), same_method(b).structure_, b.mesh(), X_AB, request);
  }

  bool search_triangle(const std::array<Vec3, 3>& corners, Real margin, TriangleVisit visit,
                       CollideStats& stats) const override {
    if constexpr (requires { structure_.search_triangle(corners, margin, visit, stats); }) {
      return structure_.search_triangle(corners, margin, visit, stats);
    } else {
      return CollisionModel::search_triangle(corners, margin, visit, stats);
    }
  }

 private:
  Structure structure_;
};

}  // namespace

bool CollisionModel::search_triangle(const std::array<Vec3, 3>&, Real, TriangleVisit,
                                     CollideStats&) const {
  return false;
}

CollideResult CollisionModel::collide_parallel(const CollisionModel& b, const Transform& X_AB,
                                               const CollideRequest& request,
                                               TaskSystem& tasks) const {
  const std::unique_ptr<SplitQuery> query = split(b, X_AB, request);
  tasks.parallel_for(query->parts(), 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) query->run(i);
  });
  return query->result();
}

std::string_view method_name(Method method) { return kNames[static_cast<std::size_t>(method)]; }

std::optional<Method> parse_method(std::string_view name) {
  for (std::size_t i = 0; i < kNames.size(); ++i) {
    if (kNames[i] == name) return kMethods[i];
  }
  return std::nullopt;
}

std::span<const Method> all_methods() { return kMethods; }

std::shared_ptr<const CollisionModel> build_model(Method method, std::shared_ptr<const Mesh> mesh) {
  if (!mesh) throw std::invalid_argument("build_model: no mesh");
  check_mesh(*mesh);  // a mesh built by hand may hold what the hierarchies cannot
  switch (method) {
    case Method::kBoxtree:
      return std::make_shared<StructureModel<Boxtree>>(method, std::move(mesh));
    case Method::kDop6:
      return std::make_shared<StructureModel<DopTree>>(method, std::move(mesh), 6);
    case Method::kDop14:
      return std::make_shared<StructureModel<DopTree>>(method, std::move(mesh), 14);
    case Method::kDop18:
      return std::make_shared<StructureModel<DopTree>>(method, std::move(mesh), 18);
    case Method::kDop26:
      return std::make_shared<StructureModel<DopTree>>(method, std::move(mesh), 26);
    case Method::kAabb:
      return std::make_shared<StructureModel<AabbTree>>(method, std::move(mesh));
    case Method::kObb:
      return std::make_shared<StructureModel<ObbTree>>(method, std::move(mesh));
    case Method::kBrute:
      return std::make_shared<StructureModel<BruteForce>>(method, std::move(mesh));
  }
  throw std::invalid_argument("build_model: unknown method");
}

}  // namespace dovetail::collision
