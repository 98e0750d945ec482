#pragma once
/// \file lua_host.h
/// The sandboxed Lua 5.4 host: one Lua state whose scripts see a whitelisted,
/// read-only standard library and run under an instruction budget, a memory
/// cap and a wall-clock guard.
///
/// Why: scenario scripts are untrusted input that must neither hang, exhaust
/// memory nor reach the file system, and a run must be reproducible. So the
/// scripts get no io/os/package/debug, `math.random` is a generator seeded by
/// the host, `pairs` and `table.sort` have a defined order, and exhausting a
/// limit is an error that pcall cannot swallow. Every failure surfaces as one
/// ScriptError with the script's file and line, and the host stays usable.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

struct lua_State;

namespace dovetail::scripting {

struct HostState;  // private: src/host_state.h

/// The limits of one host. The budget and the wall-clock guard apply to each
/// outermost host call (run_file, run_string, call), the memory cap to the
/// whole state.
struct SandboxLimits {
  /// Lua VM instructions per host call, counted in steps of 1000; the work
  /// of library functions and of copying into new memory counts too.
  std::uint64_t instructions_per_call = 20'000'000;
  /// Cap of the allocator for the whole state, enforced while a host call
  /// runs (the host's own pushes between calls are counted, not refused).
  /// The captured print log has a cap of the same size.
  std::size_t memory_bytes = 64u << 20;
  /// Wall-clock guard per host call, checked with the instruction count: a
  /// last resort for work the budget does not count (a comparison of two
  /// long strings is one instruction), far above what the budget allows on
  /// a slow machine, so that no script within the budget meets it.
  double wall_seconds_per_call = 30.0;
};

/// A script failed: syntax or runtime error, budget, memory or time exhausted.
/// what() is "file:line: message" followed by "\nstack traceback:\n..." when
/// there is one.
class ScriptError : public std::runtime_error {
 public:
  enum class Kind { kSyntax, kRuntime, kBudget, kMemory, kTime };
  ScriptError(Kind kind, const std::string& what);
  Kind kind() const { return kind_; }
  /// The first line of what(): "file:line: message".
  const std::string& message() const { return message_; }

 private:
  Kind kind_;
  std::string message_;
};

/// "syntax", "runtime", "budget", "memory" or "time" (for reports).
const char* kind_name(ScriptError::Kind kind);

/// One sandboxed Lua state. Scripts share one environment table, so globals a
/// chunk defines stay visible to later chunks and calls.
///
/// The scripts' library: assert, error, ipairs, pairs (sorted keys: numbers,
/// then strings, then booleans; other keys are an error), select, tonumber,
/// tostring, type, rawequal, rawget, rawlen, rawset, setmetatable (no __gc),
/// getmetatable, pcall and xpcall (which re-raise an exhausted limit), load
/// (text only, the sandbox environment by default), print (captured), and
/// read-only proxies of string (no dump; rep refuses results that do not fit
/// in memory), table (sort is a stable merge sort; move counts one
/// instruction per element), math (random and randomseed use the host's
/// generator), utf8 and coroutine. Tables, functions and coroutines show as
/// "table: #3" in tostring, print and string.format's %s, numbered in order
/// of first display, never by address; %p is refused.
///
/// C functions registered by users run inside the host's protected calls;
/// they may call call() re-entrantly (the outermost call's budget applies)
/// but must catch ScriptError and raise it as a Lua error only after the
/// exception object is gone, since Lua unwinds with longjmp.
class LuaHost {
 public:
  LuaHost(const SandboxLimits& limits, std::uint64_t seed);
  ~LuaHost();
  LuaHost(const LuaHost&) = delete;
  LuaHost& operator=(const LuaHost&) = delete;
  LuaHost(LuaHost&&) = delete;
  LuaHost& operator=(LuaHost&&) = delete;

  lua_State* state();

  /// Pushes the sandbox environment table (the scripts' _ENV and _G).
  void push_env();

  /// Loads the text file (named "path:line:" in messages, as given) with the
  /// sandbox environment, runs it under the limits and leaves `nresults`
  /// results on the stack (LUA_MULTRET allowed). A first line starting with
  /// '#' is ignored. A missing or unreadable file is a kRuntime ScriptError
  /// naming the path; other failures as for call().
  void run_file(const std::filesystem::path& path, int nresults);
  /// As run_file for the text `code`, named `name` in messages.
  void run_string(std::string_view code, const std::string& name, int nresults);
  /// Calls the function below the `nargs` arguments on top of the stack under
  /// a fresh budget (when not nested in another host call) and leaves
  /// `nresults` results. Throws ScriptError; the function and arguments are
  /// popped either way.
  void call(int nargs, int nresults);

  /// What scripts printed, one entry per print call (arguments joined by
  /// tabs). Nothing is written to stdout.
  const std::vector<std::string>& printed() const;
  void clear_printed();

  /// Instructions run so far over all calls, in steps of 1000.
  std::uint64_t instructions_used() const;
  /// Bytes the state holds now.
  std::size_t memory_used() const;

 private:
  void load_chunk(std::string_view code, const std::string& chunk_name);
  std::unique_ptr<HostState> host_;
};

}  // namespace dovetail::scripting
