#include "harness.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <utility>

#include "dovetail/collision/convex.h"

namespace dovetail::bench {

namespace {

using collision::CollideStats;
using collision::Method;
using collision::Transform;
using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

double median_of(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

using ModelPtr = std::shared_ptr<const collision::CollisionModel>;

/// Both objects' structures of one method, built once (`b` may be `a`).
struct ModelPair {
  ModelPtr a, b;
  double build_ms = 0;
  double bytes_per_triangle = 0;
};

ModelPair build_pair(Method method, const MeshPtr& a, const MeshPtr& b) {
  ModelPair pair;
  const auto start = Clock::now();
  pair.a = collision::build_model(method, a);
  pair.b = a == b ? pair.a : collision::build_model(method, b);
  pair.build_ms = ms_since(start);
  const double bytes = static_cast<double>(pair.a->info().bytes) +
                       (a == b ? 0.0 : static_cast<double>(pair.b->info().bytes));
  const double triangles =
      static_cast<double>(a->triangle_count() + (a == b ? 0 : b->triangle_count()));
  pair.bytes_per_triangle = bytes / std::max(1.0, triangles);
  return pair;
}

struct HullPair {
  std::shared_ptr<const collision::ConvexHull> a, b;
  double build_ms = 0;
};

HullPair build_hulls(const MeshPtr& a, const MeshPtr& b) {
  HullPair pair;
  const auto start = Clock::now();
  pair.a = std::make_shared<const collision::ConvexHull>(
      collision::compute_convex_hull(a->vertices, a->source));
  pair.b = a == b ? pair.a
                  : std::make_shared<const collision::ConvexHull>(
                        collision::compute_convex_hull(b->vertices, b->source));
  pair.build_ms = ms_since(start);
  return pair;
}

/// A convex-level approximation on both hulls.
Contender hull_contender(std::string name, std::string family, const HullPair& hulls,
                         std::function<bool(const collision::ConvexHull&,
                                            const collision::ConvexHull&, const Transform&)>
                             query) {
  Contender c;
  c.name = std::move(name);
  c.family = std::move(family);
  c.exact = false;
  c.build_ms = hulls.build_ms;
  c.query = [a = hulls.a, b = hulls.b, query = std::move(query)](
                const Transform& X, CollideStats&) { return query(*a, *b, X); };
  return c;
}

/// A hierarchy's query with `request`, adding its counters to the work.
Contender hierarchy_contender(std::string name, std::string family, bool exact,
                              const ModelPair& models, collision::CollideRequest request) {
  Contender c;
  c.name = std::move(name);
  c.family = std::move(family);
  c.exact = exact;
  c.build_ms = models.build_ms;
  c.bytes_per_triangle = models.bytes_per_triangle;
  c.query = [a = models.a, b = models.b, request](const Transform& X, CollideStats& work) {
    const collision::CollideResult r = a->collide(*b, X, request);
    work.volume_tests += r.stats.volume_tests;
    work.triangle_tests += r.stats.triangle_tests;
    return r.colliding;
  };
  return c;
}

const std::vector<Method>& hierarchies() {
  static const std::vector<Method> methods = [] {
    std::vector<Method> m;
    for (const Method method : collision::all_methods()) {
      if (method != Method::kBrute) m.push_back(method);
    }
    return m;
  }();
  return methods;
}

std::size_t first_exact(const std::vector<Contender>& contenders) {
  for (std::size_t i = 0; i < contenders.size(); ++i) {
    if (contenders[i].exact) return i;
  }
  throw std::invalid_argument("a benchmark protocol needs at least one exact contender");
}

std::string table_name(std::string name) {
  std::replace(name.begin(), name.end(), ' ', '_');
  return name;
}

}  // namespace

collision::Mesh normalized(collision::Mesh mesh) {
  if (mesh.vertices.empty()) return mesh;
  collision::Vec3 lo = mesh.vertices.front(), hi = lo;
  for (const collision::Vec3& v : mesh.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  const collision::Vec3 centre = (lo + hi) / 2;
  const collision::Real half = ((hi - lo) / 2).maxCoeff();
  if (!(half > 0)) return mesh;
  for (collision::Vec3& v : mesh.vertices) v = (v - centre) / half;
  return mesh;
}

std::vector<Contender> exact_contenders(const MeshPtr& a, const MeshPtr& b) {
  std::vector<Contender> contenders;
  for (const Method m : hierarchies()) {
    contenders.push_back(hierarchy_contender(std::string(collision::method_name(m)), "exact", true,
                                             build_pair(m, a, b), {}));
  }
  return contenders;
}

std::vector<Contender> approximate_contenders(const MeshPtr& a, const MeshPtr& b) {
  std::vector<Contender> contenders;
  for (const Method m : hierarchies()) {
    if (m == Method::kBoxtree) continue;  // its own traversal has no depth cut
    const ModelPair models = build_pair(m, a, b);
    const std::string name(collision::method_name(m));
    contenders.push_back(
        hierarchy_contender(name + " volume", "volume", false, models, {.max_depth = 0}));
    if (m != Method::kObb && m != Method::kDop18 && m != Method::kAabb) continue;
    for (const int depth : {2, 4, 8, 12, 16, 20, 24, 28, 32, 36, 40, 48}) {
      contenders.push_back(hierarchy_contender(name + " depth " + std::to_string(depth),
                                               "depth-" + name, false, models,
                                               {.max_depth = depth}));
    }
  }
  const HullPair hulls = build_hulls(a, b);
  contenders.push_back(
      hull_contender("hull", "hull", hulls,
                     [](const collision::ConvexHull& ha, const collision::ConvexHull& hb,
                        const Transform& X) { return collision::gjk(ha, hb, X).intersecting; }));
  for (const int cap : {1, 2, 4, 8, 16, 64}) {
    contenders.push_back(hull_contender("plane cap " + std::to_string(cap), "plane", hulls,
                                        [cap](const collision::ConvexHull& ha,
                                              const collision::ConvexHull& hb, const Transform& X) {
                                          collision::SeparatingPlaneCache cache;
                                          return !collision::separating_plane_test(
                                                      ha, hb, X, cache, {.max_iterations = cap})
                                                      .separated;
                                        }));
  }
  return contenders;
}

Contender hull_plane_contender(const MeshPtr& a, const MeshPtr& b) {
  auto cache = std::make_shared<collision::SeparatingPlaneCache>();
  return hull_contender("hull-plane", "plane", build_hulls(a, b),
                        [cache](const collision::ConvexHull& ha, const collision::ConvexHull& hb,
                                const Transform& X) {
                          return !collision::separating_plane_test(ha, hb, X, *cache).separated;
                        });
}

std::vector<Contender> tumble_contenders(const MeshPtr& a, const MeshPtr& b) {
  std::vector<Contender> contenders = exact_contenders(a, b);
  contenders.push_back(hull_plane_contender(a, b));
  return contenders;
}

std::vector<Contender> contact_pose_contenders(const MeshPtr& a, const MeshPtr& b) {
  std::vector<Contender> contenders = exact_contenders(a, b);
  for (Contender& c : approximate_contenders(a, b)) contenders.push_back(std::move(c));
  return contenders;
}

std::vector<collision::SampledPose> contact_poses(const MeshPtr& a, const MeshPtr& b,
                                                  const collision::ContactPoseSettings& settings) {
  const auto model_a = collision::build_model(Method::kObb, a);
  const auto model_b = a == b ? model_a : collision::build_model(Method::kObb, b);
  return collision::contact_distance_poses(*model_a, *model_b, settings);
}

TumbleCell total(const std::vector<TumbleCell>& cells) {
  TumbleCell all;
  for (const TumbleCell& x : cells) {
    all.colliding += x.colliding;
    all.free += x.free;
    all.sum_us_colliding += x.sum_us_colliding;
    all.sum_us_free += x.sum_us_free;
    all.max_us_colliding = std::max(all.max_us_colliding, x.max_us_colliding);
    all.max_us_free = std::max(all.max_us_free, x.max_us_free);
    all.volume_tests += x.volume_tests;
    all.triangle_tests += x.triangle_tests;
  }
  return all;
}

TumbleResult run_tumble(const std::vector<Contender>& contenders,
                        const collision::TumbleSettings& settings, const Progress& progress) {
  TumbleResult result;
  result.reference = first_exact(contenders);
  result.distances = collision::tumble_distances(settings);
  result.turns = settings.turns;
  const std::vector<collision::TumblePose> poses = collision::tumble_poses(settings);
  result.cells.assign(contenders.size(), std::vector<TumbleCell>(result.distances.size()));
  result.disagreements.assign(contenders.size(), 0);
  std::vector<bool> verdicts(contenders.size());
  for (std::size_t p = 0; p < poses.size(); ++p) {
    const collision::TumblePose& pose = poses[p];
    for (std::size_t c = 0; c < contenders.size(); ++c) {
      CollideStats work;
      const auto start = Clock::now();
      const bool hit = contenders[c].query(pose.X_AB, work);
      const double us = std::chrono::duration<double, std::micro>(Clock::now() - start).count();
      verdicts[c] = hit;
      TumbleCell& cell = result.cells[c][pose.distance_index];
      cell.volume_tests += static_cast<double>(work.volume_tests);
      cell.triangle_tests += static_cast<double>(work.triangle_tests);
      if (hit) {
        ++cell.colliding;
        cell.sum_us_colliding += us;
        cell.max_us_colliding = std::max(cell.max_us_colliding, us);
      } else {
        ++cell.free;
        cell.sum_us_free += us;
        cell.max_us_free = std::max(cell.max_us_free, us);
      }
    }
    for (std::size_t c = 0; c < contenders.size(); ++c) {
      if (contenders[c].exact && verdicts[c] != verdicts[result.reference]) {
        ++result.disagreements[c];
      }
    }
    if (progress && (p + 1) % 256 == 0) progress(p + 1, poses.size());
  }
  if (progress) progress(poses.size(), poses.size());
  return result;
}

void print_tumble(std::FILE* out, const std::vector<Contender>& contenders,
                  const TumbleResult& result) {
  std::fprintf(out, "%zu distances (%g to %g) x %d turns; mean us per query (max)\n",
               result.distances.size(), result.distances.front(), result.distances.back(),
               result.turns);
  std::fprintf(out, "%-14s %10s %10s %10s %10s %12s %12s %9s\n", "method", "colliding", "(max)",
               "free", "(max)", "volume tests", "tri tests", "differ");
  for (std::size_t c = 0; c < contenders.size(); ++c) {
    const TumbleCell all = total(result.cells[c]);
    const double n = std::max(1, all.colliding + all.free);
    const std::string differ = c == result.reference ? "reference"
                               : contenders[c].exact ? std::to_string(result.disagreements[c])
                                                     : "(approx.)";
    std::fprintf(out, "%-14s %10.2f %10.1f %10.2f %10.1f %12.1f %12.1f %9s\n",
                 contenders[c].name.c_str(),
                 all.colliding ? all.sum_us_colliding / all.colliding : 0.0, all.max_us_colliding,
                 all.free ? all.sum_us_free / all.free : 0.0, all.max_us_free, all.volume_tests / n,
                 all.triangle_tests / n, differ.c_str());
  }
}

bool write_tumble_table(const std::string& path, const std::vector<Contender>& contenders,
                        const TumbleResult& result) {
  std::FILE* table = std::fopen(path.c_str(), "w");
  if (table == nullptr) return false;
  std::fprintf(table,
               "# method distance colliding free mean_us mean_us_colliding max_us_colliding "
               "mean_us_free max_us_free volume_tests triangle_tests\n");
  for (std::size_t c = 0; c < contenders.size(); ++c) {
    for (std::size_t d = 0; d < result.distances.size(); ++d) {
      const TumbleCell& x = result.cells[c][d];
      const int n = std::max(1, x.colliding + x.free);
      std::fprintf(table, "%s %.3f %d %d %.4f %.4f %.4f %.4f %.4f %.1f %.1f\n",
                   table_name(contenders[c].name).c_str(), result.distances[d], x.colliding, x.free,
                   (x.sum_us_colliding + x.sum_us_free) / n,
                   x.colliding ? x.sum_us_colliding / x.colliding : 0.0, x.max_us_colliding,
                   x.free ? x.sum_us_free / x.free : 0.0, x.max_us_free, x.volume_tests / n,
                   x.triangle_tests / n);
    }
  }
  return std::fclose(table) == 0;
}

PoseResult run_contact_poses(const std::vector<Contender>& contenders,
                             const std::vector<collision::SampledPose>& poses,
                             const std::vector<collision::Real>& gaps, int runs,
                             const Progress& progress) {
  if (runs < 1) throw std::invalid_argument("a benchmark needs at least one run");
  PoseResult result;
  result.reference = first_exact(contenders);
  result.gaps = gaps;
  result.poses = poses.size();
  result.runs = runs;
  result.rows.resize(contenders.size());
  const std::size_t steps = contenders.size() * static_cast<std::size_t>(runs + 1);
  std::size_t done = 0;

  // The poses of each gap, so that a gap is timed as one block.
  std::vector<std::vector<Transform>> by_gap(gaps.size());
  for (const collision::SampledPose& p : poses) {
    const auto g = std::find(gaps.begin(), gaps.end(), p.gap);
    if (g == gaps.end()) throw std::invalid_argument("a pose's gap is not among the gaps");
    by_gap[static_cast<std::size_t>(g - gaps.begin())].push_back(p.X_AB);
  }

  // Verdicts and work, once.
  std::vector<std::vector<char>> verdicts(contenders.size());
  for (std::size_t c = 0; c < contenders.size(); ++c) {
    CollideStats work;
    for (const collision::SampledPose& p : poses) {
      verdicts[c].push_back(contenders[c].query(p.X_AB, work));
    }
    const double n = std::max<double>(1, static_cast<double>(poses.size()));
    result.rows[c].volume_tests = static_cast<double>(work.volume_tests) / n;
    result.rows[c].triangle_tests = static_cast<double>(work.triangle_tests) / n;
    if (progress) progress(++done, steps);
  }
  const std::vector<char>& truth = verdicts[result.reference];
  result.colliding = static_cast<std::size_t>(std::count(truth.begin(), truth.end(), 1));
  for (std::size_t c = 0; c < contenders.size(); ++c) {
    for (std::size_t p = 0; p < poses.size(); ++p) {
      result.rows[c].false_positives += verdicts[c][p] && !truth[p];
      result.rows[c].false_negatives += !verdicts[c][p] && truth[p];
    }
  }

  // Timed runs, contenders interleaved within each run.
  std::vector<std::vector<double>> run_us(contenders.size());
  std::vector<std::vector<std::vector<double>>> gap_us(
      contenders.size(), std::vector<std::vector<double>>(gaps.size()));
  volatile std::size_t sink = 0;
  for (int r = 0; r < runs; ++r) {
    for (std::size_t c = 0; c < contenders.size(); ++c) {
      double total_us = 0;
      for (std::size_t g = 0; g < gaps.size(); ++g) {
        CollideStats work;
        std::size_t hits = 0;
        const auto start = Clock::now();
        for (const Transform& X : by_gap[g]) hits += contenders[c].query(X, work);
        const double us = std::chrono::duration<double, std::micro>(Clock::now() - start).count();
        sink = sink + hits;
        total_us += us;
        gap_us[c][g].push_back(by_gap[g].empty() ? 0.0
                                                 : us / static_cast<double>(by_gap[g].size()));
      }
      run_us[c].push_back(poses.empty() ? 0.0 : total_us / static_cast<double>(poses.size()));
      if (progress) progress(++done, steps);
    }
  }
  result.best_exact_us = 1e300;
  for (std::size_t c = 0; c < contenders.size(); ++c) {
    PoseRow& row = result.rows[c];
    row.us_per_query = median_of(run_us[c]);
    for (std::size_t g = 0; g < gaps.size(); ++g) row.us_per_gap.push_back(median_of(gap_us[c][g]));
    const bool right = row.false_positives == 0 && row.false_negatives == 0;
    if (contenders[c].exact && right) {
      result.best_exact_us = std::min(result.best_exact_us, row.us_per_query);
    }
  }
  return result;
}

void print_contact_poses(std::FILE* out, const std::vector<Contender>& contenders,
                         const PoseResult& result) {
  const double n = std::max<double>(1, static_cast<double>(result.poses));
  std::fprintf(out, "%zu poses, %zu colliding (the exact answer: %s); median of %d runs\n",
               result.poses, result.colliding, contenders[result.reference].name.c_str(),
               result.runs);
  std::fprintf(out, "%-18s %9s %9s %9s %10s %8s %8s %12s %10s\n", "setting", "build ms",
               "bytes/tri", "us/query", "x best", "FP %", "FN %", "volume tests", "tri tests");
  for (std::size_t c = 0; c < contenders.size(); ++c) {
    const PoseRow& row = result.rows[c];
    std::fprintf(
        out, "%-18s %9.1f %9.1f %9.3f %10.4f %8.2f %8.2f %12.1f %10.1f\n",
        contenders[c].name.c_str(), contenders[c].build_ms, contenders[c].bytes_per_triangle,
        row.us_per_query, row.us_per_query / result.best_exact_us,
        100.0 * static_cast<double>(row.false_positives) / n,
        100.0 * static_cast<double>(row.false_negatives) / n, row.volume_tests, row.triangle_tests);
  }
  std::fprintf(out, "\nus per query per gap (fraction of the object size; < 0 in contact)\n%-18s",
               "setting");
  for (const collision::Real g : result.gaps) std::fprintf(out, " %+9.3f", g);
  std::fprintf(out, "\n");
  for (std::size_t c = 0; c < contenders.size(); ++c) {
    std::fprintf(out, "%-18s", contenders[c].name.c_str());
    for (const double us : result.rows[c].us_per_gap) std::fprintf(out, " %9.3f", us);
    std::fprintf(out, "\n");
  }
}

bool write_contact_pose_table(const std::string& path, const std::vector<Contender>& contenders,
                              const PoseResult& result) {
  std::FILE* table = std::fopen(path.c_str(), "w");
  if (table == nullptr) return false;
  const double n = std::max<double>(1, static_cast<double>(result.poses));
  std::fprintf(table, "# family setting us_per_query x_best_exact fp_percent fn_percent\n");
  for (std::size_t c = 0; c < contenders.size(); ++c) {
    const PoseRow& row = result.rows[c];
    std::fprintf(table, "%s %s %.4f %.4f %.4f %.4f\n", contenders[c].family.c_str(),
                 table_name(contenders[c].name).c_str(), row.us_per_query,
                 row.us_per_query / result.best_exact_us,
                 100.0 * static_cast<double>(row.false_positives) / n,
                 100.0 * static_cast<double>(row.false_negatives) / n);
  }
  return std::fclose(table) == 0;
}

std::string exact_contenders_wrong(const std::vector<Contender>& contenders,
                                   const PoseResult& result) {
  std::string names;
  for (std::size_t c = 0; c < contenders.size(); ++c) {
    const PoseRow& row = result.rows[c];
    if (contenders[c].family != "exact") continue;
    if (row.false_positives == 0 && row.false_negatives == 0) continue;
    names += (names.empty() ? "" : ", ") + contenders[c].name;
  }
  return names;
}

}  // namespace dovetail::bench
