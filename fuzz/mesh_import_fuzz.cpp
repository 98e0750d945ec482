// Mesh import (engine::import_file): the input is written to a file whose
// extension (DOVETAIL_FUZZ_EXTENSION) picks the reader, then imported. Either
// it throws MeshError (ImportError is one) or it gives a valid mesh: finite
// vertices, triangles indexing them. The importer runs in this process, not
// in the child process users get, so that its own crashes, leaks and memory
// blow-ups stay visible to the fuzzer.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <utility>

#include "dovetail/engine/mesh_import.h"
#include "fuzz_support.h"

#ifndef DOVETAIL_FUZZ_EXTENSION
#error "DOVETAIL_FUZZ_EXTENSION must name the file extension, e.g. \".obj\""
#endif

using namespace dovetail;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = fuzz::scratch_dir() / ("input" DOVETAIL_FUZZ_EXTENSION);
  fuzz::write_file(path, fuzz::as_text(data, size));
  collision::Mesh mesh;
  try {
    engine::ImportOptions options;
    options.in_child_process = false;
    mesh = std::move(engine::import_file(path, options).parts.front().mesh);
  } catch (const collision::MeshError&) {
    return 0;
  }
  fuzz::require(mesh.triangle_count() > 0, "an imported mesh has triangles");
  for (const collision::Vec3& v : mesh.vertices)
    fuzz::require(v.allFinite(), "vertices are finite");
  for (const collision::TriangleIndices& t : mesh.triangles) {
    for (std::size_t k = 0; k < 3; ++k) {
      fuzz::require(t[k] < mesh.vertex_count(), "triangles index existing vertices");
    }
  }
  return 0;
}
