#include "import_process.h"

#include <gtest/gtest.h>

#include <csignal>
#include <cstdlib>
#include <string>
#include <vector>

#include "dovetail/engine/mesh_import.h"

namespace dovetail::engine {
namespace {

namespace fs = std::filesystem;

const fs::path kModels = DOVETAIL_ASSIMP_MODELS;
const fs::path kData = DOVETAIL_TEST_DATA;

constexpr std::uintmax_t kGiB = std::uintmax_t{1} << 30;

/// The message of the ImportError that `run` throws; fails the test when it
/// throws nothing or something else.
template <typename Run>
std::string import_error(Run&& run) {
  try {
    run();
  } catch (const ImportError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "threw something other than ImportError: " << e.what();
    return {};
  }
  ADD_FAILURE() << "imported without error";
  return {};
}

TEST(ImportProcess, AReportFromTheChildIsTheSameBitsAsOneReadHere) {
  const std::vector<fs::path> files = {
      kData / "cube.obj", kData / "camera_plate.gltf", kData / "external_buffer.gltf",
      kModels / "glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb"};
  for (const fs::path& file : files) {
    for (const bool merge : {true, false}) {
      SCOPED_TRACE(file.string() + (merge ? " merged" : " per part"));
      ImportOptions here;
      here.merge = merge;
      here.part_frames = !merge;
      here.in_child_process = false;
      ImportOptions child = here;
      child.in_child_process = true;
      const ImportReport a = import_file(file, here);
      const ImportReport b = import_file(file, child);
      ASSERT_EQ(a.parts.size(), b.parts.size());
      for (std::size_t i = 0; i < a.parts.size(); ++i) {
        EXPECT_EQ(a.parts[i].name, b.parts[i].name);
        EXPECT_EQ(a.parts[i].mesh.vertices, b.parts[i].mesh.vertices);
        EXPECT_EQ(a.parts[i].mesh.triangles, b.parts[i].mesh.triangles);
        EXPECT_EQ(a.parts[i].mesh.source, b.parts[i].mesh.source);
        EXPECT_EQ(a.parts[i].X_RP.R, b.parts[i].X_RP.R);
        EXPECT_EQ(a.parts[i].X_RP.t, b.parts[i].X_RP.t);
      }
      EXPECT_EQ(a.cameras, b.cameras);
      EXPECT_EQ(a.notes, b.notes);
      EXPECT_EQ(a.files, b.files);
      // Every field, validation and counts included, byte for byte.
      EXPECT_EQ(detail::encode_report(a), detail::encode_report(b));
    }
  }
}

TEST(ImportProcess, AnEncodedReportCutShortOrGarbledIsRefused) {
  const std::string whole = detail::encode_report(import_file(kData / "cube.obj"));
  EXPECT_EQ(detail::encode_report(detail::decode_report(whole)), whole);
  for (const std::size_t keep :
       {std::size_t{0}, std::size_t{7}, whole.size() / 2, whole.size() - 1}) {
    EXPECT_THROW(detail::decode_report(whole.substr(0, keep)), std::runtime_error) << keep;
  }
  EXPECT_THROW(detail::decode_report(whole + "x"), std::runtime_error);
  std::string garbled = whole;
  garbled[0] ^= 1;
  EXPECT_THROW(detail::decode_report(garbled), std::runtime_error);
}

TEST(ImportProcess, AnImportErrorInTheChildIsThrownHereWithItsMessage) {
  const std::string message = import_error([] {
    detail::import_in_child(
        "part.obj", []() -> ImportReport { throw ImportError("part.obj: line 3: no vertex"); },
        kGiB);
  });
  EXPECT_EQ(message, "part.obj: line 3: no vertex");
  const std::string other = import_error([] {
    detail::import_in_child(
        "part.obj", []() -> ImportReport { throw std::logic_error("inside"); }, kGiB);
  });
  EXPECT_EQ(other, "part.obj: cannot be read as a mesh: inside");
}

TEST(ImportProcess, AnythingElseTheChildThrowsIsAnErrorNamingTheFile) {
  // Not an exception of the standard library's: named, not passed on.
  const std::string message = import_error([] {
    detail::import_in_child(
        "odd.obj", []() -> ImportReport { throw 42; }, kGiB);
  });
  EXPECT_EQ(message, "odd.obj: cannot be read as a mesh: unknown failure in the importer");
}

TEST(ImportProcess, AChildThatDiesOfASignalIsAnErrorNamingTheFileAndTheSignal) {
  const std::string message = import_error([] {
    detail::import_in_child(
        "broken.gltf", []() -> ImportReport { std::abort(); }, kGiB);
  });
  EXPECT_EQ(message.rfind("broken.gltf: ", 0), 0u) << message;
  EXPECT_NE(message.find("crashed"), std::string::npos) << message;
  EXPECT_NE(message.find("SIGABRT"), std::string::npos) << message;
}

TEST(ImportProcess, AChildPastItsMemoryBudgetRunsOutOfMemory) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "the budget is an address-space limit, which sanitizers' shadow memory rules out";
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || \
    __has_feature(memory_sanitizer)
  GTEST_SKIP() << "the budget is an address-space limit, which sanitizers' shadow memory rules out";
#endif
#endif
  const std::string message = import_error([] {
    detail::import_in_child(
        "huge.ply",
        []() -> ImportReport {
          // A call of the allocation function, which (unlike a new-expression)
          // the compiler may not leave out.
          void* eight_gib = ::operator new(8 * kGiB);
          ::operator delete(eight_gib);
          return {};
        },
        kGiB);
  });
  EXPECT_EQ(message, "huge.ply: ran out of memory while reading");
}

/// Files on which assimp 5.2.5, Debian 12's, reads through a null pointer
/// (found by fuzzing): each is an ImportError naming the file, never a crash.
/// A later assimp may read them; then they must import cleanly.
TEST(ImportProcess, FilesThatCrashTheImporterAreErrorsNamingTheFile) {
  std::size_t files = 0;
  for (const fs::directory_entry& entry : fs::directory_iterator(kData / "crashes_assimp")) {
    ++files;
    const fs::path file = entry.path();
    SCOPED_TRACE(file.string());
    try {
      const ImportReport report = import_file(file);
      EXPECT_FALSE(report.parts.empty());
    } catch (const ImportError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(file.string() + ": ", 0), 0u) << e.what();
    }
  }
  EXPECT_EQ(files, 2u);
}

}  // namespace
}  // namespace dovetail::engine
