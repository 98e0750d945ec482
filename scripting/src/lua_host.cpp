#include "dovetail/scripting/lua_host.h"

// Lua is compiled as C and raises errors with longjmp, which skips C++
// destructors. So a lua_CFunction (and the hook and the allocator) written
// here never has a live object with a non-trivial destructor in scope when it
// calls lua_error, luaL_error or any API function that can raise: such
// objects are destroyed first, or C++ exceptions are caught inside and turned
// into a Lua error afterwards. Host methods that throw ScriptError do so only
// after the protected Lua call has returned.

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <string_view>
#include <system_error>
#include <utility>

#include "host_state.h"
#include "sandbox_env.h"

namespace dovetail::scripting {

namespace {

using Clock = std::chrono::steady_clock;

/// Whether `where` ("chunk:line: " or "chunk: ") has a line.
bool has_line(const char* where) {
  std::size_t n = std::strlen(where);
  if (n < 4 || where[n - 1] != ' ' || where[n - 2] != ':') return false;
  n -= 2;
  std::size_t digits = 0;
  while (n > 0 && where[n - 1] >= '0' && where[n - 1] <= '9') --n, ++digits;
  return digits > 0 && n > 0 && where[n - 1] == ':';
}

void count_hook(lua_State* L, lua_Debug* ar);

// The allocator of the state: counts every byte and, while a host call runs,
// refuses growth beyond the cap (Lua then collects garbage and retries once,
// and raises a memory error if that does not help).
void* allocate(void* data, void* block, std::size_t old_size, std::size_t new_size) noexcept {
  HostState& host = *static_cast<HostState*>(data);
  const std::size_t held = block != nullptr ? old_size : 0;
  if (new_size == 0) {
    std::free(block);
    host.bytes -= held;
    return nullptr;
  }
  const bool grows = new_size > held;
  void* moved = nullptr;
  if (!grows || !host.active() || new_size - held <= host.memory_left()) {
    moved = std::realloc(block, new_size);
  }
  if (moved == nullptr) {
    if (grows) {
      if (host.refusal_pending && host.refused_old == held && host.refused_new == new_size &&
          host.active()) {
        host.memory_failed = true;
        // The line the script is at now, in the thread that runs (the
        // coroutine's own line inside one), rather than where the count
        // hook last fired, up to kHookInterval instructions ago or not yet.
        // Lua saves a thread's position before any step that can allocate,
        // and reading the stack allocates nothing.
        lua_State* const at = host.running != nullptr ? host.running : host.L;
        if (at != nullptr) {
          char here[sizeof(host.where)];
          write_where(at, 0, here, sizeof(here));
          if (here[0] != '\0') std::memcpy(host.where, here, sizeof(here));
        }
      }
      host.refusal_pending = true;
      host.refused_old = held;
      host.refused_new = new_size;
    }
    return nullptr;
  }
  host.bytes = host.bytes - held + new_size;
  if (grows) {
    host.refusal_pending = false;
    // Copying into new memory is work no instruction shows; the count
    // hook raises the budget's error at its next look.
    if (host.active()) {
      const std::uint64_t work = (new_size - held) / kBytesPerInstruction;
      host.instructions_in_call += work;
      host.instructions_total += work;
      // Past the budget: the hook looks at the next instruction rather than
      // up to kHookInterval copies later (lua_sethook may be called from
      // anywhere, the allocator too).
      if (host.instructions_in_call > host.limits.instructions_per_call) {
        lua_State* const at = host.running != nullptr ? host.running : host.L;
        if (at != nullptr) lua_sethook(at, count_hook, LUA_MASKCOUNT, 1);
      }
    }
  }
  return moved;
}

// The wall-clock limit, placed at `where` ("chunk:line: "): the count hook
// and check_deadline find it passed.
void exhaust_time(HostState& host, const char* where) {
  set_exhausted(host, ScriptError::Kind::kTime, where, "wall-clock limit of %g s exceeded",
                host.limits.wall_seconds_per_call);
}

// Counts instructions in steps of kHookInterval and, during a host call,
// raises once the budget or the deadline is passed. Coroutines inherit the
// hook from the thread that creates them, so they are counted too.
void count_hook(lua_State* L, lua_Debug* ar) {
  HostState& host = host_of(L);
  // The allocator may have made the hook look sooner; it looks every
  // kHookInterval instructions again from here.
  const int interval = lua_gethookcount(L);
  if (interval != kHookInterval) lua_sethook(L, count_hook, LUA_MASKCOUNT, kHookInterval);
  host.instructions_total += static_cast<std::uint64_t>(interval);
  if (!host.active()) return;
  if (lua_getinfo(L, "Sl", ar) != 0) {
    if (ar->currentline > 0) {
      std::snprintf(host.where, sizeof(host.where), "%s:%d: ", ar->short_src, ar->currentline);
    } else {
      std::snprintf(host.where, sizeof(host.where), "%s: ", ar->short_src);
    }
  }
  if (!limit_exhausted(host)) {
    host.instructions_in_call += static_cast<std::uint64_t>(interval);
    if (host.instructions_in_call > host.limits.instructions_per_call) {
      set_exhausted(host, ScriptError::Kind::kBudget, host.where,
                    "instruction budget of %llu exceeded",
                    static_cast<unsigned long long>(host.limits.instructions_per_call));
    } else if (Clock::now() > host.deadline) {
      exhaust_time(host, host.where);
    }
  }
  // Once exhausted, every further hook raises again: a swallowed error
  // leaves at most kHookInterval instructions.
  if (host.exhausted) raise_exhausted(L);
}

/// Whether an error message holds a position, "chunk:line: ", on its first
/// line (a chunk's name may itself hold ": ").
bool has_position(std::string_view text) {
  const std::string_view first = text.substr(0, text.find('\n'));
  for (std::size_t colon = first.find(':'); colon != std::string_view::npos;
       colon = first.find(':', colon + 1)) {
    std::size_t i = colon + 1;
    while (i < first.size() && first[i] >= '0' && first[i] <= '9') ++i;
    if (i > colon + 1 && first.substr(i, 2) == ": ") return true;
  }
  return false;
}

// The message handler of every host call: the error message (or the
// exhausted limit's) followed by a traceback.
int message_handler(lua_State* L) {
  HostState& host = host_of(L);
  if (limit_exhausted(host, L)) {
    lua_pushstring(L, host.exhausted_message);
  } else {
    const bool text = lua_type(L, 1) == LUA_TSTRING || lua_type(L, 1) == LUA_TNUMBER;
    if (text) {
      lua_pushvalue(L, 1);
    } else if (luaL_callmeta(L, 1, "__tostring") == 0 || lua_type(L, -1) != LUA_TSTRING) {
      // error(nil) or error({}): say what was raised.
      lua_pushfstring(L, "(error object is a %s value)", luaL_typename(L, 1));
    }
    // Lua adds no position to error(text, 0), to error(text, 2) in a
    // function the host called, to an error raised by a library function
    // (coroutine.yield outside a coroutine) or to an object: say where it
    // was raised.
    std::size_t length = 0;
    const char* message = lua_tolstring(L, -1, &length);
    if (!has_position(std::string_view(message, length))) {
      char where[sizeof(host.where)];
      write_where(L, 1, where, sizeof(where));
      lua_pushstring(L, where);
      lua_insert(L, -2);
      lua_concat(L, 2);
    }
  }
  // A C metamethod that raised the error (the scenario loader's unknown
  // names) is no place in the script: the traceback starts at its caller.
  int level = 1;
  lua_Debug ar;
  if (lua_getstack(L, 1, &ar) != 0 && lua_getinfo(L, "Sn", &ar) != 0 && ar.what[0] == 'C' &&
      ar.namewhat != nullptr && std::strcmp(ar.namewhat, "metamethod") == 0) {
    level = 2;
  }
  luaL_traceback(L, L, lua_tostring(L, -1), level);
  return 1;
}

Clock::time_point deadline_after(double seconds) {
  if (!(seconds < 1e9)) return Clock::time_point::max();
  const auto span = std::chrono::duration<double>(seconds > 0 ? seconds : 0);
  return Clock::now() + std::chrono::duration_cast<Clock::duration>(span);
}

// One host call. The outermost one starts a fresh budget and deadline and
// clears the exhausted flag; after a memory failure it collects the garbage
// the failed script left.
class CallScope {
 public:
  explicit CallScope(HostState& host) : host_(host) {
    if (host_.depth++ > 0) return;
    host_.instructions_in_call = 0;
    host_.deadline = deadline_after(host_.limits.wall_seconds_per_call);
    host_.exhausted.reset();
    host_.memory_failed = false;
    host_.exhausted_message[0] = '\0';
    host_.where[0] = '\0';
    host_.refusal_pending = false;
  }
  ~CallScope() {
    if (--host_.depth > 0) return;
    if (host_.exhausted == ScriptError::Kind::kMemory) lua_gc(host_.L, LUA_GCCOLLECT, 0);
  }
  CallScope(const CallScope&) = delete;
  CallScope& operator=(const CallScope&) = delete;

 private:
  HostState& host_;
};

// Every "shortened:" in text (a position, a traceback line) back to the
// file's path as given.
void restore_sources(const HostState& host, std::string& text) {
  for (const auto& [shortened, full] : host.shortened_sources) {
    if (full.empty()) continue;  // ambiguous
    const std::string from = shortened + ':';
    for (std::size_t at = text.find(from); at != std::string::npos;
         at = text.find(from, at + full.size() + 1)) {
      text.replace(at, shortened.size(), full);
    }
  }
}

// Pops the error object on top of the stack and makes the ScriptError: the
// exhausted limit's kind and message when one is set, else `kind`.
// Names the sandbox leaves out on purpose, and why: said after Lua's
// "attempt to call a nil value (global 'next')", which reads like a typo.
constexpr std::pair<std::string_view, std::string_view> kLeftOut[] = {
    {"next",
     "next is left out of the sandbox: the order it visits keys in differs from run to run; "
     "pairs visits them in sorted order"},
    {"os",
     "os is left out of the sandbox: the clock and the system would make runs differ; dt.time() "
     "is the simulated time"},
    {"io",
     "io is left out of the sandbox: scripts read and write no files; dt.log writes to the "
     "report"},
    {"require", "require is left out of the sandbox: a scenario is one file, its helpers in it"},
    {"dofile", "dofile is left out of the sandbox: a scenario is one file, its helpers in it"},
    {"loadfile", "loadfile is left out of the sandbox: a scenario is one file, its helpers in it"},
    {"package", "package is left out of the sandbox: a scenario is one file, its helpers in it"},
    {"debug", "debug is left out of the sandbox: it reaches past the sandbox's limits"},
    {"collectgarbage",
     "collectgarbage is left out of the sandbox: memory is collected as the script runs"},
};

/// `text` with the reason a global is left out added to its first line,
/// when that line is Lua's error at a use of one.
std::string with_left_out_reason(std::string text) {
  const std::size_t end = std::min(text.find('\n'), text.size());
  for (const auto& [name, reason] : kLeftOut) {
    const std::string global = "a nil value (global '" + std::string(name) + "')";
    const std::size_t at = text.find(global);
    if (at != std::string::npos && at + global.size() <= end) {
      text.insert(end, " (" + std::string(reason) + ")");
      break;
    }
  }
  return text;
}

ScriptError take_error(HostState& host, ScriptError::Kind kind) {
  lua_State* L = host.L;
  std::string text;
  if (lua_type(L, -1) == LUA_TSTRING) {
    std::size_t length = 0;
    const char* data = lua_tolstring(L, -1, &length);
    text.assign(data, length);
  } else {
    text = std::string("(error object is a ") + luaL_typename(L, -1) + " value)";
  }
  lua_pop(L, 1);
  if (limit_exhausted(host)) {
    // A memory error carries Lua's own text, and an error re-raised through
    // a coroutine a position prefix; the limit's message replaces both.
    const std::string limit_message = host.exhausted_message;
    if (text.compare(0, limit_message.size(), limit_message) != 0) text = limit_message;
    kind = *host.exhausted;
  }
  restore_sources(host, text);
  if (kind == ScriptError::Kind::kRuntime) text = with_left_out_reason(std::move(text));
  return ScriptError(kind, text);
}

// A chunk name too long for Lua's positions, with the short form Lua gives
// it: Lua's own, from a function loaded under that name.
void remember_shortened(HostState& host, const std::string& chunk_name) {
  const std::string full = chunk_name.substr(1);
  for (const auto& known : host.shortened_sources) {
    if (known.second == full) return;
  }
  lua_State* L = host.L;
  if (luaL_loadbufferx(L, "", 0, chunk_name.c_str(), "t") != LUA_OK) {
    lua_pop(L, 1);
    return;
  }
  lua_Debug ar;
  lua_getinfo(L, ">S", &ar);  // pops the function
  if (full == ar.short_src) return;
  // Two paths of one shortened name cannot be told apart: neither is given
  // back (an empty path marks the name as ambiguous).
  for (auto& known : host.shortened_sources) {
    if (known.first == ar.short_src) {
      known.second.clear();
      return;
    }
  }
  host.shortened_sources.emplace_back(ar.short_src, full);
}

// '@' names a file, '=' any other source ("@" + name trips GCC 12's -Wrestrict).
std::string chunk_name(char kind, const std::string& name) {
  std::string chunk(1, kind);
  chunk += name;
  return chunk;
}

std::string first_line(const std::string& text) { return text.substr(0, text.find('\n')); }

std::string read_script(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::error_code error;
  if (!std::filesystem::exists(path, error)) {
    throw ScriptError(ScriptError::Kind::kRuntime, name + ": file not found");
  }
  if (std::filesystem::is_directory(path, error)) {
    throw ScriptError(ScriptError::Kind::kRuntime, name + ": is a directory");
  }
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  if (in) text << in.rdbuf();
  if (!in || in.bad()) throw ScriptError(ScriptError::Kind::kRuntime, name + ": cannot be read");
  std::string code = std::move(text).str();
  // A UTF-8 byte order mark and a first line such as "#!/usr/bin/env lua"
  // are skipped; the line break stays so line numbers do not shift.
  if (code.compare(0, 3, "\xEF\xBB\xBF") == 0) code.erase(0, 3);
  if (!code.empty() && code[0] == '#') code.erase(0, code.find('\n'));
  return code;
}

}  // namespace

HostState& host_of(lua_State* L) {
  void* data = nullptr;
  lua_getallocf(L, &data);
  return *static_cast<HostState*>(data);
}

void set_exhausted(HostState& host, ScriptError::Kind kind, const char* where, const char* format,
                   ...) {
  if (host.exhausted) return;
  host.exhausted = kind;
  const int prefix = std::snprintf(host.exhausted_message, sizeof(host.exhausted_message), "%s",
                                   where != nullptr ? where : "");
  const std::size_t used = prefix > 0 ? static_cast<std::size_t>(prefix) : 0;
  if (used >= sizeof(host.exhausted_message)) return;
  va_list arguments;
  va_start(arguments, format);
  std::vsnprintf(host.exhausted_message + used, sizeof(host.exhausted_message) - used, format,
                 arguments);
  va_end(arguments);
}

int raise_exhausted(lua_State* L) {
  lua_pushstring(L, host_of(L).exhausted_message);
  return lua_error(L);
}

void note_memory_error(HostState& host, lua_State* L) {
  if (!host.active()) return;
  host.memory_failed = true;
  limit_exhausted(host, L);
}

bool limit_exhausted(HostState& host, lua_State* L) {
  if (host.memory_failed && !host.exhausted) {
    // The hook's last location has no line when it fired outside a line (in
    // a library function): then the stack, where there is one, names it.
    if (L != nullptr && !has_line(host.where)) {
      char here[sizeof(host.where)];
      write_where(L, 1, here, sizeof(here));
      if (here[0] != '\0') std::memcpy(host.where, here, sizeof(here));
    }
    set_exhausted(host, ScriptError::Kind::kMemory, host.where,
                  "memory limit of %zu bytes exceeded", host.limits.memory_bytes);
  }
  return host.exhausted.has_value();
}

void charge(lua_State* L, std::uint64_t units, const char* what) {
  HostState& host = host_of(L);
  if (!host.active()) return;
  const std::uint64_t budget = host.limits.instructions_per_call;
  host.instructions_total =
      units > std::numeric_limits<std::uint64_t>::max() - host.instructions_total
          ? std::numeric_limits<std::uint64_t>::max()
          : host.instructions_total + units;
  // Saturated one past the budget: `units` may be a bound near 2^64.
  host.instructions_in_call = units > budget || host.instructions_in_call > budget - units
                                  ? budget + 1
                                  : host.instructions_in_call + units;
  if (!limit_exhausted(host, L) && host.instructions_in_call > budget) {
    char here[sizeof(host.where)];
    write_where(L, 1, here, sizeof(here));
    set_exhausted(host, ScriptError::Kind::kBudget, here,
                  "instruction budget of %llu exceeded (%s)",
                  static_cast<unsigned long long>(budget), what);
  }
  if (host.exhausted) raise_exhausted(L);
}

void check_deadline(lua_State* L) {
  HostState& host = host_of(L);
  if (!host.active()) return;
  if (!limit_exhausted(host, L) && Clock::now() > host.deadline) {
    char here[sizeof(host.where)];
    write_where(L, 1, here, sizeof(here));
    exhaust_time(host, here);
  }
  if (host.exhausted) raise_exhausted(L);
}

void write_where(lua_State* L, int level, char* buffer, std::size_t size) {
  lua_Debug ar;
  buffer[0] = '\0';
  for (; lua_getstack(L, level, &ar) != 0; ++level) {
    if (lua_getinfo(L, "Sl", &ar) != 0 && ar.currentline > 0) {
      std::snprintf(buffer, size, "%s:%d: ", ar.short_src, ar.currentline);
      return;
    }
  }
}

ScriptError::ScriptError(Kind kind, const std::string& what)
    : std::runtime_error(what), kind_(kind), message_(first_line(what)) {}

const char* kind_name(ScriptError::Kind kind) {
  switch (kind) {
    case ScriptError::Kind::kSyntax:
      return "syntax";
    case ScriptError::Kind::kRuntime:
      return "runtime";
    case ScriptError::Kind::kBudget:
      return "budget";
    case ScriptError::Kind::kMemory:
      return "memory";
    case ScriptError::Kind::kTime:
      return "time";
  }
  return "runtime";
}

LuaHost::LuaHost(const SandboxLimits& limits, std::uint64_t seed)
    : host_(std::make_unique<HostState>()) {
  host_->limits = limits;
  host_->seed = seed;
  host_->random.reseed(seed);
  lua_State* L = lua_newstate(allocate, host_.get());
  if (L == nullptr) throw std::bad_alloc();
  host_->L = L;
  lua_sethook(L, count_hook, LUA_MASKCOUNT, kHookInterval);
  lua_pushcfunction(L, open_sandbox);
  if (lua_pcall(L, 0, 0, 0) != LUA_OK) {
    const std::string message = lua_type(L, -1) == LUA_TSTRING ? lua_tostring(L, -1) : "?";
    lua_close(L);
    throw std::runtime_error("cannot build the Lua sandbox: " + message);
  }
}

LuaHost::~LuaHost() { lua_close(host_->L); }

lua_State* LuaHost::state() { return host_->L; }

void LuaHost::push_env() {
  if (!lua_checkstack(host_->L, 1)) throw std::bad_alloc();
  push_sandbox_env(host_->L);
}

void LuaHost::load_chunk(std::string_view code, const std::string& chunk_name) {
  lua_State* L = host_->L;
  if (!lua_checkstack(L, 2)) {
    throw ScriptError(ScriptError::Kind::kMemory, chunk_name.substr(1) + ": Lua stack overflow");
  }
  if (chunk_name.size() + 4 >= LUA_IDSIZE) remember_shortened(*host_, chunk_name);
  const int status = luaL_loadbufferx(L, code.data(), code.size(), chunk_name.c_str(), "t");
  if (status != LUA_OK) {
    if (status == LUA_ERRMEM) note_memory_error(*host_);
    throw take_error(*host_, ScriptError::Kind::kSyntax);
  }
  push_sandbox_env(L);
  lua_setupvalue(L, -2, 1);  // the chunk's _ENV
}

void LuaHost::run_file(const std::filesystem::path& path, int nresults) {
  const std::string code = read_script(path);
  CallScope scope(*host_);
  load_chunk(code, chunk_name('@', path.string()));
  call(0, nresults);
}

void LuaHost::run_string(std::string_view code, const std::string& name, int nresults) {
  CallScope scope(*host_);
  load_chunk(code, chunk_name('=', name));
  call(0, nresults);
}

void LuaHost::call(int nargs, int nresults) {
  lua_State* L = host_->L;
  const int function_index = lua_gettop(L) - nargs;
  CallScope scope(*host_);
  if (!lua_checkstack(L, 2)) {
    lua_settop(L, function_index - 1);
    throw ScriptError(ScriptError::Kind::kMemory, "Lua stack overflow");
  }
  // Where a memory error is placed when the script was never seen by the
  // hook: the called function's source.
  char origin[sizeof(host_->where)] = {};
  lua_Debug ar;
  lua_pushvalue(L, function_index);
  if (lua_getinfo(L, ">S", &ar) != 0 && ar.what[0] != 'C') {
    if (ar.linedefined > 0) {
      std::snprintf(origin, sizeof(origin), "%s:%d: ", ar.short_src, ar.linedefined);
    } else {
      std::snprintf(origin, sizeof(origin), "%s: ", ar.short_src);
    }
  }
  lua_pushcfunction(L, message_handler);
  lua_insert(L, function_index);
  const int status = lua_pcall(L, nargs, nresults, function_index);
  lua_remove(L, function_index);
  if (status == LUA_OK) return;
  if (host_->where[0] == '\0') std::memcpy(host_->where, origin, sizeof(origin));
  if (status == LUA_ERRMEM) note_memory_error(*host_);
  throw take_error(*host_, ScriptError::Kind::kRuntime);
}

const std::vector<std::string>& LuaHost::printed() const { return host_->printed; }

void LuaHost::clear_printed() {
  host_->printed.clear();
  host_->printed_bytes = 0;
}

std::uint64_t LuaHost::instructions_used() const { return host_->instructions_total; }

std::size_t LuaHost::memory_used() const { return host_->bytes; }

}  // namespace dovetail::scripting
