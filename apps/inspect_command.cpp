#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "cli.h"
#include "commands.h"
#include "dovetail/collision/containment.h"
#include "dovetail/interaction/overlap.h"

namespace dovetail::cli {

namespace {

constexpr const char* kHelp =
    R"(usage: dovetail inspect MESH [--json] [--method M] [--parts]

Reads a mesh file (OBJ, STL, PLY, glTF or GLB) as `query` does and reports what
was found: vertices, triangles, validation findings (degenerate triangles
removed, unused vertices, skipped point/line primitives, notes), whether the
surface is closed and consistently wound (open and wrongly wound edges, with a
warning: penetration depth and inside tests need such a surface), the file's cameras
(by name, for `render --camera`), bounds, and
for every method the hierarchy built over it: nodes, leaves, depth, bytes,
bytes per triangle and build time.

  --json       one JSON object on one line instead of the text report
  --method M   only this method (boxtree, dop6, dop14, dop18, dop26, aabb, obb, brute)
  --parts      also list the parts (one per mesh instance of every node), each
               with its node and group (what a scenario's nodes = { ... } takes),
               its open and wrongly wound edges and its bounds in the file's frame
)";

std::string json_vec(const collision::Vec3& v) {
  return json_array({json_number(v.x()), json_number(v.y()), json_number(v.z())});
}

struct MethodRow {
  collision::Method method;
  collision::ModelInfo info;
  double build_ms = 0;
};

struct PartRow {
  std::string name;
  /// The name that selects the part's whole node (a scenario's `nodes`):
  /// the first of its meshes' names; another mesh of the node has its own.
  std::string node;
  std::vector<std::string> groups;  ///< the nodes above it, from the root down
  std::size_t vertices = 0;
  std::size_t triangles = 0;
  collision::SurfaceEdges edges{};
  collision::Bounds bounds{};  ///< in the file's frame and units
};

}  // namespace

namespace {

/// What inspect found: the merged mesh, its parts (with --parts) and each method's hierarchy.
struct Inspection {
  std::string path;
  LoadedMesh loaded;
  collision::Bounds bounds{};
  double diagonal = 0;
  collision::SurfaceEdges edges{};
  std::vector<PartRow> parts{};
  std::vector<MethodRow> rows{};
};

/// The file's mesh instances, each as its own part.
std::vector<PartRow> part_rows(const std::string& path) {
  std::vector<PartRow> parts;
  engine::ImportOptions per_part;
  per_part.merge = false;
  try {
    std::map<std::size_t, std::string> node_names;  // node -> its first mesh's part name
    for (const engine::ImportedPart& part : engine::import_file(path, per_part).parts) {
      const std::string& node = node_names.try_emplace(part.node, part.name).first->second;
      parts.push_back({part.name, node, part.groups, part.mesh.vertex_count(),
                       part.mesh.triangle_count(), collision::surface_edges(part.mesh),
                       collision::mesh_bounds(part.mesh)});
    }
  } catch (const collision::MeshError& e) {
    throw InputError(e.what());
  }
  return parts;
}

/// Builds each method's hierarchy once, timed, with a progress line on a terminal.
std::vector<MethodRow> method_rows(const std::vector<collision::Method>& methods,
                                   const std::shared_ptr<const collision::Mesh>& mesh) {
  const bool terminal = stderr_is_terminal();
  std::vector<MethodRow> rows;
  for (collision::Method m : methods) {
    if (terminal) {
      std::fprintf(stderr, "\rbuilding %-8s", std::string(collision::method_name(m)).c_str());
    }
    const BuiltModel built = build_timed(m, mesh);
    rows.push_back({m, built.model->info(), built.build_ms});
  }
  if (terminal) std::fputs("\r                 \r", stderr);
  return rows;
}

void print_json(const Inspection& x, bool with_parts) {
  const collision::Mesh& mesh = *x.loaded.mesh;
  const collision::MeshValidation& v = x.loaded.validation;
  std::vector<std::string> notes;
  for (const std::string& note : x.loaded.report.notes) notes.push_back(json_string(note));
  std::vector<std::string> cameras;
  for (const auto& camera : x.loaded.report.cameras) cameras.push_back(json_string(camera.first));
  std::vector<std::string> method_items;
  for (const MethodRow& row : x.rows) {
    JsonLine item;
    item.add("method", collision::method_name(row.method))
        .add("nodes", std::uint64_t{row.info.nodes})
        .add("leaves", std::uint64_t{row.info.leaves})
        .add("depth", std::uint64_t{row.info.depth})
        .add("bytes", std::uint64_t{row.info.bytes})
        .add("bytes_per_triangle", row.info.bytes_per_triangle)
        .add("build_ms", round_ms(row.build_ms));
    method_items.push_back(item.str());
  }
  JsonLine json;
  json.add("file", x.path)
      .add("vertices", std::uint64_t{mesh.vertex_count()})
      .add("triangles", std::uint64_t{mesh.triangle_count()})
      .add("input_vertices", std::uint64_t{v.input_vertices})
      .add("input_triangles", std::uint64_t{v.input_triangles})
      .add("degenerate_removed", std::uint64_t{v.degenerate_removed})
      .add("unused_vertices", std::uint64_t{v.unused_vertices})
      .add("skipped_line_or_point_primitives",
           std::uint64_t{x.loaded.report.skipped_line_or_point_primitives})
      .add_raw("notes", json_array(notes))
      .add_raw("cameras", json_array(cameras))
      .add_raw("bounds_min", json_vec(x.bounds.min))
      .add_raw("bounds_max", json_vec(x.bounds.max))
      .add("diagonal", x.diagonal)
      .add("open_edges", std::uint64_t{x.edges.open})
      .add("wrongly_wound_edges", std::uint64_t{x.edges.misoriented});
  if (with_parts) {
    std::vector<std::string> part_items;
    for (const PartRow& part : x.parts) {
      JsonLine item;
      std::vector<std::string> groups;
      for (const std::string& g : part.groups) groups.push_back(json_string(g));
      item.add("name", part.name)
          .add("node", part.node)
          .add_raw("groups", json_array(groups))
          .add("vertices", std::uint64_t{part.vertices})
          .add("triangles", std::uint64_t{part.triangles})
          .add("open_edges", std::uint64_t{part.edges.open})
          .add("wrongly_wound_edges", std::uint64_t{part.edges.misoriented})
          .add_raw("bounds_min", json_vec(part.bounds.min))
          .add_raw("bounds_max", json_vec(part.bounds.max));
      part_items.push_back(item.str());
    }
    json.add_raw("parts", json_array(part_items));
  }
  json.add_raw("methods", json_array(method_items));
  std::fputs((json.str() + "\n").c_str(), stdout);
}

void print_text(const Inspection& x, bool with_parts) {
  const collision::Mesh& mesh = *x.loaded.mesh;
  const collision::MeshValidation& v = x.loaded.validation;
  std::printf("file                %s\n", x.path.c_str());
  std::printf("vertices            %zu\n", mesh.vertex_count());
  std::printf("triangles           %zu\n", mesh.triangle_count());
  std::printf("read                %zu vertices, %zu triangles\n", v.input_vertices,
              v.input_triangles);
  std::printf("degenerate removed  %zu\n", v.degenerate_removed);
  std::printf("unused vertices     %zu\n", v.unused_vertices);
  std::printf("skipped primitives  %zu (points and lines)\n",
              x.loaded.report.skipped_line_or_point_primitives);
  std::printf("bounds min          %.9g %.9g %.9g\n", x.bounds.min.x(), x.bounds.min.y(),
              x.bounds.min.z());
  std::printf("bounds max          %.9g %.9g %.9g\n", x.bounds.max.x(), x.bounds.max.y(),
              x.bounds.max.z());
  std::printf("diagonal            %.9g\n", x.diagonal);
  std::printf("open edges          %zu\n", x.edges.open);
  std::printf("wrongly wound edges %zu\n", x.edges.misoriented);
  if (const std::optional<std::string> flaw = interaction::surface_flaw(*x.loaded.mesh)) {
    std::printf("warning             not a closed surface: %s; %s\n", flaw->c_str(),
                interaction::kSurfaceFlawEffect);
  }
  for (const std::string& note : x.loaded.report.notes) {
    std::printf("note                %s\n", note.c_str());
  }
  for (const auto& camera : x.loaded.report.cameras) {
    std::printf("camera              %s\n", camera.first.c_str());
  }
  if (with_parts) {
    std::printf("\n%-24s %-24s %-24s %10s %10s %10s %14s  %s\n", "part", "of node", "in group",
                "vertices", "triangles", "open edges", "wrongly wound",
                "bounds min .. max (the file's frame and units)");
    for (const PartRow& part : x.parts) {
      const collision::Bounds& b = part.bounds;
      const std::string group = part.groups.empty() ? "-" : part.groups.back();
      std::printf("%-24s %-24s %-24s %10zu %10zu %10zu %14zu  %.6g %.6g %.6g .. %.6g %.6g %.6g\n",
                  part.name.c_str(), part.node.c_str(), group.c_str(), part.vertices,
                  part.triangles, part.edges.open, part.edges.misoriented, b.min.x(), b.min.y(),
                  b.min.z(), b.max.x(), b.max.y(), b.max.z());
    }
    std::printf(
        "\nA scenario's nodes = { ... } takes a node whole (every part of it) by any of its "
        "parts' names, and a group by its name (every part in it).\n");
  }
  std::printf("\n%-8s %10s %10s %6s %12s %10s %10s\n", "method", "nodes", "leaves", "depth",
              "bytes", "bytes/tri", "build ms");
  for (const MethodRow& row : x.rows) {
    std::printf("%-8s %10zu %10zu %6zu %12zu %10.2f %10.3f\n",
                std::string(collision::method_name(row.method)).c_str(), row.info.nodes,
                row.info.leaves, row.info.depth, row.info.bytes, row.info.bytes_per_triangle,
                row.build_ms);
  }
}

}  // namespace

int inspect_command(std::span<const std::string> argv) {
  const Args args("inspect", argv, {"method"}, {"json", "parts"});
  if (args.help()) {
    std::fputs(kHelp, stdout);
    return kExitOk;
  }
  args.expect_positional(1, "one mesh file");
  std::vector<collision::Method> methods;
  if (args.value("method")) {
    methods.push_back(args.method(collision::Method::kBoxtree));
  } else {
    methods.assign(collision::all_methods().begin(), collision::all_methods().end());
  }
  Inspection x{.path = args.positional()[0], .loaded = load_mesh(args.positional()[0])};
  x.bounds = collision::mesh_bounds(*x.loaded.mesh);
  x.diagonal = (x.bounds.max - x.bounds.min).norm();
  x.edges = collision::surface_edges(*x.loaded.mesh);
  if (args.flag("parts")) x.parts = part_rows(x.path);
  x.rows = method_rows(methods, x.loaded.mesh);
  if (args.flag("json")) {
    print_json(x, args.flag("parts"));
  } else {
    print_text(x, args.flag("parts"));
  }
  return kExitOk;
}

}  // namespace dovetail::cli
