#include "dovetail/collision/capture.h"

#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <system_error>

#include "dovetail/collision/convex.h"
#include "dovetail/collision/model.h"

namespace dovetail::collision {

namespace {

namespace fs = std::filesystem;

constexpr std::string_view kMagic = "dovetail-capture 1";

/// A double as a hexadecimal float: exact, and read back by strtod to the same bits.
void put_hex(std::string& out, Real x) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%a", x);
  out += buffer;
}

/// One line: newlines would break the file, so they become spaces.
std::string one_line(std::string_view text) {
  std::string line(text);
  for (char& c : line) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return line;
}

void put_mesh(std::string& out, char name, const Mesh& mesh) {
  out += "mesh ";
  out += name;
  out += ' ' + std::to_string(mesh.vertices.size()) + ' ' + std::to_string(mesh.triangles.size());
  out += ' ' + one_line(mesh.source) + '\n';
  for (const Vec3& v : mesh.vertices) {
    for (int k = 0; k < 3; ++k) {
      if (k > 0) out += ' ';
      put_hex(out, v[k]);
    }
    out += '\n';
  }
  for (const TriangleIndices& f : mesh.triangles) {
    out += std::to_string(f[0]) + ' ' + std::to_string(f[1]) + ' ' + std::to_string(f[2]) + '\n';
  }
}

/// Reads the capture file line by line, naming the file and line in every error.
class LineReader {
 public:
  explicit LineReader(const fs::path& file) : file_(file) {
    // Errors about the file as a whole name no line.
    std::error_code error;
    if (fs::is_directory(file, error)) throw CaptureError(file.string() + ": is a folder");
    in_.open(file);
    if (!in_) {
      throw CaptureError(file.string() + ": cannot be opened: " +
                         std::error_code(errno, std::generic_category()).message());
    }
  }

  std::string next(std::string_view expecting) {
    std::string line;
    if (!std::getline(in_, line)) {
      if (line_number_ == 0) throw CaptureError(file_.string() + ": empty");
      fail("ends early, expecting " + std::string(expecting));
    }
    ++line_number_;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return line;
  }

  [[noreturn]] void fail(const std::string& message) const { fail_at(line_number_, message); }

  /// Nothing but blank lines may follow.
  void expect_end() {
    std::string line;
    while (std::getline(in_, line)) {
      ++line_number_;
      if (line.find_first_not_of(" \t\r") != std::string::npos) fail("text after 'end'");
    }
  }

  /// The numbers of a line, all of it: `count` doubles (hex or decimal).
  std::vector<Real> reals(std::string_view line, std::size_t count, std::string_view what) const {
    std::vector<Real> values;
    std::string text(line);
    const char* p = text.c_str();
    while (true) {
      while (*p == ' ' || *p == '\t') ++p;
      if (*p == '\0') break;
      char* end = nullptr;
      const Real x = std::strtod(p, &end);
      if (end == p) fail("expected " + std::string(what) + ", found '" + text + "'");
      values.push_back(x);
      p = end;
    }
    if (values.size() != count) {
      fail("expected " + std::to_string(count) + " numbers (" + std::string(what) + "), found " +
           std::to_string(values.size()));
    }
    return values;
  }

  std::uint64_t count(std::string_view word, std::string_view what) const {
    std::string text(word);
    char* end = nullptr;
    errno = 0;
    const unsigned long long n = std::strtoull(text.c_str(), &end, 10);
    if (text.empty() || text[0] == '-' || *end != '\0' || errno == ERANGE || n > (1ull << 26)) {
      fail("expected " + std::string(what) + " (0 to 2^26), found '" + text + "'");
    }
    return n;
  }

 private:
  [[noreturn]] void fail_at(std::size_t line, const std::string& message) const {
    throw CaptureError(file_.string() + ":" + std::to_string(line) + ": " + message);
  }

  fs::path file_;
  std::ifstream in_;
  std::size_t line_number_ = 0;
};

/// The text after `key ` on a line that must start with it.
std::string after(LineReader& reader, const std::string& line, std::string_view key) {
  if (line.rfind(std::string(key) + " ", 0) != 0 && line != key) {
    reader.fail("expected a line '" + std::string(key) + " ...', found '" + line + "'");
  }
  return line.size() > key.size() ? line.substr(key.size() + 1) : std::string();
}

std::shared_ptr<const Mesh> read_mesh(LineReader& reader, char name) {
  const std::string head = reader.next("a mesh");
  const std::string rest = after(reader, head, std::string("mesh ") + name);
  std::istringstream words(rest);
  std::string n_vertices, n_triangles;
  words >> n_vertices >> n_triangles;
  auto mesh = std::make_shared<Mesh>();
  const std::uint64_t nv = reader.count(n_vertices, "a vertex count");
  const std::uint64_t nt = reader.count(n_triangles, "a triangle count");
  std::getline(words >> std::ws, mesh->source);
  mesh->vertices.reserve(nv);
  for (std::uint64_t i = 0; i < nv; ++i) {
    const std::vector<Real> x = reader.reals(reader.next("a vertex"), 3, "a vertex: x y z");
    if (!std::isfinite(x[0]) || !std::isfinite(x[1]) || !std::isfinite(x[2])) {
      reader.fail("a vertex is not finite");
    }
    mesh->vertices.emplace_back(x[0], x[1], x[2]);
  }
  mesh->triangles.reserve(nt);
  for (std::uint64_t i = 0; i < nt; ++i) {
    std::istringstream line(reader.next("a triangle"));
    std::array<std::string, 3> w;
    std::string extra;
    line >> w[0] >> w[1] >> w[2];
    if (line >> extra) reader.fail("a triangle has three vertex indices, found more");
    TriangleIndices f;
    for (int k = 0; k < 3; ++k) {
      const std::uint64_t v = reader.count(w[k], "a vertex index");
      if (v >= nv)
        reader.fail("vertex index " + w[k] + " is past the mesh's " + std::to_string(nv) +
                    " vertices");
      f[k] = static_cast<std::uint32_t>(v);
    }
    mesh->triangles.push_back(f);
  }
  return mesh;
}

bool finite(const Transform& X) { return X.R.allFinite() && X.t.allFinite(); }

bool finite(const Mesh& mesh) {
  for (const Vec3& v : mesh.vertices) {
    if (!v.allFinite()) return false;
  }
  return true;
}

constexpr std::array<Method, 8> kEveryMethod = {Method::kBoxtree, Method::kDop6,  Method::kDop14,
                                                Method::kDop18,   Method::kDop26, Method::kAabb,
                                                Method::kObb,     Method::kBrute};

/// Each method's verdict; the brute-force one last.
std::vector<std::pair<Method, bool>> verdicts(const Capture& c) {
  std::vector<std::pair<Method, bool>> out;
  for (const Method m : kEveryMethod) {
    const auto a = build_model(m, c.a);
    const auto b = build_model(m, c.b);
    out.emplace_back(m, a->collide(*b, c.X_AB).colliding);
  }
  return out;
}

std::optional<ConvexHull> hull_of(const Mesh& mesh) {
  try {
    return compute_convex_hull(mesh.vertices, mesh.source);
  } catch (const std::invalid_argument&) {
    return std::nullopt;  // a flat part has no hull
  }
}

CaptureReplay replay_disagreement(const Capture& c) {
  const std::vector<std::pair<Method, bool>> v = verdicts(c);
  const bool truth = v.back().second;
  for (const auto& [method, colliding] : v) {
    if (colliding != truth) {
      return {true, std::string(method_name(method)) + " says " +
                        (colliding ? "intersecting" : "separate") + ", brute force says " +
                        (truth ? "intersecting" : "separate")};
    }
  }
  const std::optional<ConvexHull> ha = hull_of(*c.a), hb = hull_of(*c.b);
  if (ha && hb && truth) {
    SeparatingPlaneCache cache;
    if (separating_plane_test(*ha, *hb, c.X_AB, cache).separated) {
      return {true, "the separating plane separates the hulls of intersecting meshes"};
    }
  }
  return {false, std::string("every method says ") + (truth ? "intersecting" : "separate")};
}

CaptureReplay replay_iteration_cap(const Capture& c) {
  const std::optional<ConvexHull> ha = hull_of(*c.a), hb = hull_of(*c.b);
  if (!ha || !hb) return {false, "a mesh is flat: no hulls, no search"};
  const GjkResult g = gjk(*ha, *hb, c.X_AB);
  if (g.hit_iteration_cap) {
    return {true, "GJK stopped at its cap of " + std::to_string(kGjkMaxIterations) + " iterations"};
  }
  SeparatingPlaneCache cache;
  const SeparatingPlaneSettings settings;
  const SeparatingPlaneResult p = separating_plane_test(*ha, *hb, c.X_AB, cache, settings);
  if (!p.separated && !p.overlap && p.iterations >= settings.max_iterations) {
    return {true, "the separating-plane search stopped at its cap of " +
                      std::to_string(settings.max_iterations) + " iterations"};
  }
  return {false, "GJK took " + std::to_string(g.iterations) +
                     " iterations, the separating-plane search " + std::to_string(p.iterations)};
}

CaptureReplay replay_non_finite(const Capture& c) {
  const bool finite_input = finite(c.X_AB) && finite(*c.a) && finite(*c.b);
  verdicts(c);  // every method must come back on this input, whatever it says
  const std::optional<ConvexHull> ha = hull_of(*c.a), hb = hull_of(*c.b);
  if (ha && hb && finite_input) {
    const GjkResult g = gjk(*ha, *hb, c.X_AB);
    if (!std::isfinite(g.distance)) return {true, "GJK's distance is not finite on finite input"};
  }
  return {false, finite_input ? "every result is finite"
                              : "the input is not finite; every method returned"};
}

/// FNV-1a over the capture's text: the file name.
std::uint64_t text_hash(std::string_view text) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (const char ch : text) {
    h ^= static_cast<unsigned char>(ch);
    h *= 0x100000001b3ull;
  }
  return h;
}

}  // namespace

std::string_view capture_kind_name(CaptureKind kind) {
  switch (kind) {
    case CaptureKind::kMethodsDisagree:
      return "methods-disagree";
    case CaptureKind::kIterationCap:
      return "iteration-cap";
    case CaptureKind::kNonFinite:
      return "non-finite";
  }
  return "methods-disagree";
}

std::string capture_text(const Capture& c) {
  std::string out(kMagic);
  out += "\nkind ";
  out += capture_kind_name(c.kind);
  out += "\nwhat " + one_line(c.what) + "\ncontext " + one_line(c.context) + "\nX_AB";
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      put_hex(out, c.X_AB.R(r, k));
    }
  }
  for (int k = 0; k < 3; ++k) {
    out += ' ';
    put_hex(out, c.X_AB.t[k]);
  }
  out += '\n';
  put_mesh(out, 'a', c.a ? *c.a : Mesh{});
  put_mesh(out, 'b', c.b ? *c.b : Mesh{});
  out += "end\n";
  return out;
}

Capture read_capture(const fs::path& file) {
  LineReader reader(file);
  if (reader.next("the first line") != kMagic) {
    reader.fail("not a capture file: the first line must be '" + std::string(kMagic) + "'");
  }
  Capture c;
  const std::string kind = after(reader, reader.next("the kind"), "kind");
  bool known = false;
  for (const CaptureKind k :
       {CaptureKind::kMethodsDisagree, CaptureKind::kIterationCap, CaptureKind::kNonFinite}) {
    if (kind == capture_kind_name(k)) {
      c.kind = k;
      known = true;
    }
  }
  if (!known) {
    reader.fail("unknown kind '" + kind + "' (methods-disagree, iteration-cap or non-finite)");
  }
  c.what = after(reader, reader.next("what was seen"), "what");
  c.context = after(reader, reader.next("the context"), "context");
  const std::vector<Real> x =
      reader.reals(after(reader, reader.next("the transform"), "X_AB"), 12, "R row by row, then t");
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) c.X_AB.R(r, k) = x[3 * r + k];
  }
  c.X_AB.t = Vec3(x[9], x[10], x[11]);
  // Only a non-finite capture holds a pose that is not one.
  if (c.kind != CaptureKind::kNonFinite) {
    if (!finite(c.X_AB)) reader.fail("X_AB is not finite");
    const Real off = (c.X_AB.R.transpose() * c.X_AB.R - Mat3::Identity()).cwiseAbs().maxCoeff();
    // As loose as what a run accepts as a rotation (a script's set_matrix).
    if (!(off < 1e-6) || !(c.X_AB.R.determinant() > 0)) {
      char departs[32];
      std::snprintf(departs, sizeof departs, "%g", off);
      reader.fail("X_AB's R is not a rotation (R^T R departs from the identity by " +
                  std::string(departs) + ", or it mirrors)");
    }
  }
  c.a = read_mesh(reader, 'a');
  c.b = read_mesh(reader, 'b');
  if (reader.next("'end'") != "end") reader.fail("expected 'end' after the meshes");
  reader.expect_end();
  return c;
}

CaptureReplay replay_capture(const Capture& capture) {
  if (!capture.a || !capture.b) return {false, "a mesh is missing"};
  switch (capture.kind) {
    case CaptureKind::kMethodsDisagree:
      return replay_disagreement(capture);
    case CaptureKind::kIterationCap:
      return replay_iteration_cap(capture);
    case CaptureKind::kNonFinite:
      return replay_non_finite(capture);
  }
  return {};
}

CaptureSink::CaptureSink(fs::path directory, std::size_t max_files)
    : directory_(std::move(directory)), max_files_(max_files) {}

void CaptureSink::record(const Capture& capture) {
  const std::string text = capture_text(capture);
  char name[64];
  std::snprintf(name, sizeof name, "%s-%016llx.capture",
                std::string(capture_kind_name(capture.kind)).c_str(),
                static_cast<unsigned long long>(text_hash(text)));
  const fs::path file = directory_ / name;
  std::lock_guard lock(mutex_);
  ++recorded_;
  if (files_.count(file) != 0 || files_.size() >= max_files_) return;
  std::error_code ec;
  fs::create_directories(directory_, ec);
  std::ofstream out(file, std::ios::binary);
  out << text;
  out.close();
  if (!out) {
    ++failed_;
    return;
  }
  files_.insert(file);
}

std::size_t CaptureSink::recorded() const {
  std::lock_guard lock(mutex_);
  return recorded_;
}

std::vector<fs::path> CaptureSink::files() const {
  std::lock_guard lock(mutex_);
  return {files_.begin(), files_.end()};
}

std::size_t CaptureSink::failed_writes() const {
  std::lock_guard lock(mutex_);
  return failed_;
}

}  // namespace dovetail::collision
