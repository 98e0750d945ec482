#pragma once
/// \file model.h
/// One entry point over every polygon-level method: build a CollisionModel
/// for a mesh once, then query pairs of models of the same method.
///
/// Why: the command line, the benchmarks and the tests compare methods side by
/// side; they choose a Method at run time and must not care which hierarchy
/// type sits behind it. A built model is immutable and may be shared and
/// queried from any number of threads at once.

#include <array>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <type_traits>

#include "dovetail/collision/collide.h"
#include "dovetail/collision/mesh.h"
#include "dovetail/collision/task_system.h"
#include "dovetail/collision/types.h"

namespace dovetail::collision {

/// Polygon-level methods. kBrute tests every triangle pair (the reference).
enum class Method { kBoxtree, kDop6, kDop14, kDop18, kDop26, kAabb, kObb, kBrute };

/// Command-line name: boxtree, dop6, dop14, dop18, dop26, aabb, obb, brute.
std::string_view method_name(Method method);
/// Inverse of method_name; nullopt for an unknown name.
std::optional<Method> parse_method(std::string_view name);
/// Every method, in the order above.
std::span<const Method> all_methods();

/// Shape and size of a built hierarchy.
struct ModelInfo {
  std::size_t nodes = 0;  ///< all nodes, leaves included
  std::size_t leaves = 0;
  std::size_t depth = 0;  ///< longest root-to-leaf path, root = 1
  std::size_t bytes = 0;  ///< memory of the hierarchy itself (not the mesh)
  double bytes_per_triangle = 0.0;
};

/// One query divided into a fixed number of independent parts (node pairs
/// near the top of the traversal, or rows of brute force). Parts may run on
/// any threads, in any order, each exactly once; result() then merges them.
/// Parts of several queries can share one parallel loop, which balances
/// heavy pairs of different sizes better than one loop per pair.
class SplitQuery {
 public:
  virtual ~SplitQuery() = default;
  virtual std::size_t parts() const = 0;
  /// Runs part `i`; distinct parts may run concurrently.
  virtual void run(std::size_t i) = 0;
  /// The merged result, once every part has run: the verdict of collide();
  /// all-pairs results equal collide()'s exactly; a first-hit result reports
  /// the smallest of the parts' first hits. Independent of the thread count.
  virtual CollideResult result() = 0;
};

/// What CollisionModel::search_triangle calls for each triangle it visits:
/// a reference to a callable `bool(std::uint32_t)`, which it does not own
/// or copy (the callable must outlive the call that takes it, as a lambda
/// written in the call's arguments does). Unlike std::function it never
/// allocates: the search runs in the pipeline's inner loop.
class TriangleVisit {
 public:
  template <typename F>
  requires(!std::is_same_v<std::remove_cvref_t<F>, TriangleVisit> &&
           std::is_invocable_r_v<bool, F&, std::uint32_t>)
      TriangleVisit(F&& f)  // NOLINT(google-explicit-constructor): a reference, as a lambda
      : object_(const_cast<void*>(static_cast<const void*>(std::addressof(f)))),
        call_([](void* object, std::uint32_t t) -> bool {
          return (*static_cast<std::remove_reference_t<F>*>(object))(t);
        }) {}

  bool operator()(std::uint32_t t) const { return call_(object_, t); }

 private:
  void* object_;
  bool (*call_)(void*, std::uint32_t);
};

/// A mesh with its hierarchy for one Method. Immutable after build.
class CollisionModel {
 public:
  virtual ~CollisionModel() = default;
  CollisionModel(const CollisionModel&) = delete;
  CollisionModel& operator=(const CollisionModel&) = delete;

  Method method() const { return method_; }
  const Mesh& mesh() const { return *mesh_; }
  const std::shared_ptr<const Mesh>& shared_mesh() const { return mesh_; }
  virtual ModelInfo info() const = 0;

  /// Collision query with this model as A and `b` as B, X_AB the pose of B in
  /// A's frame. Throws std::invalid_argument when b was built for another Method.
  virtual CollideResult collide(const CollisionModel& b, const Transform& X_AB,
                                const CollideRequest& request = {}) const = 0;

  /// The triangles of this model that may meet one triangle: calls
  /// visit(t) for each triangle t of each leaf whose volume meets `corners`
  /// (given in this model's frame) widened by `margin`, depth first, until a
  /// call returns true; returns whether one did. Conservative: a triangle
  /// never visited does not meet `corners`. Proves nothing about those it
  /// visits: the caller tests them. Each volume tested counts in
  /// stats.triangle_volume_tests. Only the OBB tree has this search; the
  /// other hierarchies visit nothing and return false.
  virtual bool search_triangle(const std::array<Vec3, 3>& corners, Real margin, TriangleVisit visit,
                               CollideStats& stats) const;

  /// The same query divided into independent parts (the fine-grain
  /// parallelism for one heavy pair). `b`, the models' meshes and this model
  /// must outlive the returned query.
  virtual std::unique_ptr<SplitQuery> split(const CollisionModel& b, const Transform& X_AB,
                                            const CollideRequest& request) const = 0;

  /// split() run on `tasks`: see SplitQuery::result for what equals collide().
  CollideResult collide_parallel(const CollisionModel& b, const Transform& X_AB,
                                 const CollideRequest& request, TaskSystem& tasks) const;

 protected:
  CollisionModel(Method method, std::shared_ptr<const Mesh> mesh)
      : method_(method), mesh_(std::move(mesh)) {}

 private:
  Method method_;
  std::shared_ptr<const Mesh> mesh_;
};

/// Builds the hierarchy of `method` for `mesh` (top-down, once). Throws
/// MeshError for a mesh with no triangles, a non-finite vertex or an index
/// out of range (check_mesh).
std::shared_ptr<const CollisionModel> build_model(Method method, std::shared_ptr<const Mesh> mesh);

}  // namespace dovetail::collision
