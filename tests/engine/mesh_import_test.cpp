#include "dovetail/engine/mesh_import.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <numbers>
#include <set>
#include <string>
#include <vector>

#include "../support/temp_dir.h"

namespace dovetail::engine {
namespace {

namespace fs = std::filesystem;
using collision::Vec3;

const fs::path kModels = DOVETAIL_ASSIMP_MODELS;
const fs::path kData = DOVETAIL_TEST_DATA;

/// A fresh folder for one test.
class TempDir : public test::TempDir {
 public:
  TempDir() : test::TempDir("dovetail_import") {}
};

void write_file(const fs::path& path, const std::string& bytes) {
  fs::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  ASSERT_TRUE(out.good()) << path;
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

/// The ImportError message of importing `path`, failing the test when the
/// import succeeds or throws anything else.
std::string import_error(const fs::path& path, const ImportOptions& options = {}) {
  try {
    import_file(path, options);
  } catch (const ImportError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << path << ": threw something other than ImportError: " << e.what();
    return {};
  }
  ADD_FAILURE() << path << ": imported without error";
  return {};
}

std::size_t total_triangles(const ImportReport& report) {
  std::size_t n = 0;
  for (const ImportedPart& part : report.parts) n += part.mesh.triangle_count();
  return n;
}

Vec3 triangle_normal(const collision::Mesh& mesh, std::size_t t) {
  const auto& tri = mesh.triangles[t];
  const Vec3& a = mesh.vertices[tri[0]];
  return (mesh.vertices[tri[1]] - a).cross(mesh.vertices[tri[2]] - a);
}

// ---------------------------------------------------------------- real files

TEST(MeshImport, ObjBoxIsWeldedAndTriangulated) {
  collision::MeshValidation validation;
  const collision::Mesh mesh = import_mesh(kModels / "OBJ/box.obj", &validation);
  EXPECT_EQ(mesh.triangle_count(), 12u);
  EXPECT_EQ(mesh.vertex_count(), 8u);
  EXPECT_EQ(validation.degenerate_removed, 0u);
  EXPECT_EQ(validation.unused_vertices, 0u);
  EXPECT_EQ(mesh.source, (kModels / "OBJ/box.obj").string());
  const collision::Bounds b = collision::mesh_bounds(mesh);
  EXPECT_EQ(b.min, Vec3(-0.5, -0.5, -0.5));
  EXPECT_EQ(b.max, Vec3(0.5, 0.5, 0.5));
}

TEST(MeshImport, StlAsciiAndBinaryAgree) {
  const collision::Mesh ascii = import_mesh(kModels / "STL/Spider_ascii.stl");
  const collision::Mesh binary = import_mesh(kModels / "STL/Spider_binary.stl");
  EXPECT_EQ(ascii.triangle_count(), 1312u);
  EXPECT_EQ(binary.triangle_count(), ascii.triangle_count());
  const collision::Bounds a = collision::mesh_bounds(ascii);
  const collision::Bounds b = collision::mesh_bounds(binary);
  EXPECT_TRUE(a.min.isApprox(b.min, 1e-5));
  EXPECT_TRUE(a.max.isApprox(b.max, 1e-5));
}

TEST(MeshImport, PlyAsciiAndBinaryCubes) {
  EXPECT_EQ(import_mesh(kModels / "PLY/cube.ply").triangle_count(), 12u);
  EXPECT_EQ(import_mesh(kModels / "PLY/cube_binary.ply").triangle_count(), 12u);
  EXPECT_EQ(import_mesh(kModels / "PLY/Wuson.ply").triangle_count(), 3732u);
}

TEST(MeshImport, OnlyTheFormatsDovetailNeedsAreRead) {
  // Assimp reads OFF and Collada well enough; Dovetail lets only its own
  // formats through, whatever a file holds.
  for (const char* model : {"OFF/Cube.off", "Collada/duck_triangulate.dae"}) {
    const std::string message = import_error(kModels / model);
    EXPECT_EQ(message.rfind((kModels / model).string(), 0), 0u) << message;
    EXPECT_NE(message.find("does not read"), std::string::npos) << message;
    EXPECT_NE(message.find(".obj, .stl, .ply, .gltf and .glb"), std::string::npos) << message;
  }
  TempDir dir;
  const std::string cube =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  write_file(dir / "tetra", cube);
  EXPECT_NE(import_error(dir / "tetra").find("has no extension"), std::string::npos);
  write_file(dir / "tetra.3ds", cube);
  EXPECT_NE(import_error(dir / "tetra.3ds").find("'.3ds'"), std::string::npos);
  write_file(dir / "TETRA.OBJ", cube);
  EXPECT_EQ(import_mesh(dir / "TETRA.OBJ").triangle_count(), 4u);
}

/// glTF JSON of a chain of `levels` nodes, each the child of the one before.
std::string node_chain(int levels) {
  std::string json = R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [)";
  for (int i = 0; i < levels; ++i) {
    if (i > 0) json += ", ";
    json += i + 1 < levels ? "{\"children\": [" + std::to_string(i + 1) + "]}" : "{}";
  }
  return json + "]}";
}

TEST(MeshImport, AGltfNodeHierarchyDeeperThanAThousandLevelsIsRefused) {
  // 20,000 levels overflowed the importer's stack (a crash); glb and gltf alike.
  const TempDir dir;
  for (const int levels : {1001, 20000}) {
    const std::string json = node_chain(levels);
    write_file(dir / "deep.gltf", json);
    EXPECT_NE(import_error(dir / "deep.gltf")
                  .find("deep.gltf: its node hierarchy is " + std::to_string(levels) +
                        " levels deep; at most 1000 are read"),
              std::string::npos);
    std::string glb = "glTF";
    const auto u32 = [&](std::uint32_t v) {
      for (int k = 0; k < 4; ++k) glb += static_cast<char>((v >> (8 * k)) & 0xff);
    };
    const std::string padded = json + std::string((4 - json.size() % 4) % 4, ' ');
    u32(2);
    u32(static_cast<std::uint32_t>(12 + 8 + padded.size()));
    u32(static_cast<std::uint32_t>(padded.size()));
    glb += "JSON" + padded;
    write_file(dir / "deep.glb", glb);
    EXPECT_NE(import_error(dir / "deep.glb").find("levels deep; at most 1000 are read"),
              std::string::npos);
  }
  // Written as the importer reads it too: comments, an escaped key, indices
  // written 2.0; and JSON nested deeper than 256 levels is refused.
  std::string json = node_chain(1500);
  json.replace(json.find("\"nodes\""), 7, "\"node\\u0073\"");
  for (std::size_t at = json.find("\"children\": [1]"); at != std::string::npos;
       at = std::string::npos) {
    json.replace(at, 15, "\"children\": [1.0]");
  }
  write_file(dir / "written.gltf", "/* a comment */ " + json + " // end\n");
  EXPECT_NE(import_error(dir / "written.gltf").find("is 1500 levels deep"), std::string::npos);
  write_file(dir / "extras.gltf", R"({"asset": {"version": "2.0"}, "extras": )" +
                                      std::string(300, '[') + std::string(300, ']') + "}");
  EXPECT_NE(import_error(dir / "extras.gltf").find("its JSON is nested deeper than 256 levels"),
            std::string::npos);
  // 1000 levels pass this check (the importer then finds no mesh in them).
  write_file(dir / "deep.gltf", node_chain(1000));
  EXPECT_EQ(import_error(dir / "deep.gltf").find("levels deep"), std::string::npos);
}

TEST(MeshImport, AnAsciiPlyBodyMustMatchItsHeader) {
  // The reader took a missing face as none, a face line as a vertex, and a
  // face count of 255 with three corners; each is named now.
  const TempDir dir;
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string vertices = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n";
  const auto error_of = [&](const std::string& body) {
    write_file(dir / "m.ply", header + body);
    return import_error(dir / "m.ply");
  };
  EXPECT_NE(error_of(vertices + "3 0 1 2\n")
                .find("m.ply: PLY ends after 1 of the 2 face lines its header declares; truncated"),
            std::string::npos);
  EXPECT_NE(error_of("0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 2 3\n")
                .find("PLY line 13: a vertex has 3 values, this line 4"),
            std::string::npos);
  EXPECT_NE(error_of(vertices + "255 0 1 2\n3 0 2 3\n")
                .find("PLY line 14: a face line gives 255 as its count of values and lists 3"),
            std::string::npos);
  EXPECT_NE(error_of(vertices + "3 0 1 2\n3 0 2 3\n3 1 2 3\n")
                .find("PLY line 16: more lines than the header declares"),
            std::string::npos);
  // Blank lines and CRLF line ends are read.
  write_file(dir / "ok.ply", header + vertices + "\n3 0 1 2\r\n3 0 2 3\r\n");
  EXPECT_EQ(total_triangles(import_file(dir / "ok.ply")), 2u);
}

TEST(MeshImport, AnAsciiPlyElementMixingValuesAndListsMustMatchItsHeader) {
  // A vertex element with a list property after its coordinates, its lines
  // without the list: the importer read on into the next lines and asked for
  // 11 GB. Each line must hold every property, a list as its count and then
  // that many values.
  const TempDir dir;
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nproperty list uchar uint tags\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  write_file(dir / "bad.ply", header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  EXPECT_NE(import_error(dir / "bad.ply")
                .find("bad.ply: PLY line 11: a vertex line does not hold its 4 properties"),
            std::string::npos);
  write_file(dir / "long.ply", header + "0 0 0 2 7\n1 0 0 0\n0 1 0 0\n3 0 1 2\n");
  EXPECT_NE(import_error(dir / "long.ply").find("PLY line 11: a vertex line does not hold"),
            std::string::npos);
  write_file(dir / "ok.ply", header + "0 0 0 2 7 8\n1 0 0 0\n0 1 0 1 5\n3 0 1 2\n");
  EXPECT_EQ(total_triangles(import_file(dir / "ok.ply")), 1u);
}

TEST(MeshImport, GlbMergedEqualsItsParts) {
  const fs::path file = kModels / "glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";
  const ImportReport merged = import_file(file);
  ASSERT_EQ(merged.parts.size(), 1u);
  EXPECT_EQ(merged.parts[0].name, "2CylinderEngine.glb");
  EXPECT_GT(merged.parts[0].mesh.triangle_count(), 100000u);

  ImportOptions per_part;
  per_part.merge = false;
  const ImportReport parts = import_file(file, per_part);
  EXPECT_GT(parts.parts.size(), 50u);
  EXPECT_EQ(total_triangles(parts), total_triangles(merged));

  std::set<std::string> names;
  collision::Bounds all = collision::mesh_bounds(parts.parts[0].mesh);
  for (const ImportedPart& part : parts.parts) {
    EXPECT_FALSE(part.name.empty());
    EXPECT_TRUE(names.insert(part.name).second) << "duplicate part name " << part.name;
    EXPECT_EQ(part.mesh.source, file.string() + "#" + part.name);
    const collision::Bounds b = collision::mesh_bounds(part.mesh);
    all.min = all.min.cwiseMin(b.min);
    all.max = all.max.cwiseMax(b.max);
  }
  // Same placement merged or not: the union of the parts' bounds is the merged bounds.
  const collision::Bounds m = collision::mesh_bounds(merged.parts[0].mesh);
  EXPECT_EQ(all.min, m.min);
  EXPECT_EQ(all.max, m.max);

  // Deterministic: a second import gives the same names in the same order.
  const ImportReport again = import_file(file, per_part);
  ASSERT_EQ(again.parts.size(), parts.parts.size());
  for (std::size_t i = 0; i < parts.parts.size(); ++i) {
    EXPECT_EQ(again.parts[i].name, parts.parts[i].name);
    EXPECT_EQ(again.parts[i].mesh.vertices, parts.parts[i].mesh.vertices);
  }
}

TEST(MeshImport, PointsAndLinesAreSkippedWithANote) {
  const ImportReport report = import_file(kModels / "OBJ/testmixed.obj");
  EXPECT_EQ(total_triangles(report), 12u);
  EXPECT_GT(report.skipped_line_or_point_primitives, 0u);
  ASSERT_FALSE(report.notes.empty());
  EXPECT_NE(report.notes[0].find("point or line"), std::string::npos);
}

TEST(MeshImport, OnlyLinesIsAnError) {
  const std::string message = import_error(kModels / "OBJ/testline.obj");
  EXPECT_NE(message.find("testline.obj"), std::string::npos);
  EXPECT_NE(message.find("no triangles"), std::string::npos) << message;
}

// Every file assimp ships as invalid: an ImportError naming the file, or (if
// assimp reads it) a valid mesh. Never a crash, never a hang.
TEST(MeshImport, EveryShippedInvalidFileIsHandled) {
  std::size_t files = 0;
  for (const fs::directory_entry& entry : fs::directory_iterator(kModels / "invalid")) {
    if (!entry.is_regular_file()) continue;
    ++files;
    const fs::path file = entry.path();
    SCOPED_TRACE(file.string());
    const auto start = std::chrono::steady_clock::now();
    try {
      const ImportReport report = import_file(file);
      ASSERT_EQ(report.parts.size(), 1u) << file;
      EXPECT_GT(report.parts[0].mesh.triangle_count(), 0u) << file;
      for (const auto& tri : report.parts[0].mesh.triangles) {
        for (std::uint32_t v : tri) ASSERT_LT(v, report.parts[0].mesh.vertex_count()) << file;
      }
    } catch (const ImportError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(file.string(), 0), 0u)
          << file << ": message does not start with the file: " << e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << file << ": unexpected exception " << e.what();
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_LT(seconds, 5.0) << file;
  }
  EXPECT_GT(files, 10u);
}

// ---------------------------------------------------------------- files and folders

TEST(MeshImport, MissingFile) {
  TempDir dir;
  const std::string message = import_error(dir / "nothing.obj");
  EXPECT_NE(message.find("nothing.obj"), std::string::npos);
  EXPECT_NE(message.find("not found"), std::string::npos) << message;
}

TEST(MeshImport, DirectoryIsNotAMesh) {
  TempDir dir;
  fs::create_directory(dir / "model.obj");
  const std::string message = import_error(dir / "model.obj");
  EXPECT_NE(message.find("directory"), std::string::npos) << message;
}

TEST(MeshImport, EmptyFile) {
  TempDir dir;
  for (const char* name : {"empty.obj", "empty.stl", "empty.ply", "empty.glb", "empty"}) {
    write_file(dir / name, "");
    const std::string message = import_error(dir / name);
    EXPECT_NE(message.find(name), std::string::npos) << message;
    EXPECT_NE(message.find("empty"), std::string::npos) << message;
  }
}

TEST(MeshImport, UnreadableFormat) {
  TempDir dir;
  std::string noise;
  for (int i = 0; i < 4096; ++i) noise += static_cast<char>((i * 7919 + 13) % 251);
  write_file(dir / "noise.bin", noise);
  write_file(dir / "noise.obj", noise);
  EXPECT_NE(import_error(dir / "noise.bin").find("noise.bin"), std::string::npos);
  EXPECT_NE(import_error(dir / "noise.obj").find("noise.obj"), std::string::npos);
}

TEST(MeshImport, TextThatIsNoMeshIsSaidSo) {
  TempDir dir;
  const std::string text =
      "hello, this is a text file and not a mesh\nsaved under the wrong name by mistake, "
      "long enough for a header\n";
  write_file(dir / "text.stl", text);
  write_file(dir / "text.obj", text);
  const std::string stl = import_error(dir / "text.stl");
  EXPECT_NE(stl.find("text.stl: is not an STL file: it is text but does not start with 'solid'"),
            std::string::npos)
      << stl;
  const std::string obj = import_error(dir / "text.obj");
  EXPECT_NE(obj.find("text.obj: cannot be read as a mesh: the importer found no mesh in it (is it "
                     "a .obj file?)"),
            std::string::npos)
      << obj;
}

TEST(MeshImport, AFolderReachedThroughALinkIsItsTarget) {
  // "link/../x" is x beside the link's target, as the file system resolves it.
  TempDir dir;
  fs::create_directories(dir / "real" / "scenarios");
  fs::create_directories(dir / "real" / "parts");
  fs::copy_file(kModels / "OBJ/box.obj", dir / "real" / "parts" / "box.obj");
  fs::create_directories(dir / "elsewhere");
  fs::create_directory_symlink(dir / "real" / "scenarios", dir / "elsewhere" / "scenarios");
  collision::Mesh mesh;
  EXPECT_NO_THROW(mesh = import_mesh(dir / "elsewhere" / "scenarios" / ".." / "parts" / "box.obj"));
  EXPECT_EQ(mesh.triangle_count(), 12u);
}

TEST(MeshImport, VerticesAreWeldedOnlyWhenEqual) {
  // A vertex 1e-6 from another is a vertex of its own: the sliver keeps its
  // area and both triangles (a weld by distance used to merge the two and
  // drop the sliver as degenerate). Equal positions are one vertex.
  TempDir dir;
  write_file(dir / "sliver.obj",
             "v 0 0 0\nv 1 0 0\nv 1 1e-6 0\nf 1 2 3\nv 0 1 0\nv 0 0 1\nf 1 4 5\n");
  const collision::Mesh sliver = import_mesh(dir / "sliver.obj");
  EXPECT_EQ(sliver.vertex_count(), 5u);
  EXPECT_EQ(sliver.triangle_count(), 2u);
  write_file(dir / "shared.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\nf 4 5 3\n");
  const collision::Mesh shared = import_mesh(dir / "shared.obj");
  EXPECT_EQ(shared.vertex_count(), 4u);
  EXPECT_EQ(shared.triangles[1][0], shared.triangles[0][1])
      << "the corner at (1, 0, 0) is one vertex";
}

TEST(MeshImport, AnUnusedNonFiniteVertexAndAByteOrderMarkAreNamed) {
  TempDir dir;
  write_file(dir / "unused_nan.obj", "v 0 0 0\nv 0 1 0\nv 0 0 1\nv nan 0 0\nf 1 2 3\n");
  const std::string nan = import_error(dir / "unused_nan.obj");
  EXPECT_NE(nan.find("line 4: 'nan' is not finite"), std::string::npos) << nan;
  write_file(dir / "bom.obj", "\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const std::string bom = import_error(dir / "bom.obj");
  EXPECT_NE(bom.find("line 1: starts with a byte-order mark"), std::string::npos) << bom;
  // A coordinate too small for a double is finite: it reads as zero, as before.
  write_file(dir / "tiny.obj", "v 1e-400 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\n");
  EXPECT_EQ(import_mesh(dir / "tiny.obj").triangle_count(), 1u);
}

TEST(MeshImport, TruncatedBinaryStl) {
  TempDir dir;
  const std::string whole = read_file(kModels / "STL/Spider_binary.stl");
  ASSERT_GT(whole.size(), 84u + 50u * 20u);
  // Cut mid-triangle, on a triangle boundary, and inside the header.
  for (std::size_t cut :
       {std::size_t{84 + 50 * 10 + 7}, std::size_t{84 + 50 * 20}, std::size_t{60}}) {
    SCOPED_TRACE(cut);
    write_file(dir / "cut.stl", whole.substr(0, cut));
    const std::string message = import_error(dir / "cut.stl");
    EXPECT_NE(message.find("cut.stl"), std::string::npos);
    EXPECT_NE(message.find("truncated"), std::string::npos) << message;
  }
}

TEST(MeshImport, TruncatedObj) {
  TempDir dir;
  const std::string whole = read_file(kModels / "OBJ/box.obj");
  // Inside the vertex list: faces are gone or refer to vertices that are not there.
  const std::size_t vertices = whole.find("v 0.5 -0.5 -0.5");
  ASSERT_NE(vertices, std::string::npos);
  write_file(dir / "cut.obj", whole.substr(0, vertices + 5));
  EXPECT_NE(import_error(dir / "cut.obj").find("cut.obj"), std::string::npos);

  // Vertices complete, faces cut: a face now refers to a vertex beyond the list.
  write_file(dir / "cut2.obj",
             "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 3");  // complete: reads fine
  EXPECT_EQ(import_mesh(dir / "cut2.obj").triangle_count(), 2u);
  write_file(dir / "cut3.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4");
  EXPECT_NE(import_error(dir / "cut3.obj").find("cut3.obj"), std::string::npos);
}

TEST(MeshImport, NonFiniteVerticesInObj) {
  TempDir dir;
  for (const char* value : {"nan", "inf", "-inf", "1e999"}) {
    SCOPED_TRACE(value);
    write_file(dir / "bad.obj", std::string("v 0 0 0\nv 1 0 0\nv 0 1 ") + value + "\nv 0 0 1\n" +
                                    "f 1 2 3\nf 1 2 4\n");
    const std::string message = import_error(dir / "bad.obj");
    EXPECT_NE(message.find("bad.obj"), std::string::npos);
    EXPECT_NE(message.find("not finite"), std::string::npos) << message;
  }
  // A NaN in a second object must not silently drop that object.
  write_file(dir / "two.obj",
             "o good\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"
             "o bad\nv 0 0 nan\nv 1 0 1\nv 0 1 1\nf 4 5 6\n");
  EXPECT_NE(import_error(dir / "two.obj").find("not finite"), std::string::npos);
}

TEST(MeshImport, NonFiniteVerticesInGlb) {
  const std::string message =
      import_error(kModels / "glTF2/BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb");
  EXPECT_NE(message.find("not finite"), std::string::npos) << message;
}

// ---------------------------------------------------------------- declared sizes

/// Imports `path` expecting an ImportError within a fraction of a second.
std::string fast_error(const fs::path& path, const ImportOptions& options = {}) {
  const auto start = std::chrono::steady_clock::now();
  const std::string message = import_error(path, options);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(seconds, 0.5) << path;
  return message;
}

TEST(MeshImport, PlyDeclaringHundredMillionVerticesFailsFast) {
  TempDir dir;
  const std::string ascii =
      "ply\nformat ascii 1.0\nelement vertex 100000000\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  write_file(dir / "huge.ply", ascii);
  std::string message = fast_error(dir / "huge.ply");
  EXPECT_NE(message.find("huge.ply"), std::string::npos);
  EXPECT_NE(message.find("100000000"), std::string::npos) << message;

  // With limits high enough, the file size still gives it away.
  ImportOptions roomy;
  roomy.limits.max_vertices = std::size_t{1} << 32;
  message = fast_error(dir / "huge.ply", roomy);
  EXPECT_NE(message.find("truncated"), std::string::npos) << message;

  std::string binary =
      "ply\nformat binary_little_endian 1.0\nelement vertex 100000000\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n";
  binary += std::string(36, '\0');
  write_file(dir / "huge_binary.ply", binary);
  message = fast_error(dir / "huge_binary.ply", roomy);
  EXPECT_NE(message.find("truncated"), std::string::npos) << message;

  // A face count far beyond the file.
  write_file(dir / "faces.ply",
             "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
             "property float z\nelement face 50000000\nproperty list uchar int vertex_indices\n"
             "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  EXPECT_NE(fast_error(dir / "faces.ply").find("faces.ply"), std::string::npos);

  // Counts that do not even fit 64 bits.
  write_file(dir / "overflow.ply",
             "ply\nformat ascii 1.0\nelement vertex 99999999999999999999999\nproperty float x\n"
             "end_header\n0\n");
  EXPECT_NE(fast_error(dir / "overflow.ply").find("overflow.ply"), std::string::npos);
}

// Found by fuzz/ (fuzz_mesh_ply): a first line "ply?" bypassed the header
// check and the PLY reader spun on the malformed header that followed.
TEST(MeshImport, PlyMagicWithSuffixIsRefusedFast) {
  const std::string message = fast_error(kData / "ply_magic_with_suffix.ply");
  EXPECT_NE(message.find("line 1: expected 'ply' alone on the line"), std::string::npos) << message;
}

// From fuzz/ (fuzz_mesh_ply): a .ply file without the "ply" line reached the
// PLY reader; it is refused before, as malformed headers are.
TEST(MeshImport, PlyWithoutMagicIsRefusedFast) {
  const std::string message = fast_error(kData / "ply_without_magic.ply");
  EXPECT_NE(message.find("line 1: expected 'ply' alone on the line"), std::string::npos) << message;
}

// Malformed PLY headers once made the importer hang or crash; they are refused
// before it runs, naming the header line.
TEST(MeshImport, MalformedPlyHeadersAreRefused) {
  TempDir dir;
  const std::string body = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const std::string vertex = "element vertex 3\nproperty float x\nproperty float y\n";
  const std::string face = "element face 1\nproperty list uchar int vertex_indices\n";
  struct Case {
    const char* name;
    std::string text;
    const char* what;
  };
  const Case cases[] = {
      {"unknown_type.ply",
       "ply\nformat ascii 1.0\n" + vertex + "property floaoat z\n" + face + "end_header\n" + body,
       "line 6: unknown type 'floaoat'"},
      {"no_end.ply", "ply\nformat ascii 1.0\n" + vertex + "property float z\n" + face + body,
       "not terminated by end_header"},
      {"broken_end.ply",
       "ply\nformat ascii 1.0\n" + vertex + "property float z\n" + face + "end_heajer\n" + body,
       "not terminated by end_header"},
      {"short_list.ply",
       "ply\nformat ascii 1.0\n" + vertex +
           "property float z\nelement face 1\nproperty list uint8\nend_header\n" + body,
       "line 8: a list property needs two types and a name"},
      {"float_count.ply",
       "ply\nformat ascii 1.0\n" + vertex +
           "property float z\nelement face 1\nproperty list float int idx\nend_header\n" + body,
       "is not an integer type"},
      {"no_count.ply", "ply\nformat ascii 1.0\nelement vertex\nend_header\n" + body,
       "line 3: an element needs a name and a count"},
      {"orphan_property.ply", "ply\nformat ascii 1.0\nproperty float x\nend_header\n" + body,
       "line 3: property before any element"},
      {"bad_format.ply",
       "ply\nformat asc1i 1.0\n" + vertex + "property float z\n" + face + "end_header\n" + body,
       "line 2: invalid format line"},
      {"no_format.ply", "ply\n" + vertex + "property float z\n" + face + "end_header\n" + body,
       "no format line"},
      {"magic_suffix.ply",
       "ply?\nformat ascii 1.0\n" + vertex + "property float z\n" + face + "end_header\n" + body,
       "line 1: expected 'ply' alone on the line"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    write_file(dir / c.name, c.text);
    const std::string message = fast_error(dir / c.name);
    EXPECT_EQ(message.rfind((dir / c.name).string() + ": ", 0), 0u) << message;
    EXPECT_NE(message.find(c.what), std::string::npos) << message;
  }
  // Exporters that write comments without `comment` are still read.
  write_file(dir / "loose_comment.ply", "ply\nformat ascii 1.0\nCreated by some exporter\n" +
                                            vertex + "property float z\n" + face + "end_header\n" +
                                            body);
  EXPECT_EQ(import_mesh(dir / "loose_comment.ply").triangle_count(), 1u);
}

TEST(MeshImport, BinaryStlDeclaringTooManyTrianglesFailsFast) {
  TempDir dir;
  std::string stl(80, 'x');
  const std::uint32_t count = 100000000;
  for (int k = 0; k < 4; ++k) stl += static_cast<char>((count >> (8 * k)) & 0xff);
  stl += std::string(50, '\0');
  write_file(dir / "huge.stl", stl);
  EXPECT_NE(fast_error(dir / "huge.stl").find("100000000"), std::string::npos);
}

TEST(MeshImport, LimitsApply) {
  ImportOptions tight;
  tight.limits.max_triangles = 5;
  EXPECT_NE(import_error(kModels / "OBJ/box.obj", tight).find("box.obj"), std::string::npos);
  tight = {};
  tight.limits.max_vertices = 4;
  EXPECT_NE(import_error(kModels / "OBJ/box.obj", tight).find("box.obj"), std::string::npos);
}

TEST(MeshImport, ObjWithMoreVertexLinesThanTheLimitIsRefusedBeforeParsing) {
  TempDir dir;
  std::string obj;
  for (int i = 0; i < 40; ++i) obj += "v " + std::to_string(i) + " 0 0\n";
  obj += "v 0 1 0\nf 1 2 41\n";
  write_file(dir / "many.obj", obj);
  ImportOptions tight;
  tight.limits.max_vertices = 16;
  const std::string message = fast_error(dir / "many.obj", tight);
  EXPECT_NE(message.find("more than 16 vertex lines"), std::string::npos) << message;
}

TEST(MeshImport, BadObjLinesAreNamedByLine) {
  TempDir dir;
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  struct Case {
    const char* name;
    std::string text;
    const char* expected;
  };
  const Case cases[] = {
      {"short_vertex", "v 0 0 0\nv 1 0 0\nv 0 1\nf 1 2 3\n",
       "short_vertex.obj: line 3: a vertex needs three numbers (x y z), this one has 2: 'v 0 1'"},
      {"word_in_vertex", "v 0 0 0\n# a comment\nv 1 x 0\nv 0 1 0\nf 1 2 3\n",
       "word_in_vertex.obj: line 3: 'x' is not a number, in the vertex 'v 1 x 0'"},
      {"comment_for_a_number", "v 0 0 0\nv 1 0 # 0\nv 0 1 0\nf 1 2 3\n",
       "comment_for_a_number.obj: line 2: '#' is not a number"},
      {"comment_after_a_face", tri + "f 1 2 3 # the only face\n",
       "comment_after_a_face.obj: line 4: '#' is not a vertex number"},
      {"indented_vertex", "v 0 0 0\nv 1 0 0\n  v 0 1 0\nf 1 2 3\n",
       "indented_vertex.obj: line 3: '  v 0 1 0' is indented; a vertex line must start"},
      {"indented_face", tri + "\tf 1 2 3\n", "indented_face.obj: line 4: '\\tf 1 2 3' is indented"},
      {"leading_point", "v 0 0 0\nv 1 0 0\nv .5 1 0\nv 5 5 5\nf 1 2 3\n",
       "leading_point.obj: line 3: '.5' has no digit before its decimal point, in the vertex "
       "'v .5 1 0'; the OBJ reader cannot read it: write 0.5"},
      {"past_the_end", tri + "f 1 2 3\nf 1 2 7\nf 1 2 9\n",
       "past_the_end.obj: line 5: a face refers to vertex 7, but the file has 3 vertices"},
      {"relative_too_far", tri + "f 1 2 -4\n",
       "relative_too_far.obj: line 4: the face 'f 1 2 -4' refers to vertex -4, but only 3 "
       "vertices come before it"},
      {"zero", tri + "f 0 1 2\n", "zero.obj: line 4: '0' is not a vertex number"},
      {"binary", tri + "f 1 2 \x01\xff\n", "binary.obj: line 4: '?\?' is not a vertex number"},
      {"word_in_face", tri + "f 1/1 2/1 three/1\n",
       "word_in_face.obj: line 4: 'three/1' is not a vertex number"},
  };
  for (const Case& c : cases) {
    write_file(dir / (std::string(c.name) + ".obj"), c.text);
    const std::string message = import_error(dir / (std::string(c.name) + ".obj"));
    EXPECT_NE(message.find(c.expected), std::string::npos) << c.name << ": " << message;
  }
}

TEST(MeshImport, ObjLinesTheCheckLetThrough) {
  // What OBJ allows and assimp reads: a weight or a colour after x y z,
  // signs, exponents, a tab after the keyword, CRLF, a face before its
  // vertices, relative corners, texture and normal numbers, comment lines.
  TempDir dir;
  write_file(dir / "forms.obj",
             "# forms\r\nf 1/1/1 2/1/1 3/1/1\r\n"
             "v 0 0 0 1\r\nv\t+1e0 0 0 0.5 0.5 0.5\r\nv 0 1. -0.0\r\nv -.5 +.5 2.E-1 # top\r\n"
             "vt 0 0\r\nvn 0 0 1\r\nf -4//1 -3//1 -1//1\r\n");
  const ImportReport report = import_file(dir / "forms.obj");
  EXPECT_EQ(total_triangles(report), 2u);
}

// ---------------------------------------------------------------- transforms and parts

/// A glTF scene: `nodes_json` placed over one triangle mesh named "tri" with
/// vertices (0,0,0), (1,0,0), (0,1,0) from `buffer_uri` (written next to it
/// as tri.bin unless the uri says otherwise).
std::string gltf(const std::string& nodes_json, const std::string& scene_nodes,
                 const std::string& buffer_uri = "tri.bin") {
  return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":)" + scene_nodes +
         R"(}],"nodes":)" + nodes_json +
         R"(,"meshes":[{"name":"tri","primitives":[{"attributes":{"POSITION":0}}]}],)"
         R"("buffers":[{"uri":")" +
         buffer_uri +
         R"(","byteLength":36}],)"
         R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36}],)"
         R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",)"
         R"("min":[0,0,0],"max":[1,1,0]}]})";
}

std::string triangle_buffer() {
  const float xyz[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::string bytes(sizeof xyz, '\0');
  std::memcpy(bytes.data(), xyz, sizeof xyz);
  return bytes;
}

TEST(MeshImport, NodeTransformsAreAccumulated) {
  TempDir dir;
  write_file(dir / "tri.bin", triangle_buffer());
  // Parent moves by (10, 0, 0); child scales by 2 and turns 90 degrees about z.
  const double s = std::sqrt(0.5);
  write_file(dir / "scene.gltf",
             gltf(R"([{"name":"base","translation":[10,0,0],"children":[1]},)"
                  R"({"name":"arm","scale":[2,2,2],"rotation":[0,0,)" +
                      std::to_string(s) + "," + std::to_string(s) + R"(],"mesh":0}])",
                  "[0]"));
  const collision::Mesh mesh = import_mesh(dir / "scene.gltf");
  ASSERT_EQ(mesh.triangle_count(), 1u);
  const auto& tri = mesh.triangles[0];
  // p = (10,0,0) + Rz(90) * 2 * p_mesh
  EXPECT_TRUE(mesh.vertices[tri[0]].isApprox(Vec3(10, 0, 0), 1e-6));
  EXPECT_TRUE(mesh.vertices[tri[1]].isApprox(Vec3(10, 2, 0), 1e-6));
  EXPECT_TRUE(mesh.vertices[tri[2]].isApprox(Vec3(8, 0, 0), 1e-6));
  EXPECT_GT(triangle_normal(mesh, 0).z(), 0);
}

TEST(MeshImport, MirroringTransformKeepsNormalsOutward) {
  TempDir dir;
  write_file(dir / "tri.bin", triangle_buffer());
  write_file(dir / "mirror.gltf", gltf(R"([{"scale":[-1,1,1],"mesh":0}])", "[0]"));
  const collision::Mesh mesh = import_mesh(dir / "mirror.gltf");
  ASSERT_EQ(mesh.triangle_count(), 1u);
  // The unmirrored triangle faces +z; mirrored in x it still faces +z once the winding is turned.
  EXPECT_GT(triangle_normal(mesh, 0).z(), 0);
  EXPECT_LE(collision::mesh_bounds(mesh).max.x(), 0);
}

TEST(MeshImport, PartsAreNamedUniquelyPerInstance) {
  TempDir dir;
  write_file(dir / "tri.bin", triangle_buffer());
  write_file(
      dir / "parts.gltf",
      gltf(R"([{"name":"peg","mesh":0},{"name":"peg","translation":[0,0,5],"mesh":0},)"
           R"({"mesh":0,"translation":[0,0,9]},{"name":"peg_2","translation":[0,0,7],"mesh":0}])",
           "[0,1,2,3]"));
  ImportOptions per_part;
  per_part.merge = false;
  const ImportReport report = import_file(dir / "parts.gltf", per_part);
  ASSERT_EQ(report.parts.size(), 4u);
  std::set<std::string> names;
  for (const ImportedPart& part : report.parts) names.insert(part.name);
  EXPECT_EQ(names.size(), 4u);
  EXPECT_EQ(report.parts[0].name, "peg");
  EXPECT_EQ(report.parts[1].name, "peg_2");
  EXPECT_EQ(report.parts[1].mesh.vertices[0].z(), 5);
  EXPECT_EQ(report.parts[2].mesh.vertices[0].z(), 9);
  EXPECT_EQ(report.parts[3].mesh.vertices[0].z(), 7);
  EXPECT_NE(report.parts[3].name, "peg_2");

  // Merged: one mesh holding all four instances.
  const collision::Mesh merged = import_mesh(dir / "parts.gltf");
  EXPECT_EQ(merged.triangle_count(), 4u);
}

TEST(MeshImport, ObjObjectsWithOneNameStayApart) {
  // Three triangles at z = 0, 1, 2: a bracket, then two objects both named
  // washer, the second of them a pin exported under the washer's name.
  TempDir dir;
  const std::string file =
      "o bracket\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"
      "o washer\nv 0 0 1\nv 1 0 1\nv 0 1 1\nf 4 5 6\n"
      "o washer\nv 0 0 2\nv 1 0 2\nv 0 1 2\nf 7 8 9\n"
      "o bracket\nv 0 0 3\nv 1 0 3\nv 0 1 3\nf 10 11 12\n"
      "o washer_2\nv 0 0 4\nv 1 0 4\nv 0 1 4\nf 13 14 15\n";
  write_file(dir / "asm.obj", file);
  ImportOptions per_part;
  per_part.merge = false;
  const ImportReport report = import_file(dir / "asm.obj", per_part);
  ASSERT_EQ(report.parts.size(), 5u);
  // Each object is a part of its own, holding its own triangle, in file
  // order; a name the file itself uses (washer_2) is not given twice.
  const std::vector<std::string> names{"bracket", "washer", "washer_3", "bracket_2", "washer_2"};
  for (std::size_t k = 0; k < names.size(); ++k) {
    EXPECT_EQ(report.parts[k].name, names[k]);
    ASSERT_EQ(report.parts[k].mesh.triangle_count(), 1u) << names[k];
    EXPECT_EQ(report.parts[k].mesh.vertices[0].z(), static_cast<double>(k)) << names[k];
  }
  // Said, with the line of each renamed object.
  std::string notes;
  for (const std::string& note : report.notes) notes += note + "\n";
  EXPECT_NE(notes.find("line 11: the object 'washer' repeats an earlier name; it is read as "
                       "'washer_3'"),
            std::string::npos)
      << notes;
  EXPECT_NE(notes.find("line 16:"), std::string::npos) << notes;
  // The file itself is left as it was, and the merged import reads it all.
  EXPECT_EQ(read_file(dir / "asm.obj"), file);
  EXPECT_EQ(import_mesh(dir / "asm.obj").triangle_count(), 5u);
}

TEST(MeshImport, DegenerateTrianglesAreCounted) {
  TempDir dir;
  write_file(dir / "flat.obj",
             "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\n");  // second is collinear
  collision::MeshValidation validation;
  const collision::Mesh mesh = import_mesh(dir / "flat.obj", &validation);
  EXPECT_EQ(mesh.triangle_count(), 1u);
  EXPECT_EQ(validation.degenerate_removed, 1u);
  EXPECT_EQ(validation.unused_vertices, 1u);
}

TEST(MeshImport, TrianglesWithRepeatedVerticesAreRemovedWithANote) {
  TempDir dir;
  write_file(dir / "repeat.obj",
             "o a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\no b\nv 5 0 0\nv 6 0 0\nf 4 4 5\n");
  const ImportReport report = import_file(dir / "repeat.obj");
  EXPECT_EQ(total_triangles(report), 1u);
  bool noted = false;
  for (const std::string& note : report.notes) {
    noted = noted || note.find("1 triangle with a repeated vertex") != std::string::npos;
  }
  EXPECT_TRUE(noted);

  write_file(dir / "all_repeat.obj", "v 0 0 0\nv 1 0 0\nf 1 1 2\n");
  const std::string message = import_error(dir / "all_repeat.obj");
  EXPECT_NE(message.find("all_repeat.obj"), std::string::npos);
  EXPECT_NE(message.find("no usable triangles"), std::string::npos) << message;
}

TEST(MeshImport, SmallPartsKeepTheirTinyTriangles) {
  TempDir dir;
  // A 0.1 mm triangle (area 5e-9 m^2) is a real triangle, not a degenerate one.
  write_file(dir / "tiny.obj", "v 0 0 0\nv 0.0001 0 0\nv 0 0.0001 0\nf 1 2 3\n");
  EXPECT_EQ(import_mesh(dir / "tiny.obj").triangle_count(), 1u);
}

// ---------------------------------------------------------------- reading outside the folder

TEST(MeshImport, GltfBufferInItsFolderIsRead) {
  TempDir dir;
  write_file(dir / "model/tri.bin", triangle_buffer());
  write_file(dir / "model/ok.gltf", gltf(R"([{"mesh":0}])", "[0]"));
  EXPECT_EQ(import_mesh(dir / "model/ok.gltf").triangle_count(), 1u);
  // Also through a relative path with `..` that stays inside.
  write_file(dir / "model/sub/tri.bin", triangle_buffer());
  write_file(dir / "model/inside.gltf", gltf(R"([{"mesh":0}])", "[0]", "sub/../sub/tri.bin"));
  EXPECT_EQ(import_mesh(dir / "model/inside.gltf").triangle_count(), 1u);
}

TEST(MeshImport, GltfBufferOutsideItsFolderIsRefused) {
  TempDir dir;
  write_file(dir / "secret.bin", triangle_buffer());
  write_file(dir / "model/up.gltf", gltf(R"([{"mesh":0}])", "[0]", "../secret.bin"));
  std::string message = import_error(dir / "model/up.gltf");
  EXPECT_NE(message.find("up.gltf"), std::string::npos);
  EXPECT_NE(message.find("outside the model's folder"), std::string::npos) << message;
  EXPECT_NE(message.find("secret.bin"), std::string::npos) << message;

  write_file(dir / "model/deep.gltf", gltf(R"([{"mesh":0}])", "[0]", "a/../../secret.bin"));
  message = import_error(dir / "model/deep.gltf");
  EXPECT_NE(message.find("outside the model's folder"), std::string::npos) << message;

  const std::string absolute = (dir / "secret.bin").string();
  write_file(dir / "model/absolute.gltf", gltf(R"([{"mesh":0}])", "[0]", absolute));
  message = import_error(dir / "model/absolute.gltf");
  EXPECT_NE(message.find("absolute.gltf"), std::string::npos) << message;

  write_file(dir / "model/uri.gltf", gltf(R"([{"mesh":0}])", "[0]", "file://" + absolute));
  message = import_error(dir / "model/uri.gltf");
  EXPECT_NE(message.find("uri.gltf"), std::string::npos) << message;
}

TEST(MeshImport, ObjMaterialOutsideItsFolderIsNotRead) {
  TempDir dir;
  write_file(dir / "outside.mtl", "newmtl red\nKd 1 0 0\n");
  write_file(dir / "model/part.obj",
             "mtllib ../outside.mtl\nusemtl red\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const ImportReport report = import_file(dir / "model/part.obj");
  EXPECT_EQ(total_triangles(report), 1u);
  bool noted = false;
  for (const std::string& note : report.notes) {
    noted = noted || note.find("outside.mtl") != std::string::npos;
  }
  EXPECT_TRUE(noted) << "the refused material library is mentioned in the notes";
}

TEST(MeshImport, RelativePathsWork) {
  const fs::path before = fs::current_path();
  fs::current_path(kModels / "OBJ");
  collision::Mesh mesh;
  EXPECT_NO_THROW(mesh = import_mesh("box.obj"));
  fs::current_path(before);
  EXPECT_EQ(mesh.triangle_count(), 12u);
  EXPECT_EQ(mesh.source, "box.obj");
}

TEST(MeshImport, CheckedInTestData) {
  EXPECT_EQ(import_mesh(kData / "cube.obj").triangle_count(), 12u);
  EXPECT_EQ(import_mesh(kData / "tetrahedron.obj").triangle_count(), 4u);
}

}  // namespace
}  // namespace dovetail::engine

namespace dovetail::engine {
namespace {

TEST(MeshImport, GltfCamerasArePosedByTheirNodeOnly) {
  // camera_plate.gltf: a perspective camera "wide" (yfov 0.8 rad, aspect 1.5)
  // on a node translated to (0.5, 0.5, 3) and turned 90 degrees about y, so
  // it looks along -x; an orthographic camera "flat", skipped with a note.
  const ImportReport report = import_file(fs::path(DOVETAIL_TEST_DATA) / "camera_plate.gltf");
  ASSERT_EQ(report.cameras.size(), 1u);
  const auto& [name, camera] = report.cameras[0];
  EXPECT_EQ(name, "wide");
  // The node's translation once (assimp 5.2 also copies it into the camera).
  EXPECT_NEAR((camera.eye - collision::Vec3(0.5, 0.5, 3)).norm(), 0, 1e-6);
  const collision::Vec3 look = (camera.target - camera.eye).normalized();
  EXPECT_NEAR((look - collision::Vec3(-1, 0, 0)).norm(), 0, 1e-6);
  EXPECT_NEAR((camera.up.normalized() - collision::Vec3(0, 1, 0)).norm(), 0, 1e-6);
  EXPECT_NEAR(camera.fov_y_degrees, 0.8 * 180 / std::numbers::pi, 1e-4);
  ASSERT_FALSE(report.notes.empty());
  EXPECT_NE(report.notes.back().find("orthographic camera 'flat'"), std::string::npos);
}

}  // namespace
}  // namespace dovetail::engine
