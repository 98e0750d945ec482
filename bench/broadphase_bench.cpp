// Object-level benchmark: every Dovetail broad phase, Bullet's
// btDbvtBroadphase and btAxisSweep3 and FCL's DynamicAABBTreeCollisionManager
// (and its array variant) on the same box trajectories, in one run.
//
//   broadphase_bench [--scene sparse|crowded] [--objects N] [--frames F] [--runs R]
//                    [--seed S] [--size E] [--speed V] [--no-brute] [--methods LIST]
//                    [--no-peers] [--write-scene FILE]
//
// --methods sap,grid,... runs only those of Dovetail's broad phases; --no-peers
// leaves out Bullet and FCL (for profiling one method).
// Scenes: `sparse` (the default), N boxes in a cube of edge 100, moving
// coherently (random velocities, bouncing off the walls), each box's edges
// breathing by up to +-25% over time as the box of a rotating part does.
// `crowded`, the same N boxes packed into clusters of 27 (3 x 3 x 3, spaced a
// little closer than their edges, as the parts of an assembly touch several
// neighbours), each cluster moving as one, its boxes wobbling about their
// places and breathing; about four overlapping pairs per box. Prints the actual overlap (objects in
// at least one pair, pairs per frame), then per contender the median over runs of the median time
// per frame (frames after the first), the ratio to the best peer's, whether its pair sets equal
// brute force's on every frame, and its work counters per frame (box tests, endpoint swaps, cells
// or nodes touched). Bullet works in float and keeps pairs whose fattened boxes overlap: it is fed
// boxes rounded outwards, and its pairs are filtered by the exact box test before the comparison;
// any exact pair it misses is reported. FCL is given the very double boxes (its objects' world
// boxes are set directly); its pairs go through the same filter.

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bench_util.h"
#include "dovetail/collision/broadphase.h"

#ifdef DOVETAIL_HAVE_BULLET
#include <BulletCollision/BroadphaseCollision/btAxisSweep3.h>
#include <BulletCollision/BroadphaseCollision/btDbvtBroadphase.h>
#include <BulletCollision/CollisionDispatch/btCollisionDispatcher.h>
#include <BulletCollision/CollisionDispatch/btDefaultCollisionConfiguration.h>
#endif

#ifdef DOVETAIL_HAVE_FCL
#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/broadphase/broadphase_dynamic_AABB_tree_array.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/narrowphase/collision_object.h>
#endif

namespace {

using dovetail::bench::median;

using namespace dovetail::collision;
using Clock = std::chrono::steady_clock;
using Frames = std::vector<std::vector<Aabb>>;
using PairLists = std::vector<std::vector<ProxyPair>>;

constexpr double kWorld = 100;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

/// splitmix64: the same scene on every platform.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(seed) {}
  double uniform(double lo, double hi) {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return lo + (hi - lo) * (static_cast<double>(z >> 11) * 0x1.0p-53);
  }

 private:
  std::uint64_t state_;
};

struct Options {
  bool crowded = false;
  int objects = 10000;
  int frames = 100;
  int runs = 5;
  std::uint64_t seed = 1;
  double size = 0.7;    ///< mean box edge
  double speed = 0.05;  ///< mean distance per frame
  bool brute = true;
  bool peers = true;
  std::vector<BroadphaseMethod> methods;  ///< Dovetail's contenders; empty = all
  std::string write_scene;
};

/// A random direction times a speed 0.5 to 1.5 times `mean`.
std::array<double, 3> random_velocity(Rng& rng, double mean) {
  double d[3], norm = 0;
  do {
    norm = 0;
    for (double& x : d) {
      x = rng.uniform(-1, 1);
      norm += x * x;
    }
  } while (norm > 1 || norm < 1e-6);
  const double speed = mean * rng.uniform(0.5, 1.5) / std::sqrt(norm);
  return {d[0] * speed, d[1] * speed, d[2] * speed};
}

/// One axis of a move, bouncing off the walls of the world.
void move_bouncing(double& c, double& v) {
  c += v;
  if (c < 0 || c > kWorld) {
    v = -v;
    c = std::clamp(c, 0.0, kWorld);
  }
}

/// The trajectories of every box, all frames.
Frames make_scene(const Options& o) {
  Rng rng(o.seed);
  struct Mover {
    double c[3], v[3], half[3], phase[3], rate;
  };
  std::vector<Mover> movers(static_cast<std::size_t>(o.objects));
  for (Mover& m : movers) {
    const double edge = o.size * rng.uniform(0.5, 1.5);
    const std::array<double, 3> v = random_velocity(rng, o.speed);
    for (int k = 0; k < 3; ++k) {
      m.c[k] = rng.uniform(0, kWorld);
      m.v[k] = v[k];
      m.half[k] = edge / 2 * rng.uniform(0.8, 1.2);
      m.phase[k] = rng.uniform(0, 6.283185307179586);
    }
    m.rate = rng.uniform(0.01, 0.05);
  }
  Frames frames(static_cast<std::size_t>(o.frames));
  for (int f = 0; f < o.frames; ++f) {
    std::vector<Aabb>& boxes = frames[static_cast<std::size_t>(f)];
    boxes.resize(movers.size());
    for (std::size_t i = 0; i < movers.size(); ++i) {
      Mover& m = movers[i];
      for (int k = 0; k < 3; ++k) {
        const double half = m.half[k] * (1 + 0.25 * std::sin(m.rate * f + m.phase[k]));
        boxes[i].min[k] = m.c[k] - half;
        boxes[i].max[k] = m.c[k] + half;
        move_bouncing(m.c[k], m.v[k]);
      }
    }
  }
  return frames;
}

/// The crowded scene: clusters of 3 x 3 x 3 boxes spaced 0.9 of the mean
/// edge apart, each cluster moving as one (random velocity, bouncing off the
/// walls), each box wobbling by up to 5% of the edge about its place and its
/// edges breathing by up to +-10%.
Frames make_crowded_scene(const Options& o) {
  Rng rng(o.seed);
  struct Cluster {
    double c[3], v[3];
  };
  struct Member {
    std::size_t cluster;
    double offset[3], half[3], phase[3], rate;
  };
  const std::size_t clusters = (static_cast<std::size_t>(o.objects) + 26) / 27;
  std::vector<Cluster> cs(clusters);
  for (Cluster& c : cs) {
    const std::array<double, 3> v = random_velocity(rng, o.speed);
    for (int k = 0; k < 3; ++k) {
      c.c[k] = rng.uniform(0, kWorld);
      c.v[k] = v[k];
    }
  }
  const double spacing = 0.9 * o.size;
  std::vector<Member> members(static_cast<std::size_t>(o.objects));
  for (std::size_t i = 0; i < members.size(); ++i) {
    Member& m = members[i];
    m.cluster = i / 27;
    const int slot[3] = {static_cast<int>(i % 3), static_cast<int>(i / 3 % 3),
                         static_cast<int>(i / 9 % 3)};
    for (int k = 0; k < 3; ++k) {
      m.offset[k] = (slot[k] - 1) * spacing;
      m.half[k] = o.size / 2 * rng.uniform(0.8, 1.2);
      m.phase[k] = rng.uniform(0, 6.283185307179586);
    }
    m.rate = rng.uniform(0.02, 0.1);
  }
  Frames frames(static_cast<std::size_t>(o.frames));
  for (int f = 0; f < o.frames; ++f) {
    std::vector<Aabb>& boxes = frames[static_cast<std::size_t>(f)];
    boxes.resize(members.size());
    for (std::size_t i = 0; i < members.size(); ++i) {
      const Member& m = members[i];
      const Cluster& c = cs[m.cluster];
      for (int k = 0; k < 3; ++k) {
        const double wave = std::sin(m.rate * f + m.phase[k]);
        const double centre = c.c[k] + m.offset[k] + 0.05 * o.size * wave;
        const double half = m.half[k] * (1 + 0.1 * std::cos(m.rate * f + m.phase[k]));
        boxes[i].min[k] = centre - half;
        boxes[i].max[k] = centre + half;
      }
    }
    for (Cluster& c : cs) {
      for (int k = 0; k < 3; ++k) move_bouncing(c.c[k], c.v[k]);
    }
  }
  return frames;
}

/// The scene in the `dovetail broadphase --boxes` format.
bool write_scene(const Frames& frames, const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return false;
  std::fprintf(f, "%zu %zu\n", frames.empty() ? std::size_t{0} : frames[0].size(), frames.size());
  for (const std::vector<Aabb>& boxes : frames) {
    for (const Aabb& b : boxes) {
      std::fprintf(f, "%.17g %.17g %.17g %.17g %.17g %.17g\n", b.min.x(), b.min.y(), b.min.z(),
                   b.max.x(), b.max.y(), b.max.z());
    }
  }
  return std::fclose(f) == 0;
}

/// One contender's results over all runs.
struct Result {
  std::string name;
  bool peer = false;  ///< Bullet or FCL: timed against, filtered by the exact box test
  std::vector<double> run_medians;  ///< median ms per frame (after the first), per run
  std::size_t frames_differing = 0;
  std::size_t raw_pairs = 0;     ///< peers: pairs before the exact filter, all frames
  std::size_t missed_pairs = 0;  ///< exact pairs the contender did not report
  std::size_t extra_pairs = 0;   ///< pairs reported that are not exact pairs
  BroadphaseStats work;          ///< Dovetail: work counters, summed over frames after the first
};

/// Compares one frame's pairs with the reference.
void compare(const std::vector<ProxyPair>& got, const std::vector<ProxyPair>& reference,
             Result& r) {
  if (got == reference) return;
  ++r.frames_differing;
  std::vector<ProxyPair> diff;
  std::set_difference(reference.begin(), reference.end(), got.begin(), got.end(),
                      std::back_inserter(diff));
  r.missed_pairs += diff.size();
  diff.clear();
  std::set_difference(got.begin(), got.end(), reference.begin(), reference.end(),
                      std::back_inserter(diff));
  r.extra_pairs += diff.size();
}

/// Runs a Dovetail broad phase over all frames once: per-frame ms, and the pairs.
std::vector<double> run_dovetail(BroadphaseMethod method, const Frames& frames, PairLists* pairs,
                                 BroadphaseStats* work = nullptr) {
  std::unique_ptr<Broadphase> bp = make_broadphase(method);
  std::vector<double> ms;
  std::vector<ProxyPair> out;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const std::vector<Aabb>& boxes = frames[f];
    const Clock::time_point start = Clock::now();
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      if (f == 0) {
        bp->add(static_cast<ProxyId>(i), boxes[i]);
      } else {
        bp->move(static_cast<ProxyId>(i), boxes[i]);
      }
    }
    bp->pairs(out);
    ms.push_back(ms_since(start));
    if (pairs != nullptr) (*pairs)[f] = out;
    if (work != nullptr && f > 0) {
      const BroadphaseStats s = bp->stats();
      work->box_tests += s.box_tests;
      work->swaps += s.swaps;
      work->cells += s.cells;
    }
  }
  return ms;
}

#if defined(DOVETAIL_HAVE_BULLET) || defined(DOVETAIL_HAVE_FCL)
/// A peer's handle on box i (never null), and back.
void* client_of(std::size_t i) {
  return reinterpret_cast<void*>(static_cast<std::uintptr_t>(i + 1));
}
ProxyId index_of(const void* client) {
  return static_cast<ProxyId>(reinterpret_cast<std::uintptr_t>(client) - 1);
}

/// A peer's pairs (a < b), exact ones only, sorted: `out`.
void keep_exact(const std::vector<ProxyPair>& found, const std::vector<Aabb>& boxes,
                std::vector<ProxyPair>& out) {
  out.clear();
  for (const ProxyPair& p : found) {
    if (boxes[p.a].overlaps(boxes[p.b])) out.push_back(p);
  }
  std::sort(out.begin(), out.end());
}
#endif

/// A peer broad phase: runs over all frames once, returns per-frame ms, its
/// exact pairs per frame and the pairs it reported before the exact filter.
struct Peer {
  std::string name;
  std::function<std::vector<double>(const Frames&, PairLists&, std::size_t&)> run;
};

#ifdef DOVETAIL_HAVE_BULLET
/// Bullet's float box around a double box: rounded outwards, so it contains it.
void float_box(const Aabb& b, btVector3& lo, btVector3& hi) {
  float l[3], h[3];
  for (int k = 0; k < 3; ++k) {
    l[k] = static_cast<float>(b.min[k]);
    if (static_cast<double>(l[k]) > b.min[k]) l[k] = std::nextafter(l[k], -HUGE_VALF);
    h[k] = static_cast<float>(b.max[k]);
    if (static_cast<double>(h[k]) < b.max[k]) h[k] = std::nextafter(h[k], HUGE_VALF);
  }
  lo.setValue(l[0], l[1], l[2]);
  hi.setValue(h[0], h[1], h[2]);
}

/// Runs a Bullet broad phase over all frames once; the pairs it keeps are
/// filtered by the exact box test.
std::vector<double> run_bullet(const std::function<std::unique_ptr<btBroadphaseInterface>()>& make,
                               const Frames& frames, PairLists& pairs, std::size_t& raw_pairs) {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher(&configuration);
  std::unique_ptr<btBroadphaseInterface> bp = make();
  std::vector<btBroadphaseProxy*> proxies;
  std::vector<ProxyPair> found;
  std::vector<double> ms;
  raw_pairs = 0;
  btVector3 lo, hi;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const std::vector<Aabb>& boxes = frames[f];
    const Clock::time_point start = Clock::now();
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      float_box(boxes[i], lo, hi);
      if (f == 0) {
        // The client object carries the box index.
        void* client = client_of(i);
        proxies.push_back(bp->createProxy(lo, hi, 0, client, btBroadphaseProxy::DefaultFilter,
                                          btBroadphaseProxy::AllFilter, &dispatcher));
      } else {
        bp->setAabb(proxies[i], lo, hi, &dispatcher);
      }
    }
    bp->calculateOverlappingPairs(&dispatcher);
    ms.push_back(ms_since(start));
    // Bullet's pairs, by index, exact ones only.
    const btBroadphasePairArray& array = bp->getOverlappingPairCache()->getOverlappingPairArray();
    raw_pairs += static_cast<std::size_t>(array.size());
    found.clear();
    for (int p = 0; p < array.size(); ++p) {
      const ProxyId a = index_of(array[p].m_pProxy0->m_clientObject);
      const ProxyId b = index_of(array[p].m_pProxy1->m_clientObject);
      found.push_back(a < b ? ProxyPair{a, b} : ProxyPair{b, a});
    }
    keep_exact(found, boxes, pairs[f]);
  }
  for (btBroadphaseProxy* proxy : proxies) bp->destroyProxy(proxy, &dispatcher);
  return ms;
}
#endif

#ifdef DOVETAIL_HAVE_FCL
/// An FCL object whose world box is set directly, so that FCL's broad phase
/// sees exactly the boxes the others see (its own box of a shape would be
/// rounded differently).
class FclBox : public fcl::CollisionObjectd {
 public:
  explicit FclBox(const std::shared_ptr<fcl::CollisionGeometryd>& shape, std::size_t index)
      : fcl::CollisionObjectd(shape) {
    setUserData(client_of(index));
  }
  void set_box(const Aabb& b) {
    aabb = fcl::AABBd(fcl::Vector3d(b.min[0], b.min[1], b.min[2]),
                      fcl::Vector3d(b.max[0], b.max[1], b.max[2]));
  }
};

/// Runs an FCL broad-phase manager over all frames once; the pairs it reports
/// are filtered by the exact box test, as Bullet's.
std::vector<double> run_fcl(
    const std::function<std::unique_ptr<fcl::BroadPhaseCollisionManagerd>()>& make,
    const Frames& frames, PairLists& pairs, std::size_t& raw_pairs) {
  const auto shape = std::make_shared<fcl::Boxd>(1, 1, 1);
  std::unique_ptr<fcl::BroadPhaseCollisionManagerd> manager = make();
  std::vector<std::unique_ptr<FclBox>> objects;
  std::vector<ProxyPair> found;
  const auto collect = [](fcl::CollisionObjectd* a, fcl::CollisionObjectd* b, void* data) {
    auto* out = static_cast<std::vector<ProxyPair>*>(data);
    const ProxyId i = index_of(a->getUserData());
    const ProxyId j = index_of(b->getUserData());
    out->push_back(i < j ? ProxyPair{i, j} : ProxyPair{j, i});
    return false;  // go on: every pair
  };
  std::vector<double> ms;
  raw_pairs = 0;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const std::vector<Aabb>& boxes = frames[f];
    found.clear();
    const Clock::time_point start = Clock::now();
    if (f == 0) {
      std::vector<fcl::CollisionObjectd*> all;
      for (std::size_t i = 0; i < boxes.size(); ++i) {
        objects.push_back(std::make_unique<FclBox>(shape, i));
        objects.back()->set_box(boxes[i]);
        all.push_back(objects.back().get());
      }
      manager->registerObjects(all);
      manager->setup();
    } else {
      for (std::size_t i = 0; i < boxes.size(); ++i) objects[i]->set_box(boxes[i]);
      manager->update();
    }
    manager->collide(&found, collect);
    ms.push_back(ms_since(start));
    raw_pairs += found.size();
    keep_exact(found, boxes, pairs[f]);
  }
  return ms;
}
#endif

double frame_median(const std::vector<double>& ms) {
  return median(std::vector<double>(ms.begin() + (ms.size() > 1 ? 1 : 0), ms.end()));
}

[[noreturn]] void usage(const char* message) {
  std::fprintf(
      stderr,
      "broadphase_bench: %s\nusage: broadphase_bench [--scene sparse|crowded] [--objects N] "
      "[--frames F] "
      "[--runs R] [--seed S] [--size E] [--speed V] [--no-brute] [--methods LIST] [--no-peers] "
      "[--write-scene FILE]\n",
      message);
  std::exit(2);
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--no-brute") {
      o.brute = false;
      continue;
    }
    if (arg == "--no-peers") {
      o.peers = false;
      continue;
    }
    if (i + 1 >= argc) usage(("missing value for " + arg).c_str());
    const char* value = argv[++i];
    if (arg == "--scene") {
      const std::string name = value;
      if (name != "sparse" && name != "crowded") usage("--scene is sparse or crowded");
      o.crowded = name == "crowded";
    } else if (arg == "--objects") {
      o.objects = static_cast<int>(
          dovetail::bench::whole("broadphase_bench", "--objects", value, 2, 10000000));
    } else if (arg == "--frames") {
      o.frames = static_cast<int>(
          dovetail::bench::whole("broadphase_bench", "--frames", value, 1, 1000000));
    } else if (arg == "--runs") {
      o.runs =
          static_cast<int>(dovetail::bench::whole("broadphase_bench", "--runs", value, 1, 1000));
    } else if (arg == "--seed") {
      o.seed = static_cast<std::uint64_t>(
          dovetail::bench::whole("broadphase_bench", "--seed", value, 0, 1LL << 62));
    } else if (arg == "--size") {
      o.size = dovetail::bench::real("broadphase_bench", "--size", value, 0);
    } else if (arg == "--speed") {
      o.speed = dovetail::bench::real("broadphase_bench", "--speed", value, 0);
    } else if (arg == "--methods") {
      o.methods.clear();
      for (const std::string& name : dovetail::bench::comma_list(value)) {
        const std::optional<BroadphaseMethod> m = parse_broadphase(name);
        if (!m || *m == BroadphaseMethod::kBrute) {
          usage(("unknown method '" + name + "' in --methods (sap, grid, octree, mbp)").c_str());
        }
        o.methods.push_back(*m);
      }
    } else if (arg == "--write-scene") {
      o.write_scene = value;
    } else {
      usage(("unknown option " + arg).c_str());
    }
  }
  if (o.objects < 2 || o.frames < 2 || o.runs < 1 || !(o.size > 0)) usage("bad value");
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  const Frames frames = o.crowded ? make_crowded_scene(o) : make_scene(o);
  if (!o.write_scene.empty()) {
    if (!write_scene(frames, o.write_scene)) {
      std::fprintf(stderr, "broadphase_bench: cannot write %s\n", o.write_scene.c_str());
      return 1;
    }
    std::printf("wrote %s: %d boxes, %d frames\n", o.write_scene.c_str(), o.objects, o.frames);
    return 0;
  }

  // The reference: brute force once (or, with --no-brute, sweep and prune).
  const std::size_t nf = frames.size();
  PairLists reference(nf);
  std::vector<Result> results;
  const BroadphaseMethod reference_method =
      o.brute ? BroadphaseMethod::kBrute : BroadphaseMethod::kSweepAndPrune;
  {
    Result r;
    r.name = std::string(broadphase_name(reference_method)) + (o.brute ? "" : " (reference)");
    r.run_medians.push_back(
        frame_median(run_dovetail(reference_method, frames, &reference, &r.work)));
    results.push_back(r);
  }

  // The scene's actual overlap.
  double pairs_per_frame = 0, overlapping_fraction = 0;
  std::vector<char> touched(static_cast<std::size_t>(o.objects));
  for (const std::vector<ProxyPair>& list : reference) {
    std::fill(touched.begin(), touched.end(), 0);
    for (const ProxyPair& p : list) touched[p.a] = touched[p.b] = 1;
    pairs_per_frame += static_cast<double>(list.size()) / static_cast<double>(nf);
    overlapping_fraction += static_cast<double>(std::count(touched.begin(), touched.end(), 1)) /
                            o.objects / static_cast<double>(nf);
  }

  // Everything else, interleaved run by run.
  std::vector<BroadphaseMethod> methods;
  for (BroadphaseMethod m : all_broadphases()) {
    const bool chosen =
        o.methods.empty() || std::find(o.methods.begin(), o.methods.end(), m) != o.methods.end();
    if (m != BroadphaseMethod::kBrute && chosen) methods.push_back(m);
  }
  const std::size_t first = results.size();
  for (BroadphaseMethod m : methods) {
    Result r;
    r.name = broadphase_name(m);
    results.push_back(r);
  }
  std::vector<Peer> peers;
#ifdef DOVETAIL_HAVE_BULLET
  const btVector3 world_lo(-10, -10, -10), world_hi(kWorld + 10, kWorld + 10, kWorld + 10);
  const auto bullet = [&](std::string name,
                          std::function<std::unique_ptr<btBroadphaseInterface>()> make) {
    peers.push_back({std::move(name), [make](const Frames& f, PairLists& p, std::size_t& raw) {
                       return run_bullet(make, f, p, raw);
                     }});
  };
  bullet("bullet btDbvtBroadphase", [] { return std::make_unique<btDbvtBroadphase>(); });
  bullet("bullet btAxisSweep3", [&] {
    // 16-bit quantised endpoints; the ray-cast accelerator (a second
    // tree updated on every move) is switched off: only pairs are timed.
    return std::make_unique<btAxisSweep3>(world_lo, world_hi, static_cast<unsigned short>(16384),
                                          nullptr, true);
  });
  bullet("bullet bt32BitAxisSweep3", [&] {
    return std::make_unique<bt32BitAxisSweep3>(world_lo, world_hi, 16384u, nullptr, true);
  });
#endif
#ifdef DOVETAIL_HAVE_FCL
  const auto fcl_peer =
      [&](std::string name,
          std::function<std::unique_ptr<fcl::BroadPhaseCollisionManagerd>()> make) {
        peers.push_back({std::move(name), [make](const Frames& f, PairLists& p, std::size_t& raw) {
                           return run_fcl(make, f, p, raw);
                         }});
      };
  fcl_peer("fcl DynamicAABBTree",
           [] { return std::make_unique<fcl::DynamicAABBTreeCollisionManagerd>(); });
  fcl_peer("fcl DynamicAABBTree_Array",
           [] { return std::make_unique<fcl::DynamicAABBTreeCollisionManager_Arrayd>(); });
#endif
  if (!o.peers) peers.clear();
  for (const Peer& peer : peers) {
    Result r;
    r.name = peer.name;
    r.peer = true;
    results.push_back(r);
  }
  PairLists got(nf);
  for (int run = 0; run < o.runs; ++run) {
    std::size_t index = first;
    for (BroadphaseMethod m : methods) {
      Result& r = results[index++];
      r.run_medians.push_back(frame_median(
          run_dovetail(m, frames, run == 0 ? &got : nullptr, run == 0 ? &r.work : nullptr)));
      if (run == 0) {
        for (std::size_t f = 0; f < nf; ++f) compare(got[f], reference[f], r);
      }
    }
    for (const Peer& peer : peers) {
      Result& r = results[index++];
      std::size_t raw = 0;
      r.run_medians.push_back(frame_median(peer.run(frames, got, raw)));
      if (run == 0) {
        r.raw_pairs = raw;
        for (std::size_t f = 0; f < nf; ++f) compare(got[f], reference[f], r);
      }
    }
  }

  double peer_best = 0;
  for (const Result& r : results) {
    if (r.peer && (peer_best == 0 || median(r.run_medians) < peer_best)) {
      peer_best = median(r.run_medians);
    }
  }
  std::printf("scene: %s, %d boxes, %d frames, mean edge %.3g, speed %.3g per frame, seed %llu\n",
              o.crowded ? "crowded" : "sparse", o.objects, o.frames, o.size, o.speed,
              static_cast<unsigned long long>(o.seed));
  std::printf("overlap: %.2f%% of objects in at least one pair, %.1f pairs per frame\n",
              100 * overlapping_fraction, pairs_per_frame);
#ifdef DOVETAIL_HAVE_BULLET
  std::printf("bullet: btDbvtBroadphase margin %g, boxes rounded outwards to float\n",
              static_cast<double>(gDbvtMargin));
#endif
  std::printf("times: median over %d runs of the median ms per frame (frames 2..%d)\n\n", o.runs,
              o.frames);
  std::printf("| %-26s | %10s | %12s | %-34s | %30s |\n", "broad phase", "ms/frame", "vs best peer",
              "pairs vs brute force, all frames", "box tests / swaps / cells");
  std::printf("|%s|%s|%s|%s|%s|\n", std::string(28, '-').c_str(), std::string(12, '-').c_str(),
              std::string(14, '-').c_str(), std::string(36, '-').c_str(),
              std::string(32, '-').c_str());
  for (const Result& r : results) {
    const double ms = median(r.run_medians);
    char ratio[32] = "-";
    if (peer_best > 0) std::snprintf(ratio, sizeof ratio, "%.3fx", ms / peer_best);
    std::string verdict;
    if (r.name.rfind(std::string(broadphase_name(reference_method)), 0) == 0 &&
        &r == &results.front()) {
      verdict = "reference";
    } else if (r.frames_differing == 0) {
      verdict = "identical";
    } else {
      verdict = std::to_string(r.frames_differing) +
                " frames differ: " + std::to_string(r.missed_pairs) + " missed, " +
                std::to_string(r.extra_pairs) + " extra";
    }
    if (r.peer) {
      verdict += " (raw " + std::to_string(r.raw_pairs / nf) + "/frame)";
    }
    char work[64] = "-";
    if (!r.peer) {
      const double per = static_cast<double>(nf > 1 ? nf - 1 : 1);
      std::snprintf(
          work, sizeof work, "%.0f / %.0f / %.0f", static_cast<double>(r.work.box_tests) / per,
          static_cast<double>(r.work.swaps) / per, static_cast<double>(r.work.cells) / per);
    }
    std::printf("| %-26s | %10.3f | %12s | %-34s | %30s |\n", r.name.c_str(), ms, ratio,
                verdict.c_str(), work);
  }
  return 0;
}
