#include "sandbox_env.h"

// Every function here is a lua_CFunction or is called by one. Lua raises
// errors with longjmp, which skips C++ destructors, so no object with a
// non-trivial destructor is ever in scope when an API function that can
// raise is called; the print log (a std::vector) is appended to in a
// noexcept helper that catches and reports failure instead.

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>

#include "host_state.h"

namespace dovetail::scripting {

namespace {

// Registry keys (their addresses): the environment, the table that numbers
// objects for tostring, and the mark in the metatable of a read-only library.
// Distinct values, so that no constant merging can give them one address.
const char kEnvKey = 'e';
const char kDisplayIdsKey = 'i';
const char kReadOnlyKey = 'r';

// ---- tostring and print: objects are named by serial number, not address

bool is_reference(int type) {
  return type == LUA_TTABLE || type == LUA_TFUNCTION || type == LUA_TTHREAD ||
         type == LUA_TUSERDATA || type == LUA_TLIGHTUSERDATA;
}

// Pushes the text of the value at `index` as tostring shows it.
void push_display_string(lua_State* L, int index) {
  index = lua_absindex(L, index);
  if (!is_reference(lua_type(L, index)) || luaL_getmetafield(L, index, "__tostring") != LUA_TNIL) {
    if (is_reference(lua_type(L, index))) lua_pop(L, 1);  // the __tostring field
    luaL_tolstring(L, index, nullptr);
    return;
  }
  const int base = lua_gettop(L);
  const char* kind = luaL_typename(L, index);
  if (luaL_getmetafield(L, index, "__name") == LUA_TSTRING) kind = lua_tostring(L, -1);
  lua_rawgetp(L, LUA_REGISTRYINDEX, &kDisplayIdsKey);
  lua_pushvalue(L, index);
  if (lua_rawget(L, -2) == LUA_TNIL) {
    lua_pop(L, 1);
    lua_pushvalue(L, index);
    lua_pushinteger(L, ++host_of(L).display_ids);
    lua_rawset(L, -3);
    lua_pushvalue(L, index);
    lua_rawget(L, -2);
  }
  const lua_Integer id = lua_tointeger(L, -1);
  lua_pushfstring(L, "%s: #%I", kind, static_cast<LUAI_UACINT>(id));
  lua_replace(L, base + 1);
  lua_settop(L, base + 1);
}

int sandbox_tostring(lua_State* L) {
  luaL_checkany(L, 1);
  push_display_string(L, 1);
  return 1;
}

// Appends a line to the print log; false when the log is full or the host
// is out of memory.
bool append_printed(HostState& host, const char* text, std::size_t length) noexcept {
  if (length > host.limits.memory_bytes - std::min(host.printed_bytes, host.limits.memory_bytes)) {
    return false;
  }
  try {
    host.printed.emplace_back(text, length);
  } catch (...) {
    return false;
  }
  host.printed_bytes += length;
  return true;
}

int sandbox_print(lua_State* L) {
  const int count = lua_gettop(L);
  luaL_Buffer line;
  luaL_buffinit(L, &line);
  for (int i = 1; i <= count; ++i) {
    if (i > 1) luaL_addchar(&line, '\t');
    push_display_string(L, i);
    luaL_addvalue(&line);
  }
  luaL_pushresult(&line);
  std::size_t length = 0;
  const char* text = lua_tolstring(L, -1, &length);
  HostState& host = host_of(L);
  if (!append_printed(host, text, length)) {
    char where[LUA_IDSIZE + 24];
    write_where(L, 1, where, sizeof(where));
    set_exhausted(host, ScriptError::Kind::kMemory, where,
                  "print: the captured output would exceed %zu bytes", host.limits.memory_bytes);
    return raise_exhausted(L);
  }
  return 0;
}

// ---- pairs in sorted key order

// One key of a table being iterated, as sorted: numbers, then strings, then
// booleans. `slot` is its place in the table of keys in traversal order.
struct SortKey {
  int rank;  // 0 number, 1 string, 2 boolean
  bool is_integer;
  lua_Integer integer;
  lua_Number number;
  const char* text;
  std::size_t length;
  lua_Integer slot;
};

// Exact order of an integer and a float (no rounding of either).
bool integer_less_than_float(lua_Integer i, lua_Number f) {
  constexpr lua_Number kTwo63 = 9223372036854775808.0;
  if (f >= kTwo63) return true;
  if (f < -kTwo63) return false;
  const lua_Number floor = std::floor(f);
  const auto floor_integer = static_cast<lua_Integer>(floor);
  return i < floor_integer || (i == floor_integer && floor < f);
}
bool float_less_than_integer(lua_Number f, lua_Integer i) {
  constexpr lua_Number kTwo63 = 9223372036854775808.0;
  if (f >= kTwo63) return false;
  if (f < -kTwo63) return true;
  const lua_Number ceil = std::ceil(f);
  const auto ceil_integer = static_cast<lua_Integer>(ceil);
  return ceil_integer < i || (ceil_integer == i && f < ceil);
}

bool key_less(const SortKey& a, const SortKey& b) {
  if (a.rank != b.rank) return a.rank < b.rank;
  switch (a.rank) {
    case 0:
      if (a.is_integer && b.is_integer) return a.integer < b.integer;
      if (a.is_integer) return integer_less_than_float(a.integer, b.number);
      if (b.is_integer) return float_less_than_integer(a.number, b.integer);
      return a.number < b.number;
    case 1: {
      const int order = std::memcmp(a.text, b.text, std::min(a.length, b.length));
      return order < 0 || (order == 0 && a.length < b.length);
    }
    default:
      return a.integer < b.integer;
  }
}

// Upvalues: the sorted keys, the position reached, the table.
int sorted_next(lua_State* L) {
  lua_Integer position = lua_tointeger(L, lua_upvalueindex(2));
  const auto count = static_cast<lua_Integer>(lua_rawlen(L, lua_upvalueindex(1)));
  while (position < count) {
    ++position;
    lua_rawgeti(L, lua_upvalueindex(1), position);
    lua_pushvalue(L, -1);
    if (lua_rawget(L, lua_upvalueindex(3)) != LUA_TNIL) {  // a key set to nil meanwhile is skipped
      lua_pushinteger(L, position);
      lua_replace(L, lua_upvalueindex(2));
      return 2;
    }
    lua_pop(L, 2);
  }
  lua_pushinteger(L, position);
  lua_replace(L, lua_upvalueindex(2));
  return 0;
}

// Pushes an iterator over the table at `index` in sorted key order.
void push_sorted_iterator(lua_State* L, int index) {
  index = lua_absindex(L, index);
  lua_Integer count = 0;
  lua_pushnil(L);
  while (lua_next(L, index) != 0) {
    const int type = lua_type(L, -2);
    if (type != LUA_TNUMBER && type != LUA_TSTRING && type != LUA_TBOOLEAN) {
      luaL_error(L,
                 "pairs: a table with a key of type %s has no defined order "
                 "(keys must be numbers, strings or booleans)",
                 luaL_typename(L, -2));
    }
    ++count;
    lua_pop(L, 1);
  }
  if (count > std::numeric_limits<int>::max()) luaL_error(L, "pairs: table too large");
  // Sorting the keys: about count * log2(count) comparisons, each call.
  const auto n = static_cast<std::uint64_t>(count);
  char what[96];
  std::snprintf(what, sizeof(what), "pairs: sorting the %llu keys of a table",
                static_cast<unsigned long long>(n));
  charge(L, n * (1 + static_cast<std::uint64_t>(std::bit_width(n))), what);
  lua_createtable(L, static_cast<int>(count), 0);  // keys in traversal order
  const int in_traversal_order = lua_gettop(L);
  auto* keys = static_cast<SortKey*>(
      lua_newuserdatauv(L, static_cast<std::size_t>(count) * sizeof(SortKey), 0));
  lua_Integer slot = 0;
  lua_pushnil(L);
  while (lua_next(L, index) != 0) {
    lua_pop(L, 1);
    SortKey& key = keys[slot++];
    key = SortKey{0, false, 0, 0, nullptr, 0, slot};
    switch (lua_type(L, -1)) {
      case LUA_TNUMBER:
        key.is_integer = lua_isinteger(L, -1) != 0;
        key.integer = key.is_integer ? lua_tointeger(L, -1) : 0;
        key.number = key.is_integer ? 0 : lua_tonumber(L, -1);
        break;
      case LUA_TSTRING:
        key.rank = 1;
        key.text = lua_tolstring(L, -1, &key.length);  // the table keeps the string alive
        break;
      default:
        key.rank = 2;
        key.integer = lua_toboolean(L, -1);
        break;
    }
    lua_pushvalue(L, -1);
    lua_rawseti(L, in_traversal_order, slot);
  }
  std::sort(keys, keys + count, key_less);
  lua_createtable(L, static_cast<int>(count), 0);
  for (lua_Integer i = 0; i < count; ++i) {
    lua_rawgeti(L, in_traversal_order, keys[i].slot);
    lua_rawseti(L, -2, i + 1);
  }
  lua_pushinteger(L, 0);
  lua_pushvalue(L, index);
  lua_pushcclosure(L, sorted_next, 3);
  lua_replace(L, in_traversal_order);
  lua_settop(L, in_traversal_order);
}

int pairs_continuation(lua_State*, int, lua_KContext) { return 3; }

int sandbox_pairs(lua_State* L) {
  luaL_checkany(L, 1);
  if (luaL_getmetafield(L, 1, "__pairs") != LUA_TNIL) {
    lua_pushvalue(L, 1);
    lua_callk(L, 1, 3, 0, pairs_continuation);
    return 3;
  }
  luaL_checktype(L, 1, LUA_TTABLE);
  push_sorted_iterator(L, 1);
  lua_pushvalue(L, 1);
  lua_pushnil(L);
  return 3;
}

// ---- pcall and xpcall: an exhausted limit is raised again, never returned

int finish_protected_call(lua_State* L, int status, lua_KContext extra) {
  if (status != LUA_OK && status != LUA_YIELD) {
    HostState& host = host_of(L);
    if (status == LUA_ERRMEM) note_memory_error(host, L);
    if (limit_exhausted(host, L)) return raise_exhausted(L);
    lua_pushboolean(L, 0);
    lua_pushvalue(L, -2);
    return 2;
  }
  return lua_gettop(L) - static_cast<int>(extra);
}

int sandbox_pcall(lua_State* L) {
  luaL_checkany(L, 1);
  lua_pushboolean(L, 1);  // the first result when all goes well
  lua_insert(L, 1);
  const int status = lua_pcallk(L, lua_gettop(L) - 2, LUA_MULTRET, 0, 0, finish_protected_call);
  return finish_protected_call(L, status, 0);
}

int sandbox_xpcall(lua_State* L) {
  const int count = lua_gettop(L);
  luaL_checktype(L, 2, LUA_TFUNCTION);
  lua_pushboolean(L, 1);
  lua_pushvalue(L, 1);
  lua_rotate(L, 3, 2);  // f, handler, true, f, arguments...
  const int status = lua_pcallk(L, count - 2, LUA_MULTRET, 2, 2, finish_protected_call);
  return finish_protected_call(L, status, 2);
}

// ---- load: text only, the sandbox environment by default

int sandbox_load(lua_State* L) {
  HostState& host = host_of(L);
  if (lua_gettop(L) < 4) {
    lua_settop(L, 3);
    push_sandbox_env(L);
  }
  lua_pushliteral(L, "t");
  lua_replace(L, 3);
  const int results = host.base_load(L);
  if (results == 2 && lua_isnil(L, -2) && lua_type(L, -1) == LUA_TSTRING &&
      std::strcmp(lua_tostring(L, -1), "not enough memory") == 0) {
    note_memory_error(host, L);
  }
  if (limit_exhausted(host, L)) return raise_exhausted(L);
  return results;
}

// ---- setmetatable and rawset guards

int sandbox_setmetatable(lua_State* L) {
  if (lua_type(L, 2) == LUA_TTABLE) {
    lua_pushliteral(L, "__gc");
    if (lua_rawget(L, 2) != LUA_TNIL) {
      return luaL_error(L, "setmetatable: __gc metamethods are not available in the sandbox");
    }
    lua_pop(L, 1);
  }
  return host_of(L).base_setmetatable(L);
}

bool is_read_only(lua_State* L, int index) {
  if (lua_type(L, index) != LUA_TTABLE || lua_getmetatable(L, index) == 0) return false;
  const bool read_only = lua_rawgetp(L, -1, &kReadOnlyKey) != LUA_TNIL;
  lua_pop(L, 2);
  return read_only;
}

int sandbox_rawset(lua_State* L) {
  if (is_read_only(L, 1)) return luaL_error(L, "rawset: library tables are read-only");
  return host_of(L).base_rawset(L);
}

// Upvalue: the library's name.
int read_only_newindex(lua_State* L) {
  const char* field = lua_type(L, 2) == LUA_TSTRING ? lua_tostring(L, 2) : luaL_typename(L, 2);
  return luaL_error(L, "attempt to modify read-only library '%s' (field '%s')",
                    lua_tostring(L, lua_upvalueindex(1)), field);
}

// Upvalue: the library table. The proxy, not the table, is the loop state.
int read_only_pairs(lua_State* L) {
  push_sorted_iterator(L, lua_upvalueindex(1));
  lua_pushvalue(L, 1);
  lua_pushnil(L);
  return 3;
}

// ---- string.rep and string.format

int sandbox_string_rep(lua_State* L) {
  std::size_t length = 0;
  std::size_t separator_length = 0;
  luaL_checklstring(L, 1, &length);
  const lua_Integer count = luaL_checkinteger(L, 2);
  luaL_optlstring(L, 3, "", &separator_length);
  if (count <= 0 || length + separator_length == 0) {
    lua_pushliteral(L, "");
    return 1;
  }
  HostState& host = host_of(L);
  // Building the result holds it twice (the buffer and the string).
  const double bytes = static_cast<double>(count) * static_cast<double>(length + separator_length) -
                       static_cast<double>(separator_length);
  if (2 * bytes > static_cast<double>(host.memory_left())) {
    lua_gc(L, LUA_GCCOLLECT, 0);
    if (2 * bytes > static_cast<double>(host.memory_left())) {
      char where[LUA_IDSIZE + 24];
      write_where(L, 1, where, sizeof(where));
      set_exhausted(host, ScriptError::Kind::kMemory, where,
                    "string.rep: a result of %.0f bytes exceeds the memory left (%zu of %zu "
                    "bytes; building it takes twice the result)",
                    bytes, host.memory_left(), host.limits.memory_bytes);
      return raise_exhausted(L);
    }
  }
  return host.string_rep(L);
}

// ---- string patterns: a bound on backtracking
//
// Lua's matcher backtracks over every repetition (`*`, `+`, `-`) that more
// pattern follows, and neither the instruction budget nor the wall-clock guard
// can stop it inside the library: ("a"):rep(3000):find(".-.-.-b") would run
// for hours. A search may try about (n + 1)^(r + 1) * 2^q positions for a
// subject of n characters, r such repetitions (a final `$` and a balance `%b`
// count: both can fail after scanning) and q optional items (`?`) that more
// pattern follows; the + 1 is every start. A pattern whose bound exceeds
// kMaxPatternSteps is refused before it runs, the same way on every run; the
// bounds of ordinary patterns on names and log lines are far below it.
// At about 6 ns a try, 10^8 tries are about 0.6 s; the wall clock is
// looked at again when the search returns (check_deadline), so a script of
// many long searches stops within one search of its limit.
constexpr double kMaxPatternSteps = 1e8;

/// What makes a pattern's search long (see above).
struct PatternCost {
  int repetitions = 0;  ///< r
  int optionals = 0;    ///< q
};

/// Index just past the set that starts at pattern[i] == '[' (Lua 5.4's
/// syntax: a ']' or an escape right after '[' or '[^' is a member).
std::size_t skip_set(const char* pattern, std::size_t length, std::size_t i) {
  ++i;
  if (i < length && pattern[i] == '^') ++i;
  do {
    i += i < length && pattern[i] == '%' ? 2 : 1;
  } while (i < length && pattern[i] != ']');
  return i + 1;
}

/// A malformed pattern is left to the matcher to report; the scan never
/// reads beyond `length`.
PatternCost pattern_cost(const char* pattern, std::size_t length) {
  std::size_t i = length > 0 && pattern[0] == '^' ? 1 : 0;
  PatternCost seen;     // so far
  PatternCost counted;  // of them, those another item follows
  while (i < length) {
    const char c = pattern[i];
    if (c == '(' || c == ')') {  // captures are not items
      ++i;
      continue;
    }
    counted = seen;                          // an item follows everything before it
    if (c == '$' && i + 1 == length) break;  // the anchor can fail: counted
    bool single = true;                      // an item a repetition can follow
    if (c == '%' && i + 1 < length && pattern[i + 1] == 'b') {
      i += 4, single = false;  // %bxy scans like a repetition and can fail at the end
      ++seen.repetitions;
      counted.repetitions = seen.repetitions;
    } else if (c == '%' && i + 1 < length && pattern[i + 1] == 'f') {
      i += 2, single = false;  // %f[set]
      if (i < length && pattern[i] == '[') i = skip_set(pattern, length, i);
    } else if (c == '%' && i + 1 < length && pattern[i + 1] >= '0' && pattern[i + 1] <= '9') {
      i += 2, single = false;  // a back-reference: a following '*' is a literal
    } else if (c == '%') {
      i += 2;  // a class or an escaped character
    } else if (c == '[') {
      i = skip_set(pattern, length, i);
    } else {
      ++i;
    }
    if (single && i < length && (pattern[i] == '*' || pattern[i] == '+' || pattern[i] == '-')) {
      ++seen.repetitions;
      ++i;
    } else if (single && i < length && pattern[i] == '?') {
      ++seen.optionals;
      ++i;
    }
  }
  return counted;
}

/// What a search (string.find, match, gmatch, gsub) may look at: the
/// characters from its start (argument 3 where it has one, as Lua reads it)
/// to the end of the subject, and the pattern's length; anchored (`^`) it
/// tries one start only.
struct SearchSpan {
  std::size_t span = 0;     ///< characters from the start to the end
  std::size_t pattern = 0;  ///< m
  bool anchored = false;
  bool repeats = false;  ///< a repetition: one start may run to the end
  /// The comparisons it may make: each start tries up to m characters, and
  /// a repetition may scan to the end once more. (Backtracking beyond that
  /// is bounded, and refused, by check_pattern.)
  double worst() const {
    const double m = static_cast<double>(std::max<std::size_t>(pattern, 1));
    const double starts = anchored ? 1 : static_cast<double>(span) + 1;
    return starts * m + (repeats ? static_cast<double>(span) : 0);
  }
};

SearchSpan search_span(lua_State* L, bool has_start, bool plain) {
  std::size_t n = 0;
  SearchSpan s;
  luaL_checklstring(L, 1, &n);
  const char* pattern = luaL_checklstring(L, 2, &s.pattern);
  lua_Integer start = has_start ? luaL_optinteger(L, 3, 1) : 1;
  const auto length = static_cast<lua_Integer>(n);
  if (start < 0) start = start < -length ? 1 : length + start + 1;
  if (start == 0) start = 1;
  s.span = start > length + 1 ? 0 : static_cast<std::size_t>(length - start + 1);
  s.anchored = !plain && s.pattern > 0 && pattern[0] == '^';
  s.repeats = !plain && pattern_cost(pattern, s.pattern).repetitions > 0;
  return s;
}

/// Comparisons as instructions, saturated.
std::uint64_t instructions_for(double compares) {
  return compares >= 1e19 ? std::numeric_limits<std::uint64_t>::max()
                          : static_cast<std::uint64_t>(compares) / kComparesPerInstruction;
}

/// Refuses, before it runs, a search whose worst case passes the budget
/// left, so that one search of hours never starts.
void refuse_search_past_budget(lua_State* L, const char* name, const SearchSpan& s) {
  const HostState& host = host_of(L);
  if (!host.active()) return;
  const std::uint64_t budget = host.limits.instructions_per_call;
  const std::uint64_t left =
      host.instructions_in_call < budget ? budget - host.instructions_in_call : 0;
  const std::uint64_t worst = instructions_for(s.worst());
  if (worst <= left) return;
  char what[160];
  std::snprintf(what, sizeof(what),
                "string.%s: a search of %zu characters for a pattern of %zu may compare %.3g "
                "characters",
                name, s.span, s.pattern, s.worst());
  charge(L, worst, what);
}

/// Counts what a search looked at: `compares` characters.
void charge_searched(lua_State* L, const char* name, double compares) {
  char what[96];
  std::snprintf(what, sizeof(what), "string.%s: %.3g characters compared", name, compares);
  charge(L, instructions_for(compares), what);
}

/// Raises the refusal when `pattern` (argument 2) on the subject (argument 1)
/// could search for very long.
void check_pattern(lua_State* L, const char* name) {
  std::size_t n = 0;
  std::size_t pattern_length = 0;
  luaL_checklstring(L, 1, &n);
  const char* pattern = luaL_checklstring(L, 2, &pattern_length);
  const PatternCost cost = pattern_cost(pattern, pattern_length);
  const double log_tries = (cost.repetitions + 1.0) * std::log(static_cast<double>(n) + 1.0) +
                           cost.optionals * std::log(2.0);
  if (cost.repetitions + cost.optionals > 0 && log_tries > std::log(kMaxPatternSteps)) {
    luaL_error(L,
               "string.%s: the pattern '%s' has %d repetitions and %d optional items that "
               "more pattern follows; on a subject of %I characters it could search for a "
               "very long time (the sandbox allows about 10^8 tries): shorten the subject "
               "or the pattern",
               name, pattern, cost.repetitions, cost.optionals, static_cast<LUAI_UACINT>(n));
  }
}

// The library's functions are called directly, in this function's own call,
// so their errors name the function and the caller's line as they would.
// The library's search, then the wall clock (check_deadline).
int timed_search(lua_State* L, lua_CFunction search) {
  const int results = search(L);
  check_deadline(L);
  return results;
}
// Each search is refused before it runs when its worst case passes the
// budget left, and charged after it for what it looked at: find up to where
// it matched, an anchored match the characters it returned, the others
// their worst case (gmatch for all its steps at once).
int sandbox_string_find(lua_State* L) {
  const bool plain = lua_toboolean(L, 4) != 0;
  if (!plain) check_pattern(L, "find");  // a plain search has no pattern
  const SearchSpan span = search_span(L, true, plain);
  refuse_search_past_budget(L, "find", span);
  std::size_t n = 0;
  lua_tolstring(L, 1, &n);
  const lua_Integer from = static_cast<lua_Integer>(n - span.span) + 1;
  const int results = timed_search(L, host_of(L).string_find);
  double compares = span.worst();
  if (!span.repeats && !span.anchored && lua_type(L, -results) == LUA_TNUMBER) {
    const lua_Integer at = lua_tointeger(L, -results);  // where it matched
    compares = static_cast<double>(at - from + 1) *
               static_cast<double>(std::max<std::size_t>(span.pattern, 1));
  }
  charge_searched(L, "find", compares);
  return results;
}
int sandbox_string_match(lua_State* L) {
  check_pattern(L, "match");
  const SearchSpan span = search_span(L, true, false);
  refuse_search_past_budget(L, "match", span);
  const int results = timed_search(L, host_of(L).string_match);
  double compares = span.worst();
  if (span.anchored) {
    // One start: it read what it returns, and the pattern.
    std::size_t returned = 0;
    for (int i = lua_gettop(L) - results + 1; i <= lua_gettop(L); ++i) {
      if (lua_type(L, i) == LUA_TSTRING) returned += lua_rawlen(L, i);
    }
    compares = static_cast<double>(returned + std::max<std::size_t>(span.pattern, 1));
  }
  charge_searched(L, "match", compares);
  return results;
}
// One step of a gmatch iterator: the library's (upvalue 1), then the
// wall clock, as after any other search.
int gmatch_step(lua_State* L) {
  const int base = lua_gettop(L);
  lua_pushvalue(L, lua_upvalueindex(1));
  lua_call(L, 0, LUA_MULTRET);
  check_deadline(L);
  return lua_gettop(L) - base;
}
int sandbox_string_gmatch(lua_State* L) {
  check_pattern(L, "gmatch");
  const SearchSpan span = search_span(L, true, false);
  refuse_search_past_budget(L, "gmatch", span);
  charge_searched(L, "gmatch", span.worst());  // for all its steps together
  const int results = host_of(L).string_gmatch(L);
  if (results != 1 || !lua_isfunction(L, -1)) return results;
  lua_pushcclosure(L, gmatch_step, 1);
  return 1;
}
int sandbox_string_gsub(lua_State* L) {
  check_pattern(L, "gsub");
  const SearchSpan span = search_span(L, false, false);
  refuse_search_past_budget(L, "gsub", span);
  charge_searched(L, "gsub", span.worst());
  return timed_search(L, host_of(L).string_gsub);
}

// ---- functions that read a string or a range of it: one instruction per
// kComparesPerInstruction characters

/// The characters from argument `i` to argument `j` of the string at
/// argument 1 (defaults `i_default` and `j_default`, negative from the
/// end, as the library reads them), clamped to the string.
std::size_t range_length(lua_State* L, int i, lua_Integer i_default, int j, lua_Integer j_default) {
  std::size_t n = 0;
  lua_tolstring(L, 1, &n);
  const auto length = static_cast<lua_Integer>(n);
  const auto position = [&](lua_Integer p) {
    if (p < 0) p = length + p + 1;
    return std::clamp<lua_Integer>(p, 1, length + 1);
  };
  const lua_Integer from = position(lua_isinteger(L, i) ? lua_tointeger(L, i) : i_default);
  const lua_Integer to =
      std::min(position(lua_isinteger(L, j) ? lua_tointeger(L, j) : j_default), length);
  return to >= from ? static_cast<std::size_t>(to - from + 1) : 0;
}

/// Charges `name` for reading `count` characters of the string at argument 1.
void charge_string(lua_State* L, const char* name, std::size_t count) {
  char what[96];
  std::snprintf(what, sizeof(what), "%s over %zu characters", name, count);
  charge(L, count / kComparesPerInstruction, what);
}
/// The same for the whole of it.
void charge_string(lua_State* L, const char* name) {
  if (lua_type(L, 1) != LUA_TSTRING) return;  // a number reads short; the library reports the rest
  charge_string(L, name, lua_rawlen(L, 1));
}
/// The same for string.byte's and utf8.codepoint's range: i (default 1)
/// to j (default i).
void charge_i_to_j(lua_State* L, const char* name) {
  if (lua_type(L, 1) != LUA_TSTRING) return;
  const lua_Integer i = lua_isinteger(L, 2) ? lua_tointeger(L, 2) : 1;
  charge_string(L, name, range_length(L, 2, 1, 3, i));
}
int sandbox_string_byte(lua_State* L) {
  charge_i_to_j(L, "string.byte");
  return host_of(L).string_byte(L);
}
int sandbox_utf8_len(lua_State* L) {
  if (lua_type(L, 1) == LUA_TSTRING) charge_string(L, "utf8.len", range_length(L, 2, 1, 3, -1));
  return host_of(L).utf8_len(L);
}
int sandbox_utf8_codepoint(lua_State* L) {
  charge_i_to_j(L, "utf8.codepoint");
  return host_of(L).utf8_codepoint(L);
}
int sandbox_utf8_offset(lua_State* L) {
  // It walks |n| characters from its start, at most the whole string.
  if (lua_type(L, 1) == LUA_TSTRING && lua_isinteger(L, 2)) {
    const lua_Integer steps = lua_tointeger(L, 2);
    const auto walked = steps == std::numeric_limits<lua_Integer>::min()
                            ? std::numeric_limits<lua_Unsigned>::max()
                            : static_cast<lua_Unsigned>(steps < 0 ? -steps : steps);
    charge_string(L, "utf8.offset",
                  static_cast<std::size_t>(std::min<lua_Unsigned>(walked, lua_rawlen(L, 1))));
  }
  return host_of(L).utf8_offset(L);
}
int sandbox_tonumber(lua_State* L) {
  charge_string(L, "tonumber");
  return host_of(L).base_tonumber(L);
}

// Names objects by serial number in '%s' and refuses '%p': both would
// otherwise show addresses, which differ from run to run.
int sandbox_string_format(lua_State* L) {
  std::size_t length = 0;
  const char* format = luaL_checklstring(L, 1, &length);
  int argument = 1;
  for (std::size_t i = 0; i < length; ++i) {
    if (format[i] != '%') continue;
    if (++i < length && format[i] == '%') continue;
    while (i < length && format[i] != '\0' && std::strchr("-+ #0", format[i]) != nullptr) ++i;
    while (i < length && format[i] >= '0' && format[i] <= '9') ++i;
    if (i < length && format[i] == '.') {
      ++i;
      while (i < length && format[i] >= '0' && format[i] <= '9') ++i;
    }
    if (i >= length) break;  // the library reports the malformed conversion
    ++argument;
    if (format[i] == 'p') {
      return luaL_error(L, "string.format: '%%p' is not available in the sandbox");
    }
    if (format[i] == 's' && argument <= lua_gettop(L) && is_reference(lua_type(L, argument))) {
      push_display_string(L, argument);
      lua_replace(L, argument);
    }
  }
  return host_of(L).string_format(L);
}

// ---- table functions: each element moved or visited counts as one instruction

/// Charges `name` one instruction per element from `first` to `last` (none
/// when last < first), saturated; `noun` names them ("elements").
void charge_elements(lua_State* L, lua_Integer first, lua_Integer last, const char* name,
                     const char* noun) {
  if (last < first) return;
  const lua_Unsigned span = static_cast<lua_Unsigned>(last) - static_cast<lua_Unsigned>(first);
  char what[80];
  std::snprintf(what, sizeof(what), "%s: %llu %s", name, static_cast<unsigned long long>(span) + 1,
                noun);
  charge(L, span == std::numeric_limits<lua_Unsigned>::max() ? span : span + 1, what);
}

int sandbox_table_move(lua_State* L) {
  const lua_Integer first = luaL_checkinteger(L, 2);
  const lua_Integer last = luaL_checkinteger(L, 3);
  charge_elements(L, first, last, "table.move", "elements");
  return host_of(L).table_move(L);
}

/// Charges `name` on the table at argument 1 for every element of it: what
/// insert and remove at a position shift, concat joins and unpack pushes is
/// at most that. Its length as the library takes it (its __len, if any:
/// a metamethod that claims 2^40 elements gets them counted).
void charge_table(lua_State* L, const char* name) {
  if (lua_type(L, 1) != LUA_TTABLE) return;  // the library reports it
  const lua_Integer length = luaL_len(L, 1);
  if (length <= 0) return;
  char what[80];
  std::snprintf(what, sizeof(what), "table.%s on a table of %lld elements", name,
                static_cast<long long>(length));
  charge(L, static_cast<std::uint64_t>(length), what);
}
int sandbox_table_insert(lua_State* L) {
  if (lua_gettop(L) >= 3) charge_table(L, "insert");  // at a position: shifts the rest
  return host_of(L).table_insert(L);
}
int sandbox_table_remove(lua_State* L) {
  if (lua_gettop(L) >= 2) charge_table(L, "remove");
  return host_of(L).table_remove(L);
}
int sandbox_table_concat(lua_State* L) {
  charge_table(L, "concat");
  return host_of(L).table_concat(L);
}
int sandbox_table_unpack(lua_State* L) {
  // The values pushed, from i to j as the library reads them (j defaults
  // to the length; bounds may reach past the table).
  const lua_Integer first = luaL_optinteger(L, 2, 1);
  const lua_Integer last = lua_isnoneornil(L, 3) ? luaL_len(L, 1) : luaL_checkinteger(L, 3);
  charge_elements(L, first, last, "table.unpack", "values");
  return host_of(L).table_unpack(L);
}

// ---- math.random and math.randomseed: the host's generator

// A uniform value in [0, range], by rejection of the bits above range's.
lua_Unsigned project(lua_Unsigned value, lua_Unsigned range, Xoshiro256& random) {
  if ((range & (range + 1)) == 0) return value & range;  // range + 1 is a power of two
  lua_Unsigned mask = range;
  for (int shift = 1; shift < 64; shift *= 2) mask |= mask >> shift;
  while ((value &= mask) > range) value = random.next();
  return value;
}

int sandbox_random(lua_State* L) {
  Xoshiro256& random = host_of(L).random;
  const std::uint64_t value = random.next();
  lua_Integer low = 1;
  lua_Integer up = 0;
  switch (lua_gettop(L)) {
    case 0:
      lua_pushnumber(L, static_cast<lua_Number>(value >> 11) * 0x1.0p-53);
      return 1;
    case 1:
      up = luaL_checkinteger(L, 1);
      if (up == 0) {  // random(0): all bits
        lua_pushinteger(L, static_cast<lua_Integer>(value));
        return 1;
      }
      break;
    case 2:
      low = luaL_checkinteger(L, 1);
      up = luaL_checkinteger(L, 2);
      break;
    default:
      return luaL_error(L, "wrong number of arguments");
  }
  luaL_argcheck(L, low <= up, 1, "interval is empty");
  const lua_Unsigned range = static_cast<lua_Unsigned>(up) - static_cast<lua_Unsigned>(low);
  lua_pushinteger(
      L, static_cast<lua_Integer>(project(value, range, random) + static_cast<lua_Unsigned>(low)));
  return 1;
}

// randomseed() restarts the host's sequence; randomseed(x [, y]) seeds with
// the integers x and y.
int sandbox_randomseed(lua_State* L) {
  HostState& host = host_of(L);
  if (lua_isnone(L, 1)) {
    host.random.reseed(host.seed);
  } else {
    const lua_Integer seed = luaL_checkinteger(L, 1);
    const lua_Integer stream = luaL_optinteger(L, 2, 0);
    host.random.reseed(static_cast<std::uint64_t>(seed), static_cast<std::uint64_t>(stream));
  }
  return 0;
}

// ---- coroutines: a limit exhausted inside a coroutine ends the caller too

// Resumes `co` with the `count` values on top of L. Returns the number of
// results moved to L, or -1 with the error object on top of L.
int resume(lua_State* L, lua_State* co, int count) {
  if (!lua_checkstack(co, count)) {
    lua_pop(L, count);
    lua_pushliteral(L, "too many arguments to resume");
    return -1;
  }
  lua_xmove(L, co, count);
  int results = 0;
  HostState& host = host_of(L);
  lua_State* const outer = host.running;
  host.running = co;
  const int status = lua_resume(co, L, count, &results);
  host.running = outer;
  if (status == LUA_OK || status == LUA_YIELD) {
    if (!lua_checkstack(L, results + 1)) {
      lua_pop(co, results);
      lua_pushliteral(L, "too many results to resume");
      return -1;
    }
    lua_xmove(co, L, results);
    return results;
  }
  if (status == LUA_ERRMEM) note_memory_error(host, L);
  lua_xmove(co, L, 1);
  return -1;
}

int sandbox_resume(lua_State* L) {
  lua_State* co = lua_tothread(L, 1);
  luaL_argexpected(L, co != nullptr, 1, "coroutine");
  const int results = resume(L, co, lua_gettop(L) - 1);
  if (limit_exhausted(host_of(L), L)) return raise_exhausted(L);
  if (results < 0) {
    lua_pushboolean(L, 0);
    lua_insert(L, -2);
    return 2;
  }
  lua_pushboolean(L, 1);
  lua_insert(L, -(results + 1));
  return results + 1;
}

// Upvalue: the coroutine.
int wrapped_coroutine(lua_State* L) {
  lua_State* co = lua_tothread(L, lua_upvalueindex(1));
  const int results = resume(L, co, lua_gettop(L));
  HostState& host = host_of(L);
  if (limit_exhausted(host, L)) return raise_exhausted(L);
  if (results >= 0) return results;
  int status = lua_status(co);
  if (status != LUA_OK && status != LUA_YIELD) {  // the coroutine died: close its variables
    status = lua_resetthread(co);
    lua_pop(L, 1);
    lua_xmove(co, L, 1);
    if (status == LUA_ERRMEM) note_memory_error(host, L);
    if (limit_exhausted(host, L)) return raise_exhausted(L);
  }
  if (status != LUA_ERRMEM && lua_type(L, -1) == LUA_TSTRING) {
    luaL_where(L, 1);
    lua_insert(L, -2);
    lua_concat(L, 2);
  }
  return lua_error(L);
}

int sandbox_wrap(lua_State* L) {
  luaL_checktype(L, 1, LUA_TFUNCTION);
  lua_State* co = lua_newthread(L);  // inherits the count hook
  lua_pushvalue(L, 1);
  lua_xmove(L, co, 1);
  lua_pushcclosure(L, wrapped_coroutine, 1);
  return 1;
}

int sandbox_close(lua_State* L) {
  HostState& host = host_of(L);
  const int results = host.coroutine_close(L);
  if (limit_exhausted(host, L)) return raise_exhausted(L);
  return results;
}

// ---- table.sort: a stable merge sort, in Lua so that it is counted by the
// hook and its comparator may yield

constexpr const char* kSortSource = R"lua(
local type, error = ...

local function less_than(a, b) return a < b end

local function sort(list, comp)
  if type(list) ~= "table" then
    error("bad argument #1 to 'sort' (table expected, got " .. type(list) .. ")", 2)
  end
  if comp ~= nil and type(comp) ~= "function" then
    error("bad argument #2 to 'sort' (function expected, got " .. type(comp) .. ")", 2)
  end
  local n = #list
  if n < 2 then return end
  local lt = comp or less_than
  if comp and comp(list[1], list[1]) then
    error("invalid order function for sorting (comp(a, a) is true)", 2)
  end
  local from, to = {}, {}
  for i = 1, n do from[i] = list[i] end
  local width = 1
  while width < n do
    local low = 1
    while low <= n do
      local middle = low + width
      if middle > n + 1 then middle = n + 1 end
      local high = middle + width
      if high > n + 1 then high = n + 1 end
      local left, right, k = low, middle, low
      while left < middle and right < high do
        if lt(from[right], from[left]) then
          to[k] = from[right]
          right = right + 1
        else
          to[k] = from[left]
          left = left + 1
        end
        k = k + 1
      end
      while left < middle do
        to[k] = from[left]
        left, k = left + 1, k + 1
      end
      while right < high do
        to[k] = from[right]
        right, k = right + 1, k + 1
      end
      low = high
    end
    from, to = to, from
    width = width * 2
  end
  if comp then
    for i = 1, n - 1 do
      if comp(from[i + 1], from[i]) then error("invalid order function for sorting", 2) end
    end
  end
  for i = 1, n do list[i] = from[i] end
end

return sort
)lua";

// ---- building the environment

// Pushes a shallow copy of the table at `index`, without the field `omit`.
void push_copy(lua_State* L, int index, const char* omit = nullptr) {
  index = lua_absindex(L, index);
  lua_newtable(L);
  lua_pushnil(L);
  while (lua_next(L, index) != 0) {
    if (omit != nullptr && lua_type(L, -2) == LUA_TSTRING &&
        std::strcmp(lua_tostring(L, -2), omit) == 0) {
      lua_pop(L, 1);
      continue;
    }
    lua_pushvalue(L, -2);
    lua_insert(L, -2);
    lua_rawset(L, -4);
  }
}

// Pushes a read-only proxy of the library table at `index`.
void push_read_only(lua_State* L, int index, const char* name) {
  index = lua_absindex(L, index);
  lua_newtable(L);
  lua_createtable(L, 0, 5);
  lua_pushvalue(L, index);
  lua_setfield(L, -2, "__index");
  lua_pushstring(L, name);
  lua_pushcclosure(L, read_only_newindex, 1);
  lua_setfield(L, -2, "__newindex");
  lua_pushvalue(L, index);
  lua_pushcclosure(L, read_only_pairs, 1);
  lua_setfield(L, -2, "__pairs");
  lua_pushliteral(L, "read-only library");
  lua_setfield(L, -2, "__metatable");
  lua_pushboolean(L, 1);
  lua_rawsetp(L, -2, &kReadOnlyKey);
  lua_setmetatable(L, -2);
}

lua_CFunction library_function(lua_State* L, int library, const char* name) {
  lua_getfield(L, library, name);
  const lua_CFunction function = lua_tocfunction(L, -1);
  lua_pop(L, 1);
  if (function == nullptr) luaL_error(L, "sandbox: the library has no C function '%s'", name);
  return function;
}

// Opens a standard library into the host's own globals and pushes it.
int open_library(lua_State* L, const char* name, lua_CFunction open) {
  luaL_requiref(L, name, open, 1);
  return lua_gettop(L);
}

}  // namespace

void push_sandbox_env(lua_State* L) { lua_rawgetp(L, LUA_REGISTRYINDEX, &kEnvKey); }

int open_sandbox(lua_State* L) {
  HostState& host = host_of(L);
  const int base = open_library(L, LUA_GNAME, luaopen_base);
  const int string = open_library(L, LUA_STRLIBNAME, luaopen_string);
  const int table = open_library(L, LUA_TABLIBNAME, luaopen_table);
  const int math = open_library(L, LUA_MATHLIBNAME, luaopen_math);
  const int utf8 = open_library(L, LUA_UTF8LIBNAME, luaopen_utf8);
  const int coroutine = open_library(L, LUA_COLIBNAME, luaopen_coroutine);
  host.base_load = library_function(L, base, "load");
  host.base_setmetatable = library_function(L, base, "setmetatable");
  host.base_rawset = library_function(L, base, "rawset");
  host.string_rep = library_function(L, string, "rep");
  host.string_format = library_function(L, string, "format");
  host.string_find = library_function(L, string, "find");
  host.string_match = library_function(L, string, "match");
  host.string_gmatch = library_function(L, string, "gmatch");
  host.string_gsub = library_function(L, string, "gsub");
  host.string_byte = library_function(L, string, "byte");
  host.utf8_len = library_function(L, utf8, "len");
  host.utf8_codepoint = library_function(L, utf8, "codepoint");
  host.utf8_offset = library_function(L, utf8, "offset");
  host.base_tonumber = library_function(L, base, "tonumber");
  host.table_move = library_function(L, table, "move");
  host.table_insert = library_function(L, table, "insert");
  host.table_remove = library_function(L, table, "remove");
  host.table_concat = library_function(L, table, "concat");
  host.table_unpack = library_function(L, table, "unpack");
  host.coroutine_close = library_function(L, coroutine, "close");

  lua_newtable(L);  // tostring's serial numbers, weak so objects still die
  lua_createtable(L, 0, 1);
  lua_pushliteral(L, "k");
  lua_setfield(L, -2, "__mode");
  lua_setmetatable(L, -2);
  lua_rawsetp(L, LUA_REGISTRYINDEX, &kDisplayIdsKey);

  lua_createtable(L, 0, 32);
  const int env = lua_gettop(L);
  for (const char* name : {"assert", "error", "ipairs", "select", "type", "rawequal", "rawget",
                           "rawlen", "getmetatable", "_VERSION"}) {
    lua_getfield(L, base, name);
    lua_setfield(L, env, name);
  }
  static const luaL_Reg kBase[] = {{"pairs", sandbox_pairs},
                                   {"tostring", sandbox_tostring},
                                   {"print", sandbox_print},
                                   {"pcall", sandbox_pcall},
                                   {"xpcall", sandbox_xpcall},
                                   {"load", sandbox_load},
                                   {"setmetatable", sandbox_setmetatable},
                                   {"rawset", sandbox_rawset},
                                   {"tonumber", sandbox_tonumber},
                                   {nullptr, nullptr}};
  luaL_setfuncs(L, kBase, 0);
  lua_pushvalue(L, env);
  lua_setfield(L, env, "_G");

  // string: no dump; rep and format guarded. Strings' methods come from the
  // copy itself: the string metatable is protected, so scripts cannot reach
  // it to change it.
  push_copy(L, string, "dump");
  static const luaL_Reg kString[] = {
      {"rep", sandbox_string_rep},       {"format", sandbox_string_format},
      {"find", sandbox_string_find},     {"match", sandbox_string_match},
      {"gmatch", sandbox_string_gmatch}, {"gsub", sandbox_string_gsub},
      {"byte", sandbox_string_byte},     {nullptr, nullptr}};
  luaL_setfuncs(L, kString, 0);
  lua_pushliteral(L, "");
  lua_getmetatable(L, -1);
  lua_pushvalue(L, -3);
  lua_setfield(L, -2, "__index");
  lua_pushliteral(L, "protected metatable");
  lua_setfield(L, -2, "__metatable");
  lua_pop(L, 2);
  push_read_only(L, -1, "string");
  lua_setfield(L, env, "string");
  lua_pop(L, 1);

  // table: the stable sort; move, insert, remove, concat and unpack counted.
  push_copy(L, table);
  if (luaL_loadbufferx(L, kSortSource, std::strlen(kSortSource), "=[table.sort]", "t") != LUA_OK) {
    return lua_error(L);
  }
  lua_pushnil(L);
  lua_setupvalue(L, -2, 1);  // no globals
  lua_getfield(L, base, "type");
  lua_getfield(L, base, "error");
  lua_call(L, 2, 1);
  lua_setfield(L, -2, "sort");
  static const luaL_Reg kTable[] = {
      {"move", sandbox_table_move},     {"insert", sandbox_table_insert},
      {"remove", sandbox_table_remove}, {"concat", sandbox_table_concat},
      {"unpack", sandbox_table_unpack}, {nullptr, nullptr}};
  luaL_setfuncs(L, kTable, 0);
  push_read_only(L, -1, "table");
  lua_setfield(L, env, "table");
  lua_pop(L, 1);

  push_copy(L, math);
  static const luaL_Reg kMath[] = {
      {"random", sandbox_random}, {"randomseed", sandbox_randomseed}, {nullptr, nullptr}};
  luaL_setfuncs(L, kMath, 0);
  push_read_only(L, -1, "math");
  lua_setfield(L, env, "math");
  lua_pop(L, 1);

  push_copy(L, utf8);
  static const luaL_Reg kUtf8[] = {{"len", sandbox_utf8_len},
                                   {"codepoint", sandbox_utf8_codepoint},
                                   {"offset", sandbox_utf8_offset},
                                   {nullptr, nullptr}};
  luaL_setfuncs(L, kUtf8, 0);
  push_read_only(L, -1, "utf8");
  lua_setfield(L, env, "utf8");
  lua_pop(L, 1);

  push_copy(L, coroutine);
  static const luaL_Reg kCoroutine[] = {{"resume", sandbox_resume},
                                        {"wrap", sandbox_wrap},
                                        {"close", sandbox_close},
                                        {nullptr, nullptr}};
  luaL_setfuncs(L, kCoroutine, 0);
  push_read_only(L, -1, "coroutine");
  lua_setfield(L, env, "coroutine");
  lua_pop(L, 1);

  lua_createtable(L, 0, 1);
  lua_pushliteral(L, "the sandbox environment's metatable is protected");
  lua_setfield(L, -2, "__metatable");
  lua_setmetatable(L, env);
  lua_pushvalue(L, env);
  lua_rawsetp(L, LUA_REGISTRYINDEX, &kEnvKey);
  lua_settop(L, 0);
  return 0;
}

}  // namespace dovetail::scripting
