#pragma once
/// \file host_state.h
/// What one LuaHost keeps beside its lua_State: the allocator's account, the
/// per-call budget and deadline, the exhausted-limit flag, the generator and
/// the print log. Shared by the host (lua_host.cpp) and the sandbox library
/// (sandbox_env.cpp); every C function finds it through lua_getallocf.
///
/// Why: a limit, once exhausted, must stay exhausted until the outermost host
/// call ends, whichever coroutine or pcall observes it, so the flag and its
/// message live in one place outside the Lua stacks.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <lua.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "dovetail/scripting/lua_host.h"
#include "xoshiro256.h"

namespace dovetail::scripting {

/// VM instructions between two calls of the count hook.
inline constexpr int kHookInterval = 1000;

/// Library work the count hook does not see, counted in instructions so
/// that it meets the same budget, the same way on every machine: one per
/// kBytesPerInstruction bytes the script's memory grows by (a `..` or a
/// string.rep copies its result in one instruction), one per
/// kComparesPerInstruction characters a string search may compare, one per
/// element a table function moves or visits.
inline constexpr std::uint64_t kBytesPerInstruction = 64;
inline constexpr std::uint64_t kComparesPerInstruction = 4;

struct HostState {
  SandboxLimits limits;
  std::uint64_t seed = 0;
  lua_State* L = nullptr;
  // The thread running Lua code: a coroutine while the sandbox's resume
  // runs it, else null (the main thread, L).
  lua_State* running = nullptr;

  // The allocator's account. A refusal repeated for the same request means
  // the emergency collection in between did not help: the cap is reached.
  std::size_t bytes = 0;
  bool refusal_pending = false;
  std::size_t refused_old = 0;
  std::size_t refused_new = 0;

  // Host calls: the budget, the deadline and the cap apply while depth > 0.
  int depth = 0;
  std::uint64_t instructions_in_call = 0;
  std::uint64_t instructions_total = 0;
  std::chrono::steady_clock::time_point deadline;

  // The exhausted limit of the current outermost call and its message
  // ("chunk:line: ..."); fixed buffers, so setting them never allocates.
  std::optional<ScriptError::Kind> exhausted;
  // Set by the allocator when the cap is reached; the next check, which
  // knows where the script is, turns it into `exhausted`.
  bool memory_failed = false;
  char exhausted_message[256] = {};
  // "chunk:line: " of the Lua function the count hook last saw.
  char where[LUA_IDSIZE + 24] = {};

  // Files whose name Lua shortens in positions and tracebacks (to
  // LUA_IDSIZE, keeping the end behind "..."): the shortened name and the
  // path as given, which error messages get back (take_error).
  std::vector<std::pair<std::string, std::string>> shortened_sources;

  Xoshiro256 random;

  std::vector<std::string> printed;
  std::size_t printed_bytes = 0;
  // Serial numbers that name tables, functions and coroutines in tostring.
  lua_Integer display_ids = 0;

  // The library functions the sandbox wraps.
  lua_CFunction base_load = nullptr;
  lua_CFunction base_setmetatable = nullptr;
  lua_CFunction base_rawset = nullptr;
  lua_CFunction string_rep = nullptr;
  lua_CFunction string_format = nullptr;
  lua_CFunction string_find = nullptr;
  lua_CFunction string_match = nullptr;
  lua_CFunction string_gmatch = nullptr;
  lua_CFunction string_gsub = nullptr;
  lua_CFunction string_byte = nullptr;
  lua_CFunction utf8_len = nullptr;
  lua_CFunction utf8_codepoint = nullptr;
  lua_CFunction utf8_offset = nullptr;
  lua_CFunction base_tonumber = nullptr;
  lua_CFunction table_move = nullptr;
  lua_CFunction table_insert = nullptr;
  lua_CFunction table_remove = nullptr;
  lua_CFunction table_concat = nullptr;
  lua_CFunction table_unpack = nullptr;
  lua_CFunction coroutine_close = nullptr;

  bool active() const { return depth > 0; }
  std::size_t memory_left() const {
    return bytes < limits.memory_bytes ? limits.memory_bytes - bytes : 0;
  }
};

/// The host state of `L` (any of its coroutines).
HostState& host_of(lua_State* L);

/// Marks `kind` exhausted (first cause wins) with the message `where` (e.g.
/// "chunk:7: ") followed by the printf-formatted text. Never allocates.
void set_exhausted(HostState& host, ScriptError::Kind kind, const char* where, const char* format,
                   ...) __attribute__((format(printf, 4, 5)));

/// Raises the exhausted limit's message as a Lua error; does not return.
int raise_exhausted(lua_State* L);

/// Records that a memory error (status LUA_ERRMEM) was seen while a host
/// call runs, so that no pcall swallows it.
void note_memory_error(HostState& host, lua_State* L = nullptr);

/// Whether a limit is exhausted. A memory failure is first made the
/// exhausted limit, placed where the count hook last saw the script, else at
/// the Lua caller of the C function running in `L` (when given).
bool limit_exhausted(HostState& host, lua_State* L = nullptr);

/// Counts `units` instructions of work a library function (the C function
/// running in `L`) does, before it does it, and raises the budget's error,
/// placed at its Lua caller and naming `what` ("string.find: ..."), when
/// that passes the call's budget. Outside a host call it counts nothing.
void charge(lua_State* L, std::uint64_t units, const char* what);

/// Raises the wall-clock limit, placed at the Lua caller of the C function
/// running in `L`, when a host call has passed its deadline (or another
/// limit is exhausted); else returns. For library functions that can run
/// long between two of the count hook's looks (the pattern search).
void check_deadline(lua_State* L);

/// Writes "chunk:line: " of the first Lua function at `level` of L's stack
/// or above (a C function has no line) into `buffer`, empty when there is
/// none. Never allocates.
void write_where(lua_State* L, int level, char* buffer, std::size_t size);

}  // namespace dovetail::scripting
