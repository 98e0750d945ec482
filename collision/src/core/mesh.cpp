#include "dovetail/collision/mesh.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <string>
#include <tuple>
#include <utility>

#include "dovetail/collision/predicates.h"

namespace dovetail::collision {

namespace {

[[noreturn]] void fail(const std::string& source, const std::string& what) {
  throw MeshError(source + ": " + what);
}

void check_vertices(const std::vector<Vec3>& vertices, const std::string& source,
                    const MeshLimits& limits) {
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      const Real c = vertices[i][k];
      if (!std::isfinite(c)) fail(source, "vertex " + std::to_string(i) + " is not finite");
      if (std::abs(c) > limits.max_abs_coordinate) {
        char bound[32];
        std::snprintf(bound, sizeof bound, "%g", limits.max_abs_coordinate);
        fail(source, "vertex " + std::to_string(i) + " has a coordinate beyond ±" + bound);
      }
    }
  }
}

void check_indices(std::size_t i, const TriangleIndices& t, std::size_t vertices,
                   const std::string& source) {
  for (std::uint32_t v : t) {
    if (v >= vertices) {
      fail(source, "triangle " + std::to_string(i) + " references vertex " + std::to_string(v) +
                       " of " + std::to_string(vertices));
    }
  }
}

}  // namespace

void check_mesh(const Mesh& mesh) {
  if (mesh.triangles.empty()) fail(mesh.source, "mesh has no triangles");
  check_vertices(mesh.vertices, mesh.source,
                 {.max_abs_coordinate = std::numeric_limits<Real>::max()});
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    check_indices(i, mesh.triangles[i], mesh.vertices.size(), mesh.source);
  }
}

Mesh make_mesh(std::vector<Vec3> vertices, std::vector<TriangleIndices> triangles,
               std::string source, const MeshLimits& limits, MeshValidation* validation) {
  MeshValidation found;
  found.input_vertices = vertices.size();
  found.input_triangles = triangles.size();

  if (vertices.empty()) fail(source, "mesh has no vertices");
  if (triangles.empty()) fail(source, "mesh has no triangles");
  if (vertices.size() > limits.max_vertices) {
    fail(source, std::to_string(vertices.size()) + " vertices exceed the limit of " +
                     std::to_string(limits.max_vertices));
  }
  if (triangles.size() > limits.max_triangles) {
    fail(source, std::to_string(triangles.size()) + " triangles exceed the limit of " +
                     std::to_string(limits.max_triangles));
  }
  check_vertices(vertices, source, limits);

  std::vector<bool> used(vertices.size(), false);
  std::size_t kept = 0;
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    const TriangleIndices& t = triangles[i];
    check_indices(i, t, vertices.size(), source);
    if (is_degenerate_triangle(vertices[t[0]], vertices[t[1]], vertices[t[2]])) {
      ++found.degenerate_removed;
      continue;
    }
    for (std::uint32_t v : t) used[v] = true;
    triangles[kept++] = t;
  }
  triangles.resize(kept);
  if (triangles.empty()) {
    fail(source, "all " + std::to_string(found.input_triangles) + " triangles are degenerate");
  }
  for (bool u : used) found.unused_vertices += u ? 0 : 1;

  if (validation != nullptr) *validation = found;
  return Mesh{std::move(vertices), std::move(triangles), std::move(source)};
}

std::vector<std::uint32_t> welded_ids(std::span<const Vec3> vertices) {
  std::vector<std::uint32_t> order(vertices.size());
  std::iota(order.begin(), order.end(), std::uint32_t{0});
  const auto key = [&](std::uint32_t i) {
    return std::make_tuple(vertices[i].x(), vertices[i].y(), vertices[i].z());
  };
  std::sort(order.begin(), order.end(), [&](std::uint32_t i, std::uint32_t j) {
    return std::make_pair(key(i), i) < std::make_pair(key(j), j);
  });
  std::vector<std::uint32_t> id(vertices.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    id[order[k]] = (k > 0 && key(order[k]) == key(order[k - 1])) ? id[order[k - 1]] : order[k];
  }
  return id;
}

Bounds mesh_bounds(const Mesh& mesh) {
  Bounds b{mesh.vertices.front(), mesh.vertices.front()};
  for (const Vec3& v : mesh.vertices) {
    b.min = b.min.cwiseMin(v);
    b.max = b.max.cwiseMax(v);
  }
  return b;
}

Bounds transformed_bounds(const Bounds& local, const Transform& X_WP) {
  Bounds out{X_WP.apply(local.min), X_WP.apply(local.min)};
  for (int corner = 1; corner < 8; ++corner) {
    const Vec3 p(corner & 1 ? local.max.x() : local.min.x(),
                 corner & 2 ? local.max.y() : local.min.y(),
                 corner & 4 ? local.max.z() : local.min.z());
    const Vec3 p_W = X_WP.apply(p);
    out.min = out.min.cwiseMin(p_W);
    out.max = out.max.cwiseMax(p_W);
  }
  return out;
}

}  // namespace dovetail::collision
