#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "cli.h"
#include "commands.h"
#include "dovetail/collision/contacts.h"
#include "dovetail/collision/distance.h"
#include "dovetail/engine/pose_list.h"
#include "pose_queries.h"

namespace dovetail::cli {

namespace {

constexpr const char* kHelp =
    R"(usage: dovetail query A B --poses FILE [--method M] [--out FLAGS] [--all-pairs] [--threads N]
       dovetail query A B --poses FILE --distance [--method rss|brute] [--out FILE] [--threads N]
       dovetail query A B --poses FILE --tolerance EPS [--method rss|brute] [--out FILE] [--threads N]
       dovetail query A B --poses FILE --contacts [--contact-tolerance T] [--method M] [--out FILE]
                      [--threads N]

Tests mesh B against mesh A at every pose of a pose list.

  A, B           mesh files (OBJ, STL, PLY, glTF or GLB), each merged into one mesh
  --poses FILE   pose list: one pose of B in A's frame per line, `tx ty tz qw qx qy qz`
                 (extra columns ignored, `#` lines and blank lines skipped)
  --method M     boxtree (default), dop6, dop14, dop18, dop26, aabb, obb, brute;
                 with --distance or --tolerance: rss (default) or brute
  --out FLAGS    write the per-pose lines there (default: standard output, before
                 the summary)
  --all-pairs    find every intersecting triangle pair, not just the first
                 (the verdicts are the same; the summary adds pairs_total);
                 not with --distance or --tolerance, implied by --contacts
  --threads N    worker threads for the queries (default 1; 0 = all cores)

One of these changes what each pose's line holds (at most one may be given):
  (none)             1 colliding, 0 not
  --distance         the minimum distance between the surfaces (0 when colliding),
                     17 significant digits
  --tolerance EPS    1 when the distance is at most EPS (a finite number >= 0), 0 not
  --contacts         one JSON object: the contact patches of the all-pairs result
  --contact-tolerance T
                     with --contacts: a patch deeper than T is penetrating
                     (default 1e-6)

Prints a one-line JSON summary on standard output. A bad pose line stops the
run with an error naming file and line; the lines of the poses before it are
still written.
)";

enum class Mode { kCollide, kDistance, kTolerance, kContacts };

const char* mode_name(Mode mode) {
  switch (mode) {
    case Mode::kCollide:
      return "collide";
    case Mode::kDistance:
      return "distance";
    case Mode::kTolerance:
      return "tolerance";
    case Mode::kContacts:
      return "contacts";
  }
  return "collide";
}

/// The mode the options ask for; UsageError for options that do not go together.
Mode parse_mode(const Args& args) {
  std::vector<std::string> given;
  if (args.flag("distance")) given.emplace_back("--distance");
  if (args.value("tolerance")) given.emplace_back("--tolerance");
  if (args.flag("contacts")) given.emplace_back("--contacts");
  if (given.size() > 1) {
    throw UsageError("query: " + given[0] + " and " + given[1] +
                     " cannot be combined: each chooses what a pose's line holds; give at most "
                     "one of --distance, --tolerance, --contacts");
  }
  const Mode mode = args.flag("distance")     ? Mode::kDistance
                    : args.value("tolerance") ? Mode::kTolerance
                    : args.flag("contacts")   ? Mode::kContacts
                                              : Mode::kCollide;
  if ((mode == Mode::kDistance || mode == Mode::kTolerance) && args.flag("all-pairs")) {
    throw UsageError("query: --all-pairs cannot be combined with " + given[0] +
                     ", which reports no triangle pairs");
  }
  if (mode != Mode::kContacts && args.value("contact-tolerance")) {
    throw UsageError("query: --contact-tolerance needs --contacts");
  }
  return mode;
}

/// --method for the distance modes: false for rss (the default), true for
/// brute. A collision method has no distance query: a usage error, rather
/// than silently measuring with another method than the one asked for.
bool distance_method_is_brute(const Args& args, Mode mode) {
  const std::optional<std::string> name = args.value("method");
  if (!name || *name == "rss") return false;
  if (*name == "brute") return true;
  const std::string option = mode == Mode::kDistance ? "--distance" : "--tolerance";
  if (collision::parse_method(*name)) {
    throw UsageError("query: method '" + *name + "' has no distance query; " + option +
                     " uses rss (the default) or brute");
  }
  throw UsageError("query: unknown method '" + *name + "' for " + option +
                   "; valid methods: rss, brute");
}

void print_notes(const std::string& path, const LoadedMesh& loaded) {
  for (const std::string& note : loaded.report.notes) {
    std::fprintf(stderr, "dovetail: note: %s: %s\n", path.c_str(), note.c_str());
  }
  if (loaded.validation.degenerate_removed > 0) {
    std::fprintf(stderr, "dovetail: note: %s: removed %zu degenerate triangles\n", path.c_str(),
                 loaded.validation.degenerate_removed);
  }
}

/// A distance model and how long the build took.
struct BuiltDistanceModel {
  std::shared_ptr<const collision::DistanceModel> model;
  double build_ms = 0;
};

BuiltDistanceModel build_distance_timed(std::shared_ptr<const collision::Mesh> mesh) {
  const auto start = std::chrono::steady_clock::now();
  BuiltDistanceModel built;
  built.model = collision::build_distance_model(std::move(mesh));
  built.build_ms = ms_since(start);
  return built;
}

/// Build times and memory of the two hierarchies (all 0 for brute-force distances).
struct ModelSummary {
  double build_ms_a = 0;
  double build_ms_b = 0;
  std::uint64_t bytes_a = 0;
  std::uint64_t bytes_b = 0;
};

}  // namespace

namespace {

/// What the command line asks of a query run.
struct QueryOptions {
  std::string path_a, path_b, poses_path;
  std::optional<std::string> out_path;
  Mode mode = Mode::kCollide;
  bool distance_mode = false;   ///< --distance or --tolerance
  bool distance_brute = false;  ///< ... by brute force instead of the RSS tree
  collision::Method method = collision::Method::kBoxtree;  ///< collision modes only
  double tolerance = 0;
  collision::ContactRequest contact_request;
  collision::CollideRequest request;
  int threads = 1;
};

QueryOptions parse_query_options(const Args& args) {
  args.expect_positional(2, "two mesh files A and B");
  QueryOptions o;
  o.path_a = args.positional()[0];
  o.path_b = args.positional()[1];
  o.poses_path = args.required("poses");
  o.mode = parse_mode(args);
  o.distance_mode = o.mode == Mode::kDistance || o.mode == Mode::kTolerance;
  o.distance_brute = o.distance_mode && distance_method_is_brute(args, o.mode);
  if (!o.distance_mode && args.value("method") == "rss") {
    throw UsageError(
        "query: method 'rss' (the distance hierarchy) answers --distance and --tolerance only; "
        "collision methods: " +
        method_list());
  }
  // The collision method (not used by the distance modes, which have their own).
  o.method = o.distance_mode ? collision::Method::kBrute : args.method(collision::Method::kBoxtree);
  o.tolerance = args.number("tolerance", 0.0).value_or(0.0);
  o.contact_request.touching_tolerance =
      args.number("contact-tolerance", 0.0).value_or(o.contact_request.touching_tolerance);
  o.threads = static_cast<int>(args.integer("threads", 0, 1024).value_or(1));
  o.out_path = args.value("out");
  o.request.all_pairs = args.flag("all-pairs");
  return o;
}

/// The poses up to the first bad line, and that line's error (reported after
/// the results of the good poses are written).
struct PoseBatch {
  std::vector<collision::Transform> poses;
  std::optional<std::string> error;
};

PoseBatch read_poses(engine::PoseListReader& reader) {
  PoseBatch batch;
  try {
    while (std::optional<engine::PoseEntry> pose = reader.next()) batch.poses.push_back(pose->X_AB);
  } catch (const engine::PoseListError& e) {
    batch.error = e.what();
  }
  return batch;
}

/// A mode's results: per-pose lines, its own summary keys (`counts` after
/// query_ms_total, `extras` after threads) and the work done.
struct QueryOutcome {
  std::string lines;
  ModelSummary models;
  JsonLine counts;
  JsonLine extras;
  collision::CollideStats stats;
  double query_ms = 0;
};

QueryOutcome run_distance_mode(const QueryOptions& o, const LoadedMesh& a, const LoadedMesh& b,
                               const std::vector<collision::Transform>& poses) {
  QueryOutcome r;
  DistanceInputs inputs{.mesh_a = a.mesh.get(), .mesh_b = b.mesh.get()};
  BuiltDistanceModel model_a;
  BuiltDistanceModel model_b;
  if (!o.distance_brute) {
    model_a = build_distance_timed(a.mesh);
    model_b = build_distance_timed(b.mesh);
    inputs.model_a = model_a.model.get();
    inputs.model_b = model_b.model.get();
    r.models = {model_a.build_ms, model_b.build_ms, model_a.model->info().bytes,
                model_b.model->info().bytes};
  }
  if (o.mode == Mode::kDistance) {
    const DistanceQueryResult result = run_distance_queries(inputs, poses, o.threads);
    r.lines.reserve(20 * poses.size());
    for (double d : result.distances) r.lines += format_distance(d) + "\n";
    r.counts.add("colliding", result.colliding_count)
        .add("distance_min", result.distance_min)
        .add("distance_max", result.distance_max);
    r.stats = result.stats;
    r.query_ms = result.wall_ms;
  } else {
    const ToleranceQueryResult result =
        run_tolerance_queries(inputs, poses, o.tolerance, o.threads);
    r.lines.reserve(2 * poses.size());
    for (std::uint8_t w : result.within) r.lines += w != 0 ? "1\n" : "0\n";
    r.counts.add("tolerance", o.tolerance).add("within", result.within_count);
    r.stats = result.stats;
    r.query_ms = result.wall_ms;
  }
  return r;
}

QueryOutcome run_collision_mode(const QueryOptions& o, const LoadedMesh& a, const LoadedMesh& b,
                                const std::vector<collision::Transform>& poses) {
  QueryOutcome r;
  const BuiltModel model_a = build_timed(o.method, a.mesh);
  const BuiltModel model_b = build_timed(o.method, b.mesh);
  r.models = {model_a.build_ms, model_b.build_ms, model_a.model->info().bytes,
              model_b.model->info().bytes};
  if (o.mode == Mode::kContacts) {
    const ContactQueryResult result =
        run_contact_queries(*model_a.model, *model_b.model, poses, o.contact_request, o.threads);
    for (const std::string& line : result.lines) r.lines += line + "\n";
    r.counts.add("colliding", result.colliding_count);
    r.extras.add("pairs_total", result.pairs_total)
        .add("contact_tolerance", o.contact_request.touching_tolerance)
        .add("patches_total", result.patches_total)
        .add("patches_face", result.face_patches)
        .add("patches_curve", result.curve_patches)
        .add("patches_point", result.point_patches)
        .add("patches_penetrating", result.penetrating_patches);
    r.stats = result.stats;
    r.query_ms = result.wall_ms;
  } else {
    const PoseQueryResult result =
        run_pose_queries(*model_a.model, *model_b.model, poses, o.request, o.threads);
    r.lines.reserve(2 * poses.size());
    for (std::uint8_t c : result.colliding) r.lines += c != 0 ? "1\n" : "0\n";
    r.counts.add("colliding", result.colliding_count);
    if (o.request.all_pairs) r.extras.add("pairs_total", result.pairs_total);
    r.stats = result.stats;
    r.query_ms = result.wall_ms;
  }
  return r;
}

/// The one-line JSON summary.
JsonLine query_summary(const QueryOptions& o, const LoadedMesh& a, const LoadedMesh& b,
                       std::size_t queries, const QueryOutcome& r) {
  const std::string_view method_shown = !o.distance_mode   ? collision::method_name(o.method)
                                        : o.distance_brute ? std::string_view("brute")
                                                           : std::string_view("rss");
  JsonLine json;
  json.add("method", method_shown)
      .add("mode", mode_name(o.mode))
      .add("a", o.path_a)
      .add("b", o.path_b)
      .add("triangles_a", std::uint64_t{a.mesh->triangle_count()})
      .add("triangles_b", std::uint64_t{b.mesh->triangle_count()})
      .add("build_ms", round_ms(r.models.build_ms_a + r.models.build_ms_b))
      .add("build_ms_a", round_ms(r.models.build_ms_a))
      .add("build_ms_b", round_ms(r.models.build_ms_b))
      .add("queries", std::uint64_t{queries})
      .add("query_ms_total", round_ms(r.query_ms))
      .add_all(r.counts)
      .add("model_bytes", r.models.bytes_a + r.models.bytes_b)
      .add("model_bytes_a", r.models.bytes_a)
      .add("model_bytes_b", r.models.bytes_b)
      .add("volume_tests", r.stats.volume_tests)
      .add("triangle_tests", r.stats.triangle_tests)
      .add("threads", o.threads)
      .add_all(r.extras);
  return json;
}

}  // namespace

int query_command(std::span<const std::string> argv) {
  const Args args("query", argv,
                  {"poses", "method", "out", "threads", "tolerance", "contact-tolerance"},
                  {"all-pairs", "distance", "contacts"});
  if (args.help()) {
    std::fputs(kHelp, stdout);
    return kExitOk;
  }
  const QueryOptions o = parse_query_options(args);

  // Check the output first: an unwritable destination should fail before any
  // work. It is replaced only once the answers are there.
  if (o.out_path) {
    const std::string inputs[] = {o.path_a, o.path_b, o.poses_path};
    refuse_overwriting_input("query", *o.out_path, inputs);
    check_writable(*o.out_path);
  }
  std::optional<engine::PoseListReader> reader;
  try {
    reader.emplace(o.poses_path);
  } catch (const engine::PoseListError& e) {
    throw InputError(e.what());
  }
  const LoadedMesh a = load_mesh(o.path_a);
  const LoadedMesh b = load_mesh(o.path_b);
  print_notes(o.path_a, a);
  print_notes(o.path_b, b);
  if (o.out_path) {  // nor a file the meshes refer to (a glTF buffer)
    refuse_overwriting_input("query", *o.out_path, a.report.files);
    refuse_overwriting_input("query", *o.out_path, b.report.files);
  }

  const PoseBatch batch = read_poses(*reader);
  const QueryOutcome r = o.distance_mode ? run_distance_mode(o, a, b, batch.poses)
                                         : run_collision_mode(o, a, b, batch.poses);
  // A pose list whose first line is already wrong leaves an existing file as it was.
  const bool no_answers = batch.poses.empty() && batch.error.has_value();
  if (o.out_path && !no_answers) {
    std::ofstream out(*o.out_path, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(*o.out_path + ": cannot be written: " + std::strerror(errno));
    out.write(r.lines.data(), static_cast<std::streamsize>(r.lines.size()));
    out.close();
    if (!out) throw InputError(*o.out_path + ": write failed: " + std::strerror(errno));
  } else if (!o.out_path) {
    std::fwrite(r.lines.data(), 1, r.lines.size(), stdout);
  }
  JsonLine json = query_summary(o, a, b, batch.poses.size(), r);
  if (batch.error) json.add("error", *batch.error);
  std::fputs((json.str() + "\n").c_str(), stdout);

  if (batch.error) throw InputError(*batch.error);
  return kExitOk;
}

}  // namespace dovetail::cli
