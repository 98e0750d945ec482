#include "dovetail/collision/capture.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "dovetail/collision/collision_world.h"
#include "dovetail/collision/primitives.h"

namespace dovetail::collision {
namespace {

namespace fs = std::filesystem;

class TempDir {
 public:
  TempDir() {
    path_ =
        fs::temp_directory_path() /
        ("dovetail-capture-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
         "-" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

/// Two boxes, B resting on A's top, turned by a general rotation: a touching,
/// nearly coplanar pair, the kind of query that is worth keeping.
Capture resting_boxes() {
  const Mat3 Q = Eigen::AngleAxis<Real>(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  Capture c;
  c.kind = CaptureKind::kMethodsDisagree;
  c.what = "obb says intersecting,\nboxtree says separate";  // a newline is flattened
  c.context = "step 3: 'a' and 'b'";
  c.a = std::make_shared<const Mesh>(make_box(Vec3(2, 2, 1)));
  c.b = std::make_shared<const Mesh>(make_box(Vec3(1, 0.5, 0.5)));
  c.X_AB.R = Q;
  c.X_AB.t = Q * Vec3(0.5, 0, 1.5);
  return c;
}

void write_text(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
}

std::string read_error(const fs::path& file) {
  try {
    read_capture(file);
  } catch (const CaptureError& e) {
    return e.what();
  }
  ADD_FAILURE() << file << " was read";
  return "";
}

TEST(Capture, WrittenAndReadBackBitForBit) {
  TempDir dir;
  Capture c = resting_boxes();
  // Values that decimal printing would not give back exactly.
  auto odd = std::make_shared<Mesh>(*c.b);
  odd->vertices[0] = Vec3(-0.0, std::numeric_limits<Real>::denorm_min(), 0.1 + 0.2);
  odd->vertices[1] = Vec3(1e300, -std::nextafter(1.0, 2.0), 1.0 / 3.0);
  odd->source = "odd box";
  c.b = odd;
  const fs::path file = dir.path() / "c.capture";
  write_text(file, capture_text(c));
  const Capture back = read_capture(file);
  EXPECT_EQ(back.kind, c.kind);
  EXPECT_EQ(back.what, "obb says intersecting, boxtree says separate");
  EXPECT_EQ(back.context, c.context);
  EXPECT_EQ(back.X_AB.R, c.X_AB.R);
  EXPECT_EQ(back.X_AB.t, c.X_AB.t);
  ASSERT_EQ(back.b->vertices.size(), c.b->vertices.size());
  for (std::size_t i = 0; i < c.b->vertices.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(std::signbit(back.b->vertices[i][k]), std::signbit(c.b->vertices[i][k]));
      EXPECT_EQ(back.b->vertices[i][k], c.b->vertices[i][k]) << i << " " << k;
    }
  }
  EXPECT_EQ(back.a->triangles, c.a->triangles);
  EXPECT_EQ(back.b->source, "odd box");
  // Same capture, same bytes.
  EXPECT_EQ(capture_text(back), capture_text(c));
}

TEST(Capture, ReplayOfAgreeingMethodsIsNotReproduced) {
  const CaptureReplay replay = replay_capture(resting_boxes());
  EXPECT_FALSE(replay.reproduced) << replay.what;
  EXPECT_EQ(replay.what, "every method says intersecting");
  Capture apart = resting_boxes();
  apart.X_AB.t += Vec3(10, 0, 0);
  EXPECT_EQ(replay_capture(apart).what, "every method says separate");
}

TEST(Capture, ReplayOfASearchCapOnSimpleHullsIsNotReproduced) {
  Capture c = resting_boxes();
  c.kind = CaptureKind::kIterationCap;
  const CaptureReplay replay = replay_capture(c);
  EXPECT_FALSE(replay.reproduced) << replay.what;
  EXPECT_NE(replay.what.find("GJK took"), std::string::npos) << replay.what;
}

TEST(Capture, ReplayOfANonFinitePoseReturns) {
  Capture c = resting_boxes();
  c.kind = CaptureKind::kNonFinite;
  c.X_AB.t.x() = std::numeric_limits<Real>::quiet_NaN();
  const CaptureReplay replay = replay_capture(c);
  EXPECT_FALSE(replay.reproduced);
  EXPECT_EQ(replay.what, "the input is not finite; every method returned");
}

TEST(Capture, BadFilesNameTheFileAndLine) {
  TempDir dir;
  const std::string good = capture_text(resting_boxes());
  struct Case {
    std::string name, text, expected;
  };
  std::string bad_vertex = good;
  bad_vertex.replace(bad_vertex.find("mesh a"), 0, "");
  const std::size_t v = good.find('\n', good.find("mesh a")) + 1;  // first vertex of a
  bad_vertex.replace(v, good.find('\n', v) - v, "0x1p0 zebra 3");
  std::string nan_vertex = good;
  nan_vertex.replace(v, good.find('\n', v) - v, "0 nan 3");
  std::string bad_index = good;
  const std::size_t t = good.rfind("\nend\n");
  const std::size_t last = good.rfind('\n', t - 1) + 1;  // last triangle of b
  bad_index.replace(last, t - last, "0 1 99");
  // A pose whose first entry of R is changed is no rotation; a NaN in it is not finite.
  const std::size_t x = good.find("X_AB ") + 5;
  const std::size_t x_end = good.find(' ', x);
  std::string not_rotation = good;
  not_rotation.replace(x, x_end - x, "0.78");
  std::string nan_pose = good;
  nan_pose.replace(x, x_end - x, "nan");
  const std::vector<Case> cases = {
      {"magic.capture", "dovetail-capture 2\n", ":1: not a capture file"},
      {"rotation.capture", not_rotation, ":5: X_AB's R is not a rotation"},
      {"nan_pose.capture", nan_pose, ":5: X_AB is not finite"},
      {"trailing.capture", good + "\nmore\n", "text after 'end'"},
      {"empty.capture", "", ": empty"},
      {"kind.capture", "dovetail-capture 1\nkind overheated\n", ":2: unknown kind 'overheated'"},
      {"short.capture", good.substr(0, good.find("mesh b")), "ends early, expecting a mesh"},
      {"vertex.capture", bad_vertex, "expected a vertex: x y z, found '0x1p0 zebra 3'"},
      {"nan.capture", nan_vertex, "a vertex is not finite"},
      {"index.capture", bad_index, "vertex index 99 is past the mesh's 8 vertices"},
      {"end.capture", good.substr(0, t + 1) + "more\n", "expected 'end'"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path file = dir.path() / c.name;
    write_text(file, c.text);
    const std::string message = read_error(file);
    EXPECT_EQ(message.rfind(file.string() + ":", 0), 0u) << message;
    EXPECT_NE(message.find(c.expected), std::string::npos) << message;
  }
  EXPECT_NE(read_error(dir.path() / "missing.capture").find("cannot be opened"), std::string::npos);
}

TEST(Capture, SinkWritesEachDistinctCaptureOnceFromAnyThread) {
  TempDir dir;
  CaptureSink sink(dir.path() / "out", 3);
  std::vector<std::thread> threads;
  for (int i = 0; i < 8; ++i) {
    threads.emplace_back([&sink, i] {
      for (int k = 0; k < 20; ++k) {
        Capture c = resting_boxes();
        c.context = "thread " + std::to_string((i + k) % 2);  // two distinct captures
        sink.record(c);
      }
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(sink.recorded(), 160u);
  ASSERT_EQ(sink.files().size(), 2u);
  for (const fs::path& file : sink.files()) {
    EXPECT_EQ(file.filename().string().rfind("methods-disagree-", 0), 0u) << file;
    EXPECT_EQ(read_capture(file).context.rfind("thread ", 0), 0u);
  }
  // The cap: later distinct captures are counted, not written.
  for (int k = 0; k < 5; ++k) {
    Capture c = resting_boxes();
    c.context = "more " + std::to_string(k);
    sink.record(c);
  }
  EXPECT_EQ(sink.files().size(), 3u);
  EXPECT_EQ(sink.recorded(), 165u);
  EXPECT_EQ(sink.failed_writes(), 0u);
}

TEST(Capture, TheWorldCapturesAPoseThatIsNotFinite) {
  TempDir dir;
  CaptureSink sink(dir.path());
  CollisionWorld world({.capture = &sink, .cross_check = Method::kBrute});
  const auto box = std::make_shared<const Mesh>(make_box(Vec3(1, 1, 1)));
  const PartId a = world.add_part({.mesh = box, .X_WP = Transform{}, .name = "a"});
  Transform X;
  X.t = Vec3(0.5, 0, 0);
  const PartId b = world.add_part({.mesh = box, .X_WP = X, .name = "b"});
  world.step();
  EXPECT_EQ(sink.recorded(), 0u);  // obb and brute force agree on overlapping boxes
  X.t.y() = std::numeric_limits<Real>::quiet_NaN();
  world.set_pose(b, X);
  world.step();  // must come back
  ASSERT_EQ(sink.files().size(), 1u);
  const Capture c = read_capture(sink.files()[0]);
  EXPECT_EQ(c.kind, CaptureKind::kNonFinite);
  EXPECT_EQ(c.context, "step 1: 'a' and 'b'");
  EXPECT_TRUE(std::isnan(c.X_AB.t.y()));
  EXPECT_FALSE(replay_capture(c).reproduced);
  (void)a;
}

// Every capture checked in under tests/data/captures/ is a suspect query that
// was fixed (or found harmless): its replay must not reproduce it.
TEST(Capture, CheckedInCapturesNoLongerReproduce) {
  const fs::path folder = fs::path(DOVETAIL_TEST_DATA) / "captures";
  std::size_t files = 0;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
    if (entry.path().extension() != ".capture") continue;
    ++files;
    SCOPED_TRACE(entry.path().string());
    const CaptureReplay replay = replay_capture(read_capture(entry.path()));
    EXPECT_FALSE(replay.reproduced) << replay.what;
  }
  EXPECT_GT(files, 0u);
}

}  // namespace
}  // namespace dovetail::collision
