#include "import_process.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <mutex>
#include <new>
#include <stdexcept>
#include <string_view>
#include <type_traits>

namespace dovetail::engine::detail {

namespace fs = std::filesystem;

namespace {

/// Starts every encoded report, so that a child that wrote something else
/// (or nothing) is not read as one.
constexpr std::uint64_t kMagic = 0x31'54'52'4f'50'4d'49'44;  // "DIMPORT1"

class Writer {
 public:
  template <typename T>
  void raw(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    out_.append(reinterpret_cast<const char*>(&value), sizeof value);
  }
  void count(std::size_t n) { raw(static_cast<std::uint64_t>(n)); }
  void text(const std::string& s) {
    count(s.size());
    out_ += s;
  }
  void vec(const collision::Vec3& v) {
    for (int k = 0; k < 3; ++k) raw(v[k]);
  }
  std::string take() { return std::move(out_); }

 private:
  std::string out_;
};

class Reader {
 public:
  explicit Reader(std::string_view in) : in_(in) {}

  template <typename T>
  T raw() {
    static_assert(std::is_trivially_copyable_v<T>);
    T value;
    need(sizeof value);
    std::memcpy(&value, in_.data() + at_, sizeof value);
    at_ += sizeof value;
    return value;
  }
  /// A count of items of at least `item_bytes` each, checked against what is left.
  std::size_t count(std::size_t item_bytes) {
    const auto n = raw<std::uint64_t>();
    if (item_bytes > 0 && n > (in_.size() - at_) / item_bytes) truncated();
    return static_cast<std::size_t>(n);
  }
  std::string text() {
    const std::size_t n = count(1);
    std::string s(in_.substr(at_, n));
    at_ += n;
    return s;
  }
  collision::Vec3 vec() {
    collision::Vec3 v;
    for (int k = 0; k < 3; ++k) v[k] = raw<double>();
    return v;
  }
  bool done() const { return at_ == in_.size(); }

 private:
  void need(std::size_t n) const {
    if (n > in_.size() - at_) truncated();
  }
  [[noreturn]] static void truncated() {
    throw std::runtime_error("the import's answer is cut short");
  }

  std::string_view in_;
  std::size_t at_ = 0;
};

/// Writes all of `bytes` to `fd`; false when the reader has gone.
bool write_all(int fd, const std::string& bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<std::size_t>(n);
  }
  return true;
}

std::string read_all(int fd) {
  std::string in;
  char buffer[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return in;
    in.append(buffer, static_cast<std::size_t>(n));
  }
}

/// Bytes of address space this process has mapped (its VmSize).
std::uintmax_t mapped_bytes() {
  std::ifstream statm("/proc/self/statm");
  std::uintmax_t pages = 0;
  statm >> pages;
  return pages * static_cast<std::uintmax_t>(::sysconf(_SC_PAGESIZE));
}

/// Whether this build runs under a sanitizer, whose shadow memory an
/// address-space limit would break.
constexpr bool kSanitized =
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
    true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || \
    __has_feature(memory_sanitizer)
    true;
#else
    false;
#endif
#else
    false;
#endif

/// The child's side: caps its memory, imports, sends 'R' and the report or
/// 'E' and the error, and leaves without running the parent's exit handlers
/// (they would flush the parent's buffered output a second time). Nothing
/// may unwind out of it: the child would go on as a second copy of the
/// program.
[[noreturn]] void run_child(int fd, pid_t parent, const fs::path& path,
                            const std::function<ImportReport()>& import,
                            std::uintmax_t memory_budget_bytes) noexcept {
  try {
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(1);
    // The parent's handlers (an interrupt that sets a flag) are not the child's.
    for (const int signal_number : {SIGINT, SIGTERM, SIGHUP, SIGPIPE}) {
      ::signal(signal_number, SIG_DFL);
    }
    if (!kSanitized) {
      const std::uintmax_t limit = mapped_bytes() + memory_budget_bytes;
      const rlimit cap{static_cast<rlim_t>(limit), static_cast<rlim_t>(limit)};
      ::setrlimit(RLIMIT_AS, &cap);
    }
    std::string answer;
    try {
      answer = 'R' + encode_report(import());
    } catch (const ImportError& e) {
      answer = std::string("E") + e.what();
    } catch (const std::bad_alloc&) {
      answer = "E" + path.string() + ": ran out of memory while reading";
    } catch (const std::exception& e) {
      answer = "E" + path.string() + ": cannot be read as a mesh: " + e.what();
    } catch (...) {
      answer = "E" + path.string() + ": cannot be read as a mesh: unknown failure in the importer";
    }
    ::_exit(write_all(fd, answer) ? 0 : 1);
  } catch (...) {
    ::_exit(2);  // the parent says the importer's process ended without an answer
  }
}

/// Why a child that ended this way gave no answer.
std::string child_failure(int status) {
  if (WIFSIGNALED(status)) {
    const int signal_number = WTERMSIG(status);
    const char* abbreviation = ::sigabbrev_np(signal_number);
    const std::string name =
        abbreviation != nullptr ? std::string("SIG") + abbreviation : std::to_string(signal_number);
    if (signal_number == SIGKILL) {
      return "the mesh importer was killed (" + name +
             ") while reading it, most likely for running out of memory";
    }
    if (signal_number == SIGINT || signal_number == SIGTERM || signal_number == SIGHUP) {
      return "the mesh importer was stopped (" + name + ") while reading it";
    }
    return "the mesh importer (assimp) crashed on it (" + name + ", " + ::strsignal(signal_number) +
           "): the file is malformed in a way Dovetail does not check itself; "
           "open it in another tool, or export it again";
  }
  return "the mesh importer's process ended without an answer (exit status " +
         std::to_string(WEXITSTATUS(status)) + ")";
}

/// The parent's hold on a child: its pipe closed, and the child killed and
/// reaped, however the parent leaves (an exception while reading included).
struct Child {
  pid_t pid = -1;
  int fd = -1;
  Child() = default;
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  ~Child() {
    if (fd >= 0) ::close(fd);
    if (pid > 0) {
      ::kill(pid, SIGKILL);
      while (::waitpid(pid, nullptr, 0) < 0 && errno == EINTR) {
      }
    }
  }
};

/// Pipes and forks one import at a time: a child forked while another
/// import's pipe was open would hold that pipe's write end, and its reader
/// would wait for that child too.
std::mutex g_fork_mutex;

}  // namespace

std::string encode_report(const ImportReport& report) {
  Writer w;
  w.raw(kMagic);
  w.count(report.parts.size());
  for (const ImportedPart& part : report.parts) {
    w.text(part.name);
    w.count(part.node);
    w.count(part.groups.size());
    for (const std::string& group : part.groups) w.text(group);
    w.text(part.mesh.source);
    w.count(part.mesh.vertices.size());
    for (const collision::Vec3& v : part.mesh.vertices) w.vec(v);
    w.count(part.mesh.triangles.size());
    for (const collision::TriangleIndices& t : part.mesh.triangles) w.raw(t);
    w.count(part.validation.input_vertices);
    w.count(part.validation.input_triangles);
    w.count(part.validation.degenerate_removed);
    w.count(part.validation.unused_vertices);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) w.raw(part.X_RP.R(r, c));
    }
    w.vec(part.X_RP.t);
  }
  w.count(report.cameras.size());
  for (const auto& [name, camera] : report.cameras) {
    w.text(name);
    w.vec(camera.eye);
    w.vec(camera.target);
    w.vec(camera.up);
    w.raw(camera.fov_y_degrees);
  }
  w.count(report.skipped_line_or_point_primitives);
  w.count(report.notes.size());
  for (const std::string& note : report.notes) w.text(note);
  w.count(report.files.size());
  for (const std::string& file : report.files) w.text(file);
  return w.take();
}

ImportReport decode_report(std::string_view bytes) {
  Reader r(bytes);
  if (r.raw<std::uint64_t>() != kMagic) throw std::runtime_error("the import's answer is garbled");
  ImportReport report;
  report.parts.resize(r.count(1));
  for (ImportedPart& part : report.parts) {
    part.name = r.text();
    part.node = r.count(0);
    part.groups.resize(r.count(1));
    for (std::string& group : part.groups) group = r.text();
    part.mesh.source = r.text();
    part.mesh.vertices.resize(r.count(3 * sizeof(double)));
    for (collision::Vec3& v : part.mesh.vertices) v = r.vec();
    part.mesh.triangles.resize(r.count(sizeof(collision::TriangleIndices)));
    for (collision::TriangleIndices& t : part.mesh.triangles) {
      t = r.raw<collision::TriangleIndices>();
    }
    part.validation.input_vertices = r.count(0);
    part.validation.input_triangles = r.count(0);
    part.validation.degenerate_removed = r.count(0);
    part.validation.unused_vertices = r.count(0);
    for (int row = 0; row < 3; ++row) {
      for (int c = 0; c < 3; ++c) part.X_RP.R(row, c) = r.raw<double>();
    }
    part.X_RP.t = r.vec();
  }
  report.cameras.resize(r.count(1));
  for (auto& [name, camera] : report.cameras) {
    name = r.text();
    camera.eye = r.vec();
    camera.target = r.vec();
    camera.up = r.vec();
    camera.fov_y_degrees = r.raw<double>();
  }
  report.skipped_line_or_point_primitives = r.count(0);
  report.notes.resize(r.count(1));
  for (std::string& note : report.notes) note = r.text();
  report.files.resize(r.count(1));
  for (std::string& file : report.files) file = r.text();
  if (!r.done()) throw std::runtime_error("the import's answer is longer than the report");
  return report;
}

ImportReport import_in_child(const fs::path& path, const std::function<ImportReport()>& import,
                             std::uintmax_t memory_budget_bytes) {
  Child child;
  std::string why_not;  // why no child could be started
  {
    const std::lock_guard<std::mutex> lock(g_fork_mutex);
    int fds[2] = {-1, -1};
    if (::pipe2(fds, O_CLOEXEC) != 0) {
      why_not = std::string("no pipe: ") + std::strerror(errno);
    } else {
      const pid_t parent = ::getpid();
      const pid_t pid = ::fork();
      if (pid == 0) {
        ::close(fds[0]);
        run_child(fds[1], parent, path, import, memory_budget_bytes);
      }
      const int fork_errno = errno;
      ::close(fds[1]);
      if (pid < 0) {
        ::close(fds[0]);
        why_not = std::string("no process: ") + std::strerror(fork_errno);
      } else {
        child.pid = pid;
        child.fd = fds[0];
      }
    }
  }
  if (child.pid < 0) {
    // Read here, unguarded, rather than not at all; and said so.
    ImportReport report = import();
    report.notes.push_back(
        "read in Dovetail's own process, without the guard of a process of "
        "its own (" +
        why_not + ")");
    return report;
  }
  const std::string answer = read_all(child.fd);
  int status = 0;
  pid_t waited = -1;
  while ((waited = ::waitpid(child.pid, &status, 0)) < 0 && errno == EINTR) {
  }
  if (waited == child.pid) child.pid = -1;  // reaped
  // A child that could not be waited for (its exit collected elsewhere) is
  // judged by its answer alone.
  const bool exited_cleanly = waited < 0 || (WIFEXITED(status) && WEXITSTATUS(status) == 0);
  if (!exited_cleanly || answer.empty()) {
    throw ImportError(path.string() + ": " +
                      (waited < 0 ? std::string("the mesh importer's process gave no answer")
                                  : child_failure(status)));
  }
  if (answer[0] == 'E') throw ImportError(answer.substr(1));
  try {
    return decode_report(std::string_view(answer).substr(1));
  } catch (const std::runtime_error& e) {
    throw ImportError(path.string() + ": " + e.what());
  }
}

}  // namespace dovetail::engine::detail
