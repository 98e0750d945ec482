// Every broad phase must report exactly the pairs the exhaustive reference
// reports, frame by frame, while boxes move, grow, shrink, appear and vanish.

#include "dovetail/collision/broadphase.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "broadphase/multi_box_pruning.h"
#include "broadphase/octree.h"
#include "broadphase/proxy_pairs.h"
#include "broadphase/uniform_grid.h"

namespace dovetail::collision {
namespace {

/// splitmix64: the same numbers on every platform.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  /// Uniform in [0, 1).
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  std::uint32_t below(std::uint32_t n) { return static_cast<std::uint32_t>(next() % n); }

 private:
  std::uint64_t state_;
};

/// What kind of box an object is.
enum class Kind {
  kMoving,      ///< ordinary box, bouncing, changing size
  kPoint,       ///< zero size
  kFlat,        ///< zero thickness on one axis
  kTouching,    ///< shares a face plane with another object's box, exactly
  kCoincident,  ///< the very same box as another object
  kHuge,        ///< spans a large part of the scene
  kOutlier,     ///< far away from everything
};

struct SceneSpec {
  std::string name;
  int objects = 100;
  int frames = 200;
  bool clustered = false;
  bool snapped = false;  ///< coordinates rounded to 1/8: many exact ties
  double churn = 0.05;   ///< chance per frame of adding and removing objects
  std::uint64_t seed = 1;
  int burst_frame = -1;  ///< at this frame, half of the objects appear or vanish at once
  double drift = 0;      ///< every box also moves by this per frame along (1, 0.5, 0.25)
  double growth = 1;     ///< every box's size is multiplied by this per frame
};

/// One object's motion: a box centre bouncing in the scene cube, half extents
/// breathing per axis (as the box of a rotating part does).
struct Mover {
  Kind kind = Kind::kMoving;
  Vec3 center = Vec3::Zero();
  Vec3 velocity = Vec3::Zero();
  Vec3 half = Vec3::Zero();
  Vec3 phase = Vec3::Zero();
  double rate = 0;
  int axis = 0;             ///< flat axis, or the touching axis
  std::uint32_t other = 0;  ///< the object touched or coincided with
};

class Scene {
 public:
  explicit Scene(const SceneSpec& spec) : spec_(spec), rng_(spec.seed) {
    world_ = 10 * std::cbrt(static_cast<double>(spec.objects));
    for (int c = 0; c < 6; ++c) {
      clusters_.push_back(
          Vec3(rng_.uniform(0, world_), rng_.uniform(0, world_), rng_.uniform(0, world_)));
    }
    for (int i = 0; i < spec.objects; ++i) {
      movers_.push_back(make_mover(static_cast<std::uint32_t>(i)));
      present_.push_back(1);
    }
  }

  /// Advances one frame: moves everything, removes and adds a few objects.
  void step() {
    ++frame_;
    for (Mover& m : movers_) advance(m);
    if (frame_ == spec_.burst_frame) {
      // Half of the objects vanish (or come back), and as many new ones arrive.
      const std::size_t n = movers_.size();
      for (std::size_t id = 0; id < n; ++id) {
        if (rng_.uniform() < 0.5) continue;
        present_[id] = present_[id] != 0 ? 0 : 1;
        if (present_[id] != 0) movers_[id] = make_mover(static_cast<std::uint32_t>(id));
      }
      for (std::size_t i = 0; i < n / 2; ++i) {
        movers_.push_back(make_mover(static_cast<std::uint32_t>(movers_.size())));
        present_.push_back(1);
      }
    }
    if (rng_.uniform() < spec_.churn) {
      const int changes = 1 + static_cast<int>(rng_.below(1 + movers_.size() / 50));
      for (int c = 0; c < changes; ++c) {
        const std::uint32_t id = rng_.below(static_cast<std::uint32_t>(movers_.size()));
        present_[id] = present_[id] != 0 ? 0 : 1;
        if (present_[id] != 0) movers_[id] = make_mover(id);
      }
      // Sometimes a fresh id beyond the current ones.
      if (rng_.uniform() < 0.3) {
        movers_.push_back(make_mover(static_cast<std::uint32_t>(movers_.size())));
        present_.push_back(1);
      }
    }
  }

  std::size_t size() const { return movers_.size(); }
  bool present(std::size_t id) const { return present_[id] != 0; }
  int frame() const { return frame_; }

  /// The box of object `id` now.
  Aabb box(std::uint32_t id) const { return box_of(id, 0); }

 private:
  Mover make_mover(std::uint32_t id) {
    Mover m;
    const double u = rng_.uniform();
    if (id > 0 && u < 0.05) {
      m.kind = Kind::kTouching;
    } else if (id > 0 && u < 0.08) {
      m.kind = Kind::kCoincident;
    } else if (u < 0.11) {
      m.kind = Kind::kPoint;
    } else if (u < 0.14) {
      m.kind = Kind::kFlat;
    } else if (u < 0.145) {
      m.kind = Kind::kHuge;
    } else if (u < 0.15) {
      m.kind = Kind::kOutlier;
    }
    m.other = id > 0 ? rng_.below(id) : 0;
    m.axis = static_cast<int>(rng_.below(3));
    const Vec3 around = spec_.clustered ? clusters_[rng_.below(6)] : Vec3::Constant(world_ / 2);
    const double spread = spec_.clustered ? world_ / 12 : world_ / 2;
    for (int k = 0; k < 3; ++k) {
      m.center[k] = std::clamp(around[k] + rng_.uniform(-spread, spread), 0.0, world_);
      m.velocity[k] = rng_.uniform(-0.3, 0.3);
      m.phase[k] = rng_.uniform(0, 6.283);
    }
    // Mixed sizes: mostly around 1, some 3 to 8 times larger.
    const double size = rng_.uniform() < 0.1 ? rng_.uniform(3, 8) : rng_.uniform(0.3, 1.5);
    m.half =
        Vec3(size * rng_.uniform(0.3, 1), size * rng_.uniform(0.3, 1), size * rng_.uniform(0.3, 1));
    m.rate = rng_.uniform(0.02, 0.2);
    if (m.kind == Kind::kHuge) m.half = Vec3::Constant(world_ / 4);
    if (m.kind == Kind::kOutlier) {
      const double far = rng_.uniform() < 0.5 ? 1e6 : -1e12;
      m.center = Vec3(far, rng_.uniform(-far, far), far * 0.5);
      m.velocity *= 1e-3;
    }
    return m;
  }

  void advance(Mover& m) const {
    m.center += m.velocity;
    m.half *= spec_.growth;
    if (m.kind == Kind::kOutlier) return;
    for (int k = 0; k < 3; ++k) {
      if (m.center[k] < 0 || m.center[k] > world_) {
        m.velocity[k] = -m.velocity[k];
        m.center[k] = std::clamp(m.center[k], 0.0, world_);
      }
    }
  }

  Aabb box_of(std::uint32_t id, int depth) const {
    const Mover& m = movers_[id];
    // Derived boxes follow another object (chains are cut after a few links).
    if ((m.kind == Kind::kTouching || m.kind == Kind::kCoincident) && depth < 4) {
      Aabb b = box_of(m.other, depth + 1);
      if (m.kind == Kind::kTouching) {
        const double width = b.max[m.axis] - b.min[m.axis];
        b.min[m.axis] = b.max[m.axis];
        b.max[m.axis] = b.max[m.axis] + width + 0.25;
        // Offset on another axis, still overlapping there.
        const int k = (m.axis + 1) % 3;
        b.min[k] += (b.max[k] - b.min[k]) / 2;
        b.max[k] += (b.max[k] - b.min[k]) / 2;
      }
      return b;
    }
    Vec3 half = m.half;
    for (int k = 0; k < 3; ++k) half[k] *= 1 + 0.4 * std::sin(m.rate * frame_ + m.phase[k]);
    if (m.kind == Kind::kPoint) half.setZero();
    if (m.kind == Kind::kFlat) half[m.axis] = 0;
    const Vec3 drift = spec_.drift * frame_ * Vec3(1, 0.5, 0.25);
    Aabb b{m.center + drift - half, m.center + drift + half};
    if (spec_.snapped) {
      for (int k = 0; k < 3; ++k) {
        b.min[k] = std::floor(b.min[k] * 8) / 8;
        b.max[k] = std::ceil(b.max[k] * 8) / 8;
      }
    }
    return b;
  }

  SceneSpec spec_;
  Rng rng_;
  double world_ = 0;
  std::vector<Vec3> clusters_;
  std::vector<Mover> movers_;
  std::vector<char> present_;
  int frame_ = 0;
};

struct Contender {
  std::string name;
  std::unique_ptr<Broadphase> broadphase;
};

/// The methods with their default settings, plus (`extremes`) settings at the
/// extremes, which are slow on large scenes.
std::vector<Contender> contenders(bool extremes) {
  std::vector<Contender> list;
  for (BroadphaseMethod m : all_broadphases()) {
    if (m == BroadphaseMethod::kBrute) continue;
    list.push_back({std::string(broadphase_name(m)), make_broadphase(m)});
  }
  if (!extremes) return list;
  BroadphaseSettings tiny_cells;
  tiny_cells.grid_cell = 0.25;  // many cells per box, the larger boxes too big for the grid
  list.push_back({"grid cell 0.25", make_broadphase(BroadphaseMethod::kGrid, tiny_cells)});
  BroadphaseSettings huge_cells;
  huge_cells.grid_cell = 1000;
  list.push_back({"grid cell 1000", make_broadphase(BroadphaseMethod::kGrid, huge_cells)});
  BroadphaseSettings deep;
  deep.octree_leaf_size = 1;
  deep.octree_max_depth = 20;
  list.push_back({"octree leaf 1", make_broadphase(BroadphaseMethod::kOctree, deep)});
  BroadphaseSettings shallow;
  shallow.octree_leaf_size = 2;
  shallow.octree_max_depth = 2;
  list.push_back({"octree depth 2", make_broadphase(BroadphaseMethod::kOctree, shallow)});
  BroadphaseSettings narrow;
  narrow.mbp_column = 0.25;  // boxes in many columns, the larger ones tested against all
  list.push_back({"mbp column 0.25", make_broadphase(BroadphaseMethod::kMultiBoxPruning, narrow)});
  BroadphaseSettings wide;
  wide.mbp_column = 1000;  // one column: a single sweep
  list.push_back({"mbp column 1000", make_broadphase(BroadphaseMethod::kMultiBoxPruning, wide)});
  return list;
}

std::string show(const std::vector<ProxyPair>& pairs, std::size_t limit = 8) {
  std::string s;
  for (std::size_t i = 0; i < pairs.size() && i < limit; ++i) {
    s += " (" + std::to_string(pairs[i].a) + "," + std::to_string(pairs[i].b) + ")";
  }
  if (pairs.size() > limit) s += " ...";
  return s;
}

/// Runs the scene through brute force and every contender, comparing each frame.
void expect_agreement(const SceneSpec& spec) {
  Scene scene(spec);
  std::unique_ptr<Broadphase> brute = make_broadphase(BroadphaseMethod::kBrute);
  std::vector<Contender> list = contenders(spec.objects <= 1000);
  std::vector<char> inside;  // which ids the broad phases hold
  std::vector<ProxyPair> reference, got;
  std::uint64_t pairs_total = 0, touching_frames = 0;
  int disagreements = 0;
  for (int f = 0; f < spec.frames; ++f) {
    if (f > 0) scene.step();
    inside.resize(scene.size(), 0);
    // The same updates, in the same order, to every broad phase.
    for (std::uint32_t id = 0; id < scene.size(); ++id) {
      const bool now = scene.present(id);
      if (!now && inside[id] == 0) continue;
      const Aabb box = scene.box(id);
      for (std::size_t c = 0; c <= list.size(); ++c) {
        Broadphase& bp = c == list.size() ? *brute : *list[c].broadphase;
        if (now && inside[id] == 0) {
          bp.add(id, box);
        } else if (!now) {
          bp.remove(id);
        } else {
          bp.move(id, box);
        }
      }
      inside[id] = now ? 1 : 0;
    }
    brute->pairs(reference);
    pairs_total += reference.size();
    // Count frames with an exactly touching pair (the hard case for ties).
    bool touching = false;
    for (const ProxyPair& p : reference) {
      const Aabb a = scene.box(p.a), b = scene.box(p.b);
      for (int k = 0; k < 3 && !touching; ++k)
        touching = a.max[k] == b.min[k] || b.max[k] == a.min[k];
    }
    touching_frames += touching ? 1 : 0;
    for (Contender& c : list) {
      c.broadphase->pairs(got);
      ASSERT_EQ(c.broadphase->size(), brute->size());
      if (got != reference && ++disagreements <= 5) {
        std::vector<ProxyPair> missing, extra;
        std::set_difference(reference.begin(), reference.end(), got.begin(), got.end(),
                            std::back_inserter(missing));
        std::set_difference(got.begin(), got.end(), reference.begin(), reference.end(),
                            std::back_inserter(extra));
        ADD_FAILURE() << spec.name << " frame " << f << " " << c.name << ": missing"
                      << show(missing) << ", extra" << show(extra);
      }
    }
  }
  EXPECT_EQ(disagreements, 0) << spec.name;
  EXPECT_GT(pairs_total, 0u) << spec.name;
  std::printf(
      "[ agreement ] %s: %zu objects, %d frames, %llu pairs (%llu frames with touching pairs) x "
      "%zu broad phases, %d disagreements\n",
      spec.name.c_str(), scene.size(), spec.frames, static_cast<unsigned long long>(pairs_total),
      static_cast<unsigned long long>(touching_frames), list.size(), disagreements);
}

TEST(Broadphase, NamesRoundTrip) {
  ASSERT_EQ(all_broadphases().size(), 5u);
  for (BroadphaseMethod m : all_broadphases()) {
    EXPECT_EQ(parse_broadphase(broadphase_name(m)), m);
  }
  EXPECT_EQ(broadphase_name(BroadphaseMethod::kSweepAndPrune), "sap");
  EXPECT_FALSE(parse_broadphase("boxtree").has_value());
}

TEST(Broadphase, EmptyAndSingle) {
  for (BroadphaseMethod m : all_broadphases()) {
    std::unique_ptr<Broadphase> bp = make_broadphase(m);
    std::vector<ProxyPair> out{{1, 2}};
    bp->pairs(out);
    EXPECT_TRUE(out.empty()) << broadphase_name(m);
    bp->add(7, Aabb{Vec3(0, 0, 0), Vec3(1, 1, 1)});
    bp->pairs(out);
    EXPECT_TRUE(out.empty()) << broadphase_name(m);
    bp->add(3, Aabb{Vec3(1, 1, 1), Vec3(2, 2, 2)});  // touches 7 at a corner
    bp->pairs(out);
    EXPECT_EQ(out, (std::vector<ProxyPair>{{3, 7}})) << broadphase_name(m);
    bp->move(3, Aabb{Vec3(1, 1, std::nextafter(1.0, 2.0)), Vec3(2, 2, 2)});
    bp->pairs(out);
    EXPECT_TRUE(out.empty()) << broadphase_name(m);
    bp->remove(7);
    bp->remove(3);
    EXPECT_EQ(bp->size(), 0u);
    bp->pairs(out);
    EXPECT_TRUE(out.empty()) << broadphase_name(m);
    // Ids come back, with new boxes.
    bp->add(3, Aabb{Vec3(5, 5, 5), Vec3(5, 5, 5)});
    bp->add(7, Aabb{Vec3(5, 5, 5), Vec3(5, 5, 5)});
    bp->pairs(out);
    EXPECT_EQ(out, (std::vector<ProxyPair>{{3, 7}})) << broadphase_name(m);
  }
}

TEST(Broadphase, RemoveAndAddBetweenQueries) {
  // Removing and re-adding an id before the next pairs() must not keep stale state.
  for (BroadphaseMethod m : all_broadphases()) {
    std::unique_ptr<Broadphase> bp = make_broadphase(m);
    std::vector<ProxyPair> out;
    for (ProxyId id = 0; id < 20; ++id) {
      bp->add(id, Aabb{Vec3(id, 0, 0), Vec3(id + 1.0, 1, 1)});
    }
    bp->pairs(out);
    EXPECT_EQ(out.size(), 19u) << broadphase_name(m);
    bp->remove(5);
    bp->add(5, Aabb{Vec3(100, 0, 0), Vec3(101, 1, 1)});
    bp->add(20, Aabb{Vec3(100.5, 0.5, 0.5), Vec3(100.5, 0.5, 0.5)});
    bp->remove(20);
    bp->add(21, Aabb{Vec3(101, 1, 1), Vec3(102, 2, 2)});
    bp->pairs(out);
    std::vector<ProxyPair> expected;
    for (ProxyId id = 0; id + 1 < 20; ++id) {
      if (id != 4 && id != 5) expected.push_back({id, id + 1});
    }
    expected.push_back({5, 21});
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(out, expected) << broadphase_name(m);
  }
}

TEST(Broadphase, Deterministic) {
  // The same update sequence gives the same pairs and the same work counters.
  for (BroadphaseMethod m : all_broadphases()) {
    std::vector<std::uint64_t> runs[2];
    for (auto& run : runs) {
      Scene scene(
          {.name = "det", .objects = 300, .frames = 0, .clustered = true, .churn = 0, .seed = 9});
      std::unique_ptr<Broadphase> bp = make_broadphase(m);
      std::vector<ProxyPair> out;
      for (std::uint32_t id = 0; id < scene.size(); ++id) bp->add(id, scene.box(id));
      for (int f = 0; f < 30; ++f) {
        bp->pairs(out);
        const BroadphaseStats s = bp->stats();
        run.insert(run.end(), {out.size(), s.box_tests, s.swaps, s.cells});
        for (const ProxyPair& p : out) run.push_back((std::uint64_t{p.a} << 32) | p.b);
        scene.step();
        for (std::uint32_t id = 0; id < scene.size(); ++id) bp->move(id, scene.box(id));
      }
    }
    EXPECT_EQ(runs[0], runs[1]) << broadphase_name(m);
  }
}

TEST(Broadphase, PairsOfTwoFixedBoxesAreLeftOut) {
  // Every method reports exactly the overlapping pairs of all boxes less
  // those of two fixed ones, while the marks change between frames (a mark
  // set before its box is added, on a box removed and added again, cleared).
  for (BroadphaseMethod m : all_broadphases()) {
    Scene scene({.name = "fixed", .objects = 200, .frames = 0, .clustered = true, .seed = 4});
    Rng rng(17);
    std::unique_ptr<Broadphase> bp = make_broadphase(m);
    std::vector<std::uint8_t> in(scene.size(), 0);
    std::vector<ProxyPair> out;
    std::size_t left_out = 0;
    for (int f = 0; f < 40; ++f) {
      for (int k = 0; k < 10; ++k) {
        const std::uint32_t id = rng.below(static_cast<std::uint32_t>(scene.size() + 5));
        bp->set_fixed(id, rng.uniform() < 0.7);
      }
      in.resize(scene.size(), 0);
      std::vector<ProxyPair> all;
      std::vector<std::uint32_t> present;
      for (std::uint32_t id = 0; id < scene.size(); ++id) {
        if (!scene.present(id)) {
          if (in[id]) bp->remove(id);
          in[id] = 0;
          continue;
        }
        if (in[id])
          bp->move(id, scene.box(id));
        else
          bp->add(id, scene.box(id));
        in[id] = 1;
        present.push_back(id);
      }
      for (std::size_t i = 0; i < present.size(); ++i) {
        for (std::size_t j = i + 1; j < present.size(); ++j) {
          if (scene.box(present[i]).overlaps(scene.box(present[j]))) {
            all.push_back({present[i], present[j]});
          }
        }
      }
      std::vector<ProxyPair> expected;
      for (const ProxyPair& p : all) {
        if (!(bp->fixed(p.a) && bp->fixed(p.b))) expected.push_back(p);
      }
      left_out += all.size() - expected.size();
      bp->pairs(out);
      ASSERT_EQ(out, expected) << broadphase_name(m) << " frame " << f;
      scene.step();
    }
    EXPECT_GT(left_out, 100u) << broadphase_name(m);  // the marks were exercised
  }
}

TEST(Broadphase, GridCellSize) {
  // Chosen from the boxes: twice the median size; re-chosen when sizes drift.
  UniformGrid grid;
  std::vector<ProxyPair> out;
  for (ProxyId id = 0; id < 10; ++id) {
    grid.add(id, Aabb{Vec3(3.0 * id, 0, 0), Vec3(3.0 * id + 1, 1, 1)});
  }
  grid.pairs(out);
  EXPECT_DOUBLE_EQ(grid.cell_size(), 2.0);
  for (ProxyId id = 0; id < 10; ++id) {
    grid.move(id, Aabb{Vec3(3.0 * id, 0, 0), Vec3(3.0 * id + 5, 5, 5)});
  }
  grid.pairs(out);
  EXPECT_DOUBLE_EQ(grid.cell_size(), 10.0);
  EXPECT_EQ(out.size(), 9u);
}

TEST(Broadphase, OctreeSplitsAndMerges) {
  Octree octree(2, 6);
  std::vector<ProxyPair> out;
  Rng rng(4);
  for (ProxyId id = 0; id < 200; ++id) {
    const Vec3 c(rng.uniform(0, 100), rng.uniform(0, 100), rng.uniform(0, 100));
    octree.add(id, Aabb{c, c + Vec3::Constant(0.5)});
  }
  octree.pairs(out);
  const std::size_t grown = octree.node_count();
  EXPECT_GT(grown, 64u);
  for (ProxyId id = 0; id < 199; ++id) octree.remove(id);
  octree.pairs(out);
  EXPECT_EQ(octree.node_count(), 1u);
  EXPECT_TRUE(out.empty());
}

TEST(Broadphase, MultiBoxPruningLayout) {
  // Boxes of extent 1 strung out along z: the sweep runs along z, the columns
  // are 8 median extents wide across it, and re-chosen when the boxes grow.
  MultiBoxPruning mbp;
  std::unique_ptr<Broadphase> brute = make_broadphase(BroadphaseMethod::kBrute);
  std::vector<ProxyPair> out, expected;
  const auto box = [](ProxyId id, Real extent) {
    const Vec3 c(id % 5, id % 7, 3.0 * id);
    return Aabb{c, c + Vec3::Constant(extent)};
  };
  for (ProxyId id = 0; id < 100; ++id) {
    mbp.add(id, box(id, 1));
    brute->add(id, box(id, 1));
  }
  mbp.pairs(out);
  brute->pairs(expected);
  EXPECT_EQ(mbp.sweep_axis(), 2);
  EXPECT_DOUBLE_EQ(mbp.column_size(), 8.0);
  EXPECT_EQ(out, expected);
  for (ProxyId id = 0; id < 100; ++id) {
    mbp.move(id, box(id, 4));
    brute->move(id, box(id, 4));
  }
  mbp.pairs(out);
  brute->pairs(expected);
  EXPECT_DOUBLE_EQ(mbp.column_size(), 32.0);
  EXPECT_EQ(out, expected);
  // Each box overlaps the next along z unless their y offsets wrap (6 -> 0).
  EXPECT_EQ(out.size(), 85u);
}

TEST(Broadphase, MultiBoxPruningAtTheEndsOfTheDoubles) {
  // Centres and spreads that overflow, boxes at +-1e307 and 1e308: no hang,
  // no undefined arithmetic, and brute force's pairs.
  const std::vector<Aabb> boxes = {
      {Vec3(-1e307, 0, 0), Vec3(-1e307, 1, 1)}, {Vec3(-1e307, 0.5, 0.5), Vec3(-1e307, 2, 2)},
      {Vec3(1e307, 0, 0), Vec3(1e308, 1, 1)},   {Vec3(1.7e308, 0, 0), Vec3(1.7e308, 1, 1)},
      {Vec3(0, -1e308, 0), Vec3(0, 1e308, 0)},  {Vec3(0, 0, 0), Vec3(1, 1, 1)},
      {Vec3(0, 0, -1e308), Vec3(1, 1, 1e308)},  {Vec3(1.7e308, 1, 1), Vec3(1.7e308, 2, 2)}};
  std::unique_ptr<Broadphase> brute = make_broadphase(BroadphaseMethod::kBrute);
  MultiBoxPruning mbp;
  for (ProxyId id = 0; id < boxes.size(); ++id) {
    brute->add(id, boxes[id]);
    mbp.add(id, boxes[id]);
  }
  std::vector<ProxyPair> expected, got;
  brute->pairs(expected);
  mbp.pairs(got);
  EXPECT_EQ(got, expected);
  EXPECT_FALSE(expected.empty());
}

TEST(BroadphaseAgreement, Uniform100) {
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    expect_agreement({.name = "uniform 100 seed " + std::to_string(seed),
                      .objects = 100,
                      .frames = 300,
                      .seed = seed});
  }
}

TEST(BroadphaseAgreement, Clustered100) {
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    expect_agreement({.name = "clustered 100 seed " + std::to_string(seed),
                      .objects = 100,
                      .frames = 300,
                      .clustered = true,
                      .churn = 0.2,
                      .seed = seed});
  }
}

TEST(BroadphaseAgreement, Snapped100) {
  // Coordinates on a 1/8 lattice: endpoints tie all the time, boxes touch exactly.
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    expect_agreement({.name = "snapped 100 seed " + std::to_string(seed),
                      .objects = 100,
                      .frames = 300,
                      .clustered = seed % 2 == 0,
                      .snapped = true,
                      .seed = seed});
  }
}

TEST(BroadphaseAgreement, DriftingGrowingBursts100) {
  // The whole scene drifts away from where it started (the octree's root must
  // be rebuilt) and grows by 4x (the grid's cell must be re-chosen); half of
  // the objects appear or vanish at once (sweep and prune re-sorts from scratch).
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    expect_agreement({.name = "drifting growing 100 seed " + std::to_string(seed),
                      .objects = 100,
                      .frames = 300,
                      .clustered = seed == 2,
                      .snapped = seed == 3,
                      .seed = seed,
                      .burst_frame = 150,
                      .drift = 0.5,
                      .growth = 1.005});
  }
}

TEST(BroadphaseAgreement, Uniform10000) {
  expect_agreement({.name = "uniform 10000",
                    .objects = 10000,
                    .frames = 10,
                    .churn = 0.5,
                    .seed = 11,
                    .burst_frame = 6});
}

TEST(BroadphaseAgreement, Clustered10000) {
  expect_agreement({.name = "clustered snapped drifting 10000",
                    .objects = 10000,
                    .frames = 10,
                    .clustered = true,
                    .snapped = true,
                    .churn = 0.5,
                    .seed = 12,
                    .drift = 2,
                    .growth = 1.02});
}

}  // namespace
TEST(Broadphase, PairSortingMatchesAComparisonSort) {
  // Small lists, lists long enough for the radix sort, ids of every width
  // up to 32 bits, repeats of one id: the same order as std::sort.
  std::uint64_t state = 12345;
  const auto next = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<std::uint32_t>(state >> 32);
  };
  detail::PairSortScratch keys;
  for (const std::size_t n : {0, 1, 2, 100, 511, 512, 513, 5000, 70000}) {
    for (const int width : {1, 5, 11, 14, 16, 17, 22, 31, 32}) {
      const std::uint64_t range = std::uint64_t{1} << width;
      std::vector<ProxyPair> pairs;
      for (std::size_t i = 0; i < n; ++i) {
        std::uint32_t a = static_cast<std::uint32_t>(next() % range);
        std::uint32_t b = static_cast<std::uint32_t>(next() % range);
        if (a == b) b = a == 0 ? 1 : a - 1;
        pairs.push_back({std::min(a, b), std::max(a, b)});
      }
      std::vector<ProxyPair> expected = pairs;
      std::sort(expected.begin(), expected.end(), [](const ProxyPair& x, const ProxyPair& y) {
        return x.a < y.a || (x.a == y.a && x.b < y.b);
      });
      detail::sort_proxy_pairs(pairs, keys);
      ASSERT_EQ(pairs, expected) << n << " pairs, ids of " << width << " bits";
    }
  }
}

}  // namespace dovetail::collision
