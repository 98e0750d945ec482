#include "dovetail/engine/simulation.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "dovetail/collision/primitives.h"

namespace dovetail::engine {
namespace {

namespace fs = std::filesystem;
using collision::Vec3;

const fs::path kEngine =
    fs::path(DOVETAIL_ASSIMP_MODELS) / "glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";

/// Simulated time of frame k at the default step, as the loop computes it.
double frame_time(std::uint64_t k) { return static_cast<double>(k) * (1.0 / 90.0); }

Transform at(double x, double y, double z) {
  Transform X;
  X.t = Vec3(x, y, z);
  return X;
}

/// A fixed block at the origin, a slider at x = 3 with a child 2 above it,
/// and a sphere far away; all boxes have half-size 0.5.
Scene test_scene() {
  const auto cube =
      std::make_shared<const collision::Mesh>(collision::make_box(Vec3::Constant(0.5)));
  const auto ball = std::make_shared<const collision::Mesh>(collision::make_sphere(0.5, 3));
  Scene scene;
  scene.add_part({.name = "block", .tags = {"fixture"}, .movable = false, .render_mesh = cube});
  scene.add_part({.name = "slider", .X_QP = at(3, 0, 0), .render_mesh = cube});
  scene.add_part({.name = "rider", .parent = "slider", .X_QP = at(0, 2, 0), .render_mesh = ball});
  scene.add_part({.name = "ball", .X_QP = at(-5, 0, 0), .render_mesh = ball});
  return scene;
}

/// The slider enters the block at frame 5 and leaves at frame 10; the ball
/// rolls into the block at frame 12 and stays; timers at 0 and 0.05 s; a region.
Simulation scripted(int threads,
                    collision::ContactDetail detail = collision::ContactDetail::kPairs) {
  Simulation sim(test_scene(), {.collision_threads = threads, .contacts = detail});
  sim.queue_pose({5, "slider", at(0.9, 0, 0)});
  sim.queue_pose({10, "slider", at(3, 0, 0)});
  sim.queue_pose({12, "ball", at(-0.95, 0.1, 0)});
  sim.add_timer("start", 0.0);
  sim.add_timer("later", 0.05);  // 0.05 * 90 = 4.5: the first frame at or after is 5
  sim.add_region({.name = "goal", .box = {Vec3(0.6, -1, -1), Vec3(2, 1, 1)}});
  return sim;
}

std::vector<Event> only(const std::vector<Event>& events, EventKind kind) {
  std::vector<Event> out;
  for (const Event& e : events) {
    if (e.kind == kind) out.push_back(e);
  }
  return out;
}

TEST(Simulation, ContactsBeginAndEndInTheExpectedFrames) {
  Simulation sim = scripted(1);
  std::vector<Event> seen;
  sim.events().subscribe_all([&](const Event& e) { seen.push_back(e); });
  EXPECT_EQ(sim.run(20), 20u);
  EXPECT_EQ(sim.frame(), 20u);
  EXPECT_EQ(sim.time(), frame_time(20));

  const std::vector<Event> begins = only(seen, EventKind::kContactBegin);
  const std::vector<Event> ends = only(seen, EventKind::kContactEnd);
  ASSERT_EQ(begins.size(), 2u);
  EXPECT_EQ(begins[0], (Event{EventKind::kContactBegin, 5, frame_time(5), "block", "slider"}));
  EXPECT_EQ(begins[1], (Event{EventKind::kContactBegin, 12, frame_time(12), "ball", "block"}));
  ASSERT_EQ(ends.size(), 1u);
  EXPECT_EQ(ends[0], (Event{EventKind::kContactEnd, 10, frame_time(10), "block", "slider"}));

  // The slider carries its rider: both moved at 5 and 10.
  const std::vector<Event> moved = only(seen, EventKind::kPartMoved);
  ASSERT_EQ(moved.size(), 5u);
  EXPECT_EQ(moved[0].frame, 5u);
  EXPECT_EQ(moved[0].a, "rider");
  EXPECT_EQ(moved[1].a, "slider");
  EXPECT_TRUE(sim.scene().world_pose("rider").t.isApprox(Vec3(3, 2, 0)));
  // Part-moved events stay out of the timeline by default.
  EXPECT_TRUE(only(sim.report().events, EventKind::kPartMoved).empty());
  EXPECT_EQ(sim.report().events.size(), seen.size() - moved.size());

  // Delivery order is event_less.
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end(), event_less));

  // Contact statistics per pair.
  const std::vector<PairContactStats>& stats = sim.report().contacts;
  ASSERT_EQ(stats.size(), 2u);
  EXPECT_EQ(stats[0].a, "ball");
  EXPECT_EQ(stats[0].first_frame, 12u);
  EXPECT_EQ(stats[0].last_frame, 19u);
  EXPECT_EQ(stats[0].frames_in_contact, 8u);
  EXPECT_GT(stats[0].max_contacts, 0u);
  EXPECT_EQ(stats[1].a, "block");
  EXPECT_EQ(stats[1].b, "slider");
  EXPECT_EQ(stats[1].frames_in_contact, 5u);
  EXPECT_EQ(stats[1].first_frame, 5u);
  EXPECT_EQ(stats[1].last_frame, 9u);
}

TEST(Simulation, TimersAndRegionsFireInTheRightFrames) {
  Simulation sim = scripted(1);
  sim.run(20);
  const std::vector<Event> timers = only(sim.report().events, EventKind::kTimer);
  ASSERT_EQ(timers.size(), 2u);
  EXPECT_EQ(timers[0].a, "start");
  EXPECT_EQ(timers[0].frame, 0u);
  EXPECT_EQ(timers[1].a, "later");
  EXPECT_EQ(timers[1].frame, 5u);

  const std::vector<Event> enter = only(sim.report().events, EventKind::kRegionEnter);
  const std::vector<Event> leave = only(sim.report().events, EventKind::kRegionLeave);
  ASSERT_EQ(enter.size(), 1u);
  EXPECT_EQ(enter[0], (Event{EventKind::kRegionEnter, 5, frame_time(5), "slider", "goal"}));
  ASSERT_EQ(leave.size(), 1u);
  EXPECT_EQ(leave[0], (Event{EventKind::kRegionLeave, 10, frame_time(10), "slider", "goal"}));

  // A region watching named parts only.
  Simulation watched(test_scene());
  watched.add_region(
      {.name = "around_block", .box = {Vec3(-1, -1, -1), Vec3(1, 1, 1)}, .parts = {"ball"}});
  watched.queue_pose({3, "ball", at(-1.2, 0, 0)});
  watched.run(5);
  const std::vector<Event> in = only(watched.report().events, EventKind::kRegionEnter);
  ASSERT_EQ(in.size(), 1u);
  EXPECT_EQ(in[0].a, "ball");
  EXPECT_EQ(in[0].frame, 3u);
  EXPECT_THROW(watched.add_region({.name = "around_block"}), SceneError);
  EXPECT_THROW(watched.add_region({.name = "x", .parts = {"nobody"}}), SceneError);
}

TEST(Simulation, SameEventsHashAndReportForAnyThreadCount) {
  std::vector<std::string> reports;
  std::vector<std::uint64_t> hashes;
  for (const int threads : {1, 2, 8}) {
    Simulation sim = scripted(threads);
    sim.run(20);
    reports.push_back(sim.report().to_json());
    hashes.push_back(sim.state_hash());
  }
  EXPECT_EQ(reports[0], reports[1]);
  EXPECT_EQ(reports[0], reports[2]);
  EXPECT_EQ(hashes[0], hashes[1]);
  EXPECT_EQ(hashes[0], hashes[2]);
  EXPECT_NE(reports[0].find("\"kind\": \"contact_begin\", \"a\": \"block\", \"b\": \"slider\""),
            std::string::npos)
      << reports[0];
  EXPECT_EQ(reports[0].find("timings"), std::string::npos);
}

TEST(Simulation, TriangleContactsCountedAndDeterministic) {
  std::vector<std::string> reports;
  for (const int threads : {1, 2, 8}) {
    Simulation sim = scripted(threads, collision::ContactDetail::kTriangles);
    sim.run(20);
    reports.push_back(sim.report().to_json());
    const std::vector<PairContactStats>& stats = sim.report().contacts;
    ASSERT_EQ(stats.size(), 2u);
    // Every intersecting triangle pair counts; the pairs are those of the pairs-only run.
    EXPECT_GT(stats[0].max_contacts, 1u);
    EXPECT_GT(stats[1].max_contacts, 1u);
    EXPECT_EQ(stats[1].frames_in_contact, 5u);
  }
  EXPECT_EQ(reports[0], reports[1]);
  EXPECT_EQ(reports[0], reports[2]);
  Simulation pairs = scripted(1);
  pairs.run(20);
  EXPECT_EQ(only(pairs.report().events, EventKind::kContactBegin).size(), 2u);
  EXPECT_EQ(pairs.report().contacts[0].max_contacts, 1u);
}

TEST(Simulation, EngineAssemblyIsDeterministicAcrossThreads) {
  // A real CAD assembly: every part touches its neighbours; two parts are
  // pushed through the others frame by frame.
  std::vector<std::string> reports;
  for (const int threads : {1, 2, 8}) {
    Simulation sim(load_assembly(kEngine), {.collision_threads = threads});
    const std::vector<PartId> parts = sim.scene().parts();
    const std::string mover = sim.scene().name(parts[parts.size() / 2]);
    const Transform X_start = sim.scene().local_pose(parts[parts.size() / 2]);
    sim.set_frame_hook([&](Simulation& s, std::uint64_t frame, double) {
      Transform X = X_start;
      X.t.x() += 0.004 * static_cast<double>(frame);
      s.scene().set_local_pose(mover, X);
    });
    sim.run(6);
    reports.push_back(sim.report().to_json());
    EXPECT_FALSE(sim.report().contacts.empty());
  }
  EXPECT_EQ(reports[0], reports[1]);
  EXPECT_EQ(reports[0], reports[2]);
}

TEST(Simulation, StateHashFollowsPosesBitForBit) {
  Simulation a(test_scene());
  Simulation b(test_scene());
  EXPECT_EQ(a.state_hash(), b.state_hash());
  EXPECT_EQ(a.state_hash(), state_hash(a.scene()));
  a.queue_pose({1, "ball", at(-5, 0, std::nextafter(0.0, 1.0))});
  a.run(2);
  b.run(2);
  EXPECT_NE(a.state_hash(), b.state_hash());
  EXPECT_EQ(b.last_frame().state_hash, b.state_hash());
}

TEST(Simulation, StateHashSeesMovesMadeBySubscribers) {
  // The hash folded while the poses are committed is used only while the
  // scene is unchanged; a subscriber that moves a part during the frame
  // changes the scene after the commit, and the hash must show it.
  Simulation sim(test_scene());
  int moves = 0;
  sim.events().subscribe_all([&](const Event&) {
    if (moves >= 3) return;
    Transform X = sim.scene().local_pose(sim.scene().get("ball"));
    X.t.z() += 0.25;
    sim.scene().set_local_pose("ball", X);
    ++moves;
  });
  sim.queue_pose({1, "ball", at(-5, 0, 0.5)});
  for (int f = 0; f < 6; ++f) {
    sim.step();
    EXPECT_EQ(sim.state_hash(), state_hash(sim.scene())) << "frame " << f;
    EXPECT_EQ(sim.last_frame().state_hash, sim.state_hash());
  }
  EXPECT_EQ(moves, 3);
}

/// The state hash recomputed from its definition in docs/engine.md,
/// independently of the engine.
std::uint64_t documented_state_hash(const Scene& scene, std::vector<std::string> names) {
  std::sort(names.begin(), names.end());
  std::uint64_t h = 0xcbf29ce484222325ull;
  auto feed = [&](std::uint64_t word) {
    h = (h ^ word) * 0x100000001b3ull;
    h ^= h >> 32;
  };
  for (const std::string& name : names) {
    // The name and a 0 byte, in little-endian 8-byte words, zero-padded.
    std::string bytes = name + '\0';
    bytes.resize((bytes.size() + 7) / 8 * 8, '\0');
    for (std::size_t i = 0; i < bytes.size(); i += 8) {
      std::uint64_t word = 0;
      for (int k = 7; k >= 0; --k) word = (word << 8) | static_cast<unsigned char>(bytes[i + k]);
      feed(word);
    }
    const Transform X_WP = scene.world_pose(name);
    std::vector<double> values;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) values.push_back(X_WP.R(r, c));
    }
    for (int k = 0; k < 3; ++k) values.push_back(X_WP.t(k));
    for (const double v : values) {
      std::uint64_t bits = 0;
      std::memcpy(&bits, &v, sizeof(bits));
      feed(bits);
    }
  }
  return h;
}

TEST(Simulation, StateHashIsTheDocumentedWordHash) {
  const Scene scene = test_scene();
  EXPECT_EQ(state_hash(scene), documented_state_hash(scene, {"ball", "block", "rider", "slider"}));
  // Names that end exactly at, just before and just after a word boundary.
  Scene named;
  const auto mesh = std::make_shared<const collision::Mesh>(collision::make_box(Vec3(1, 1, 1)));
  std::vector<std::string> names = {"seven77",          "eight888",          "fifteen15151515",
                                    "sixteen161616161", "seventeen17171717", "x"};
  for (std::size_t i = 0; i < names.size(); ++i) {
    named.add_part({.name = names[i],
                    .X_QP = at(0.5 * static_cast<double>(i), 0.25, -1),
                    .render_mesh = mesh});
  }
  EXPECT_EQ(state_hash(named), documented_state_hash(named, names));
}

TEST(Simulation, PauseStepAndSubscribers) {
  Simulation sim = scripted(1);
  int begins = 0;
  const EventBus::SubscriptionId id =
      sim.events().subscribe(EventKind::kContactBegin, [&](const Event&) {
        ++begins;
        sim.set_paused(true);
      });
  EXPECT_EQ(sim.run(100), 6u);  // paused by the subscriber in frame 5
  EXPECT_EQ(begins, 1);
  EXPECT_EQ(sim.run(100), 0u);
  sim.step();  // stepping works while paused
  EXPECT_EQ(sim.frame(), 7u);
  sim.events().unsubscribe(id);
  sim.set_paused(false);
  sim.run(20);
  EXPECT_EQ(begins, 1);
  EXPECT_EQ(sim.frame(), 27u);
}

TEST(Simulation, PartsAddedAndRemovedBetweenFrames) {
  Simulation sim(test_scene());
  sim.run(2);
  sim.scene().add_part({.name = "late",
                        .X_QP = at(0.5, 0.5, 0),
                        .render_mesh = std::make_shared<const collision::Mesh>(
                            collision::make_box(Vec3::Constant(0.2)))});
  sim.step();
  ASSERT_EQ(sim.last_frame().events.size(), 1u);
  EXPECT_EQ(sim.last_frame().events[0].kind, EventKind::kContactBegin);
  EXPECT_EQ(sim.last_frame().events[0].b, "late");
  EXPECT_TRUE(sim.collision_id(sim.scene().get("late")).valid());
  sim.scene().remove_part(sim.scene().get("late"));
  sim.step();
  ASSERT_EQ(sim.last_frame().events.size(), 1u);
  EXPECT_EQ(sim.last_frame().events[0].kind, EventKind::kContactEnd);
  EXPECT_EQ(sim.last_frame().events[0].b, "late");
}

TEST(Simulation, BadInputIsRefused) {
  EXPECT_THROW(Simulation(test_scene(), {.time_step = 0}), std::invalid_argument);
  Simulation sim(test_scene());
  EXPECT_THROW(sim.queue_pose({1, "nobody", {}}), SceneError);
}

TEST(Report, JsonFieldsAndTimingsApart) {
  Simulation sim = scripted(1);
  sim.run(12);
  const Report& report = sim.report();
  const std::string json = report.to_json();
  for (const char* field :
       {"\"format\": \"dovetail-report\"", "\"time_step\": 0.011111111111111112", "\"frames\": 12",
        "\"parts\": 4", "\"state_hash\": \"0x", "\"events\": [", "\"contacts\": [",
        "\"frames_in_contact\": 5", "\"kind\": \"timer\", \"a\": \"later\"",
        "\"collision_plans\": [\n    {\"a\": \"block\", \"b\": \"slider\", \"level\": \"exact\", "
        "\"method\": \"obb\", \"convex_level\": false, \"front\": true, \"reason\": \"the polygon "
        "level on OBB trees"}) {
    EXPECT_NE(json.find(field), std::string::npos) << field << "\n" << json;
  }
  EXPECT_EQ(report.timings.size(), 12u);
  const std::string timed = report.to_json(true);
  EXPECT_NE(timed.find("\"timings\": {"), std::string::npos);
  EXPECT_EQ(timed.substr(0, json.size() - 3), json.substr(0, json.size() - 3));

  const fs::path dir = fs::temp_directory_path() / "dovetail_report_test";
  fs::create_directories(dir);
  report.write_json(dir / "report.json");
  report.write_timings_json(dir / "timings.json");
  std::ifstream in(dir / "report.json");
  const std::string written((std::istreambuf_iterator<char>(in)), {});
  EXPECT_EQ(written, json);
  EXPECT_TRUE(fs::file_size(dir / "timings.json") > 0);
  EXPECT_THROW(report.write_json(dir / "missing_folder" / "r.json"), std::runtime_error);
  fs::remove_all(dir);
}

TEST(Report, ProgressPrintsPlainLinesWhenNotATerminal) {
  std::FILE* out = std::tmpfile();
  ASSERT_NE(out, nullptr);
  ProgressMeter meter(10, out);
  for (std::uint64_t k = 1; k <= 10; ++k) meter.update(k);
  meter.finish();
  std::rewind(out);
  char line[128] = {};
  ASSERT_NE(std::fgets(line, sizeof(line), out), nullptr);
  EXPECT_EQ(std::string(line), "frame 10/10 done\n");
  std::fclose(out);
}

TEST(Report, ProgressDrawsABarOnATerminal) {
  const int master = posix_openpt(O_RDWR | O_NOCTTY);
  if (master < 0) GTEST_SKIP() << "no pseudo-terminal available";
  ASSERT_EQ(grantpt(master), 0);
  ASSERT_EQ(unlockpt(master), 0);
  const int slave = open(ptsname(master), O_RDWR | O_NOCTTY);
  ASSERT_GE(slave, 0);
  std::FILE* out = fdopen(slave, "w");
  ASSERT_NE(out, nullptr);
  {
    ProgressMeter meter(4, out);
    for (std::uint64_t k = 1; k <= 4; ++k) meter.update(k);
    meter.finish();
  }
  std::fclose(out);
  std::string text;
  char buffer[4096];
  for (;;) {
    const ssize_t n = read(master, buffer, sizeof(buffer));
    if (n <= 0) break;
    text.append(buffer, static_cast<std::size_t>(n));
    if (text.find('\n') != std::string::npos) break;
  }
  close(master);
  EXPECT_NE(text.find("\r["), std::string::npos) << text;
  EXPECT_NE(text.find("100% frame 4/4"), std::string::npos) << text;
}

}  // namespace
}  // namespace dovetail::engine
