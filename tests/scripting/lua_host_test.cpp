#include "dovetail/scripting/lua_host.h"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <lua.hpp>
#include <string>

#include "../support/temp_dir.h"

namespace dovetail::scripting {
namespace {

using Kind = ScriptError::Kind;

SandboxLimits small_limits() {
  SandboxLimits limits;
  limits.instructions_per_call = 1'000'000;
  limits.memory_bytes = 16u << 20;
  limits.wall_seconds_per_call = 2.0;
  return limits;
}

// Runs `code` and returns its one result as text.
std::string run(LuaHost& host, const std::string& code, const std::string& name = "test.lua") {
  lua_State* L = host.state();
  host.run_string(code, name, 1);
  std::size_t length = 0;
  const char* text = lua_tolstring(L, -1, &length);
  std::string result = text != nullptr ? std::string(text, length) : "<not a string>";
  lua_pop(L, 1);
  return result;
}

// Runs `code`, which must fail, and returns the error.
ScriptError run_error(LuaHost& host, const std::string& code,
                      const std::string& name = "script.lua") {
  const int top = lua_gettop(host.state());
  try {
    host.run_string(code, name, 0);
  } catch (const ScriptError& error) {
    EXPECT_EQ(lua_gettop(host.state()), top) << "the stack is left as it was";
    return error;
  }
  ADD_FAILURE() << "no error from: " << code;
  return ScriptError(Kind::kRuntime, "");
}

// The error of running `file`, as run_error's of a string.
ScriptError run_file_error(LuaHost& host, const std::filesystem::path& file) {
  const int top = lua_gettop(host.state());
  try {
    host.run_file(file, 0);
  } catch (const ScriptError& error) {
    EXPECT_EQ(lua_gettop(host.state()), top) << "the stack is left as it was";
    return error;
  }
  ADD_FAILURE() << "no error from " << file;
  return ScriptError(Kind::kRuntime, "");
}

// A fresh chunk still runs correctly on `host`.
void expect_works(LuaHost& host) {
  EXPECT_EQ(
      run(host,
          "local t = {} for i = 1, 5 do t[#t + 1] = ('%d'):format(i * i) end\n"
          "local ok, sum = pcall(function() local s = 0 for _, v in ipairs(t) do s = s + v end "
          "return s end)\n"
          "return table.concat(t, ',') .. ' ' .. sum .. ' ' .. string.rep('ab', 2)"),
      "1,4,9,16,25 55 abab");
}

// ---- 1. the environment

TEST(LuaHostEnv, OnlyTheWhitelistIsGlobal) {
  LuaHost host(small_limits(), 1);
  EXPECT_EQ(run(host,
                "local names = {} for k in pairs(_G) do names[#names + 1] = k end "
                "return table.concat(names, ' ')"),
            "_G _VERSION assert coroutine error getmetatable ipairs load math pairs pcall print "
            "rawequal rawget rawlen rawset select setmetatable string table tonumber tostring type "
            "utf8 xpcall");
  EXPECT_EQ(run(host, "return tostring(_G == _ENV)"), "true");
}

TEST(LuaHostEnv, DangerousNamesAreAbsent) {
  LuaHost host(small_limits(), 1);
  for (const char* name : {"io", "os", "package", "debug", "require", "dofile", "loadfile",
                           "collectgarbage", "next", "loadstring", "unpack", "string.dump"}) {
    EXPECT_EQ(run(host, std::string("return tostring(") + name + ")"), "nil") << name;
  }
}

TEST(LuaHostEnv, HostileCallsFailNamingWhatIsMissing) {
  LuaHost host(small_limits(), 1);
  const std::pair<const char*, const char*> cases[] = {
      {"os.exit()", "global 'os'"},
      {"io.open('/etc/passwd')", "global 'io'"},
      {"require'x'", "global 'require'"},
      {"debug.sethook()", "global 'debug'"},
      {"package.loadlib('libc.so.6', 'system')", "global 'package'"},
      {"string.dump(print)", "field 'dump'"},
      {"collectgarbage('stop')", "global 'collectgarbage'"}};
  for (const auto& [code, expected] : cases) {
    const ScriptError error = run_error(host, code);
    EXPECT_EQ(error.kind(), Kind::kRuntime) << code;
    EXPECT_NE(error.message().find(expected), std::string::npos) << error.message();
    EXPECT_EQ(error.message().rfind("script.lua:1:", 0), 0u) << error.message();
  }
  expect_works(host);
}

TEST(LuaHostEnv, LibrariesAreReadOnly) {
  LuaHost host(small_limits(), 1);
  const std::pair<const char*, const char*> cases[] = {
      {"string.rep = nil", "read-only library 'string' (field 'rep')"},
      {"math.random = function() return 4 end", "read-only library 'math' (field 'random')"},
      {"table.sort = nil", "read-only library 'table'"},
      {"coroutine.resume = nil", "read-only library 'coroutine'"},
      {"utf8.char = nil", "read-only library 'utf8'"},
      {"string.extra = 1", "read-only library 'string' (field 'extra')"},
      {"rawset(string, 'rep', nil)", "read-only"},
      {"setmetatable(math, nil)", "protected metatable"},
      {"getmetatable('').__index = {}", "attempt to index"},
      {"setmetatable(getmetatable(string), nil)", "bad argument"}};
  for (const auto& [code, expected] : cases) {
    const ScriptError error = run_error(host, code);
    EXPECT_NE(error.message().find(expected), std::string::npos) << code << " -> " << error.what();
  }
  EXPECT_EQ(run(host, "return ('x'):rep(3) .. math.type(math.random(5)) .. #table.pack(1, 2)"),
            "xxxinteger2");
  EXPECT_EQ(run(host, "return getmetatable('') .. ' ' .. getmetatable(string)"),
            "protected metatable read-only library");
  // The libraries can still be listed, in order.
  EXPECT_EQ(run(host,
                "local n = {} for k in pairs(utf8) do n[#n + 1] = k end "
                "return table.concat(n, ' ')"),
            "char charpattern codepoint codes len offset");
}

TEST(LuaHostEnv, EnvironmentMetatableIsProtected) {
  LuaHost host(small_limits(), 1);
  const ScriptError error = run_error(host, "setmetatable(_G, nil)");
  EXPECT_NE(error.message().find("cannot change a protected metatable"), std::string::npos)
      << error.what();
  EXPECT_EQ(run(host, "return getmetatable(_G)"),
            "the sandbox environment's metatable is protected");
  // Globals themselves belong to the scripts and persist between chunks.
  host.run_string("counter = 41", "a.lua", 0);
  EXPECT_EQ(run(host, "counter = counter + 1 return tostring(counter)"), "42");
}

TEST(LuaHostEnv, StringMethodsComeFromTheSandboxLibrary) {
  LuaHost host(small_limits(), 1);
  EXPECT_EQ(run(host, "return ('ab'):rep(3, '-') .. ('%d'):format(7) .. ('XY'):lower()"),
            "ab-ab-ab7xy");
  EXPECT_EQ(run(host, "return tostring(('x').dump)"), "nil");
  EXPECT_EQ(run(host, "return tostring(string.rep('', 2^62))"), "");
  EXPECT_EQ(run(host, "return tostring(('x'):rep(0) == '')"), "true");
}

TEST(LuaHostEnv, GcMetamethodsAreRefused) {
  LuaHost host(small_limits(), 1);
  const ScriptError error = run_error(host, "setmetatable({}, {__gc = function() end})");
  EXPECT_NE(error.message().find("__gc"), std::string::npos) << error.what();
  EXPECT_EQ(run(host, "return tostring(setmetatable({}, {__index = {x = 3}}).x)"), "3");
}

TEST(LuaHostEnv, PrintIsCapturedNeverWritten) {
  LuaHost host(small_limits(), 1);
  testing::internal::CaptureStdout();
  host.run_string(
      "print('a', 1, nil, true, 2.5) print() print(setmetatable({}, "
      "{__tostring = function() return 'custom' end}))",
      "p.lua", 0);
  EXPECT_EQ(testing::internal::GetCapturedStdout(), "");
  ASSERT_EQ(host.printed().size(), 3u);
  EXPECT_EQ(host.printed()[0], "a\t1\tnil\ttrue\t2.5");
  EXPECT_EQ(host.printed()[1], "");
  EXPECT_EQ(host.printed()[2], "custom");
  host.clear_printed();
  EXPECT_TRUE(host.printed().empty());
}

TEST(LuaHostEnv, PrintLogIsCapped) {
  LuaHost host(small_limits(), 1);
  const ScriptError error =
      run_error(host, "local s = ('x'):rep(1 << 20)\nfor i = 1, 100 do print(s) end");
  EXPECT_EQ(error.kind(), Kind::kMemory);
  EXPECT_EQ(error.message().rfind("script.lua:2: print: the captured output", 0), 0u)
      << error.message();
  EXPECT_LE(host.printed().size(), 16u);
  host.clear_printed();
  expect_works(host);
}

TEST(LuaHostEnv, ObjectsAreNamedBySerialNumberNotAddress) {
  LuaHost host(small_limits(), 1);
  EXPECT_EQ(run(host,
                "local t = {} return tostring(t) .. ' ' .. tostring(print) .. ' ' .. "
                "tostring(t) .. ' ' .. string.format('%s|%5.1f', {}, 1)"),
            "table: #1 function: #2 table: #1 table: #3|  1.0");
  const ScriptError error = run_error(host, "return string.format('%p', {})");
  EXPECT_NE(error.message().find("'%p' is not available"), std::string::npos) << error.what();
}

TEST(LuaHostEnv, LoadIsTextOnlyInTheSandbox) {
  LuaHost host(small_limits(), 1);
  EXPECT_EQ(run(host, "return tostring(load('return os, string.rep ~= nil')())"), "nil");
  EXPECT_EQ(run(host, "return tostring(select(2, load('return os, string.rep ~= nil')()))"),
            "true");
  EXPECT_EQ(run(host, "return select(2, load('x = = 1', '=chunk'))"),
            "chunk:1: unexpected symbol near '='");
  EXPECT_EQ(run(host, "local env = {y = 5} return tostring(load('return y', 'c', 'b', env)())"),
            "5");
  const ScriptError error = run_error(host, "assert(load('\\27Lua\\84\\0'))");
  EXPECT_NE(error.message().find("attempt to load a binary chunk (mode is 't')"), std::string::npos)
      << error.what();
  expect_works(host);
}

// ---- 2. instruction budget and wall-clock guard, also inside coroutines

TEST(LuaHostBudget, InfiniteLoopEndsWithBudgetError) {
  LuaHost host(small_limits(), 1);
  const ScriptError error = run_error(host, "local x = 0\nwhile true do x = x + 1 end");
  EXPECT_EQ(error.kind(), Kind::kBudget);
  EXPECT_EQ(error.message(), "script.lua:2: instruction budget of 1000000 exceeded");
  EXPECT_NE(std::string(error.what()).find("\nstack traceback:\n"), std::string::npos);
  EXPECT_GE(host.instructions_used(), 1'000'000u);
  expect_works(host);
}

// Library work the count hook does not see meets the budget too, the same
// way on every machine: with no wall-clock guard to speak of (1000 s), each
// of these stops on the budget, at its own line, naming what spent it.
TEST(LuaHostBudget, LibraryWorkCountsAgainstTheBudget) {
  SandboxLimits limits = small_limits();
  limits.wall_seconds_per_call = 1000;
  struct Case {
    const char* script;
    const char* names;
  };
  const Case cases[] = {
      // One search comparing 10^10 characters: refused before it runs.
      {"local s = ('a'):rep(1 << 20)\nreturn s:find(('a'):rep(10000) .. 'b', 1, true)",
       "script.lua:2: instruction budget of 1000000 exceeded (string.find: a search of 1048576 "
       "characters for a pattern of 10001 may compare 1.05e+10 characters)"},
      {"local s = ('a'):rep(1 << 20)\nreturn s:gsub(('a'):rep(10000) .. 'b', '')",
       "(string.gsub: a search of 1048576"},
      // Sorting 100,000 keys for every pairs: a few calls spend the budget.
      {"local t = {}\nfor i = 1, 100000 do t['k' .. i] = i end\n"
       "for _ = 1, 100 do for k in pairs(t) do break end end",
       "script.lua:3: instruction budget of 1000000 exceeded (pairs: sorting the 100000 keys"},
      // Each insert at the front shifts the whole table.
      {"local t = {}\nfor i = 1, 100000 do t[i] = i end\n"
       "for i = 1, 1000 do table.insert(t, 1, i) end",
       "script.lua:3: instruction budget of 1000000 exceeded (table.insert on a table of"},
      {"local t = {}\nfor i = 1, 100000 do t[i] = i end\n"
       "for i = 1, 1000 do table.remove(t, 1) end",
       "(table.remove on a table of"},
      {"local t = {}\nfor i = 1, 100000 do t[i] = 'x' end\n"
       "for i = 1, 1000 do local s = table.concat(t) end",
       "(table.concat on a table of 100000 elements)"},
      {"local t = {}\nfor i = 1, 100000 do t[i] = i end\n"
       "for i = 1, 1000 do local a = select('#', table.unpack(t)) end",
       "(table.unpack: 100000 values)"},
      {"local s = ('7'):rep(1 << 20)\nfor i = 1, 1000 do local x = tonumber(s) end",
       "(tonumber over 1048576 characters)"},
      {"local s = ('x'):rep(1 << 20)\nfor i = 1, 1000 do local n = utf8.len(s) end",
       "(utf8.len over 1048576 characters)"},
      // A __len that claims 2^40 elements has them counted, as the library
      // shifts them; float bounds count as integer ones.
      {"local t = setmetatable({}, { __len = function() return 1 << 40 end })\n"
       "table.insert(t, 1, 0)",
       "script.lua:2: instruction budget of 1000000 exceeded (table.insert on a table of "
       "1099511627776 elements)"},
      {"local t = setmetatable({}, { __len = function() return 1 << 40 end })\n"
       "table.remove(t, 1)",
       "(table.remove on a table of 1099511627776 elements)"},
      {"local t = {}\nfor i = 1, 100 do local a = select('#', table.unpack(t, 1, 100000.0)) end",
       "script.lua:2: instruction budget of 1000000 exceeded (table.unpack: 100000 values)"},
  };
  for (const Case& c : cases) {
    LuaHost host(limits, 1);
    const ScriptError error = run_error(host, c.script);
    EXPECT_EQ(error.kind(), Kind::kBudget) << c.script << " -> " << error.what();
    EXPECT_NE(error.message().find(c.names), std::string::npos) << error.message();
  }
}

// A search is charged for what it looked at: a tokenizer that finds each
// next space from where it is reads the string once, however long.
TEST(LuaHostBudget, ALinearScanOfFindsIsChargedLinearly) {
  SandboxLimits limits = small_limits();
  limits.wall_seconds_per_call = 1000;
  LuaHost host(limits, 1);
  EXPECT_EQ(run(host,
                "local s = ('ab '):rep(40000)\n"
                "local n, at = 0, 1\n"
                "while true do\n"
                "  local space = s:find(' ', at, true)\n"
                "  if not space then break end\n"
                "  n, at = n + 1, space + 1\n"
                "end\n"
                "local bytes = 0\n"
                "for i = 1, #s, 3 do bytes = bytes + s:byte(i, i + 2) end\n"
                "return tostring(n)"),
            "40000");
}

// Copying a long string (a `..` is one instruction) counts by the bytes
// copied: a loop that copies a megabyte a turn stops on the budget.
TEST(LuaHostBudget, CopyingIntoNewMemoryCountsAgainstTheBudget) {
  SandboxLimits limits = small_limits();
  limits.wall_seconds_per_call = 1000;
  LuaHost host(limits, 1);
  const ScriptError error =
      run_error(host, "local s = ('x'):rep(1 << 20)\nfor i = 1, 1e9 do local t = s .. i end");
  EXPECT_EQ(error.kind(), Kind::kBudget) << error.what();
  EXPECT_EQ(error.message().rfind("script.lua:2: instruction budget of 1000000 exceeded", 0), 0u)
      << error.message();
  // About 1000000 / (2^20 / 64) = 61 turns, not the 1000000 / 4 that
  // counting the loop's instructions alone would allow.
  EXPECT_LT(host.instructions_used(), 2'000'000u);
  expect_works(host);
}

TEST(LuaHostSandbox, ANameLeftOutSaysWhy) {
  LuaHost host(small_limits(), 1);
  const ScriptError next = run_error(host, "local k = next({ a = 1 })");
  EXPECT_EQ(next.message(),
            "script.lua:1: attempt to call a nil value (global 'next') (next is left out of the "
            "sandbox: the order it visits keys in differs from run to run; pairs visits them in "
            "sorted order)");
  const ScriptError os = run_error(host, "return os.time()");
  EXPECT_NE(os.message().find("(global 'os') (os is left out of the sandbox"), std::string::npos)
      << os.message();
  // A name that is no left-out one reads as Lua has it.
  EXPECT_EQ(run_error(host, "nxt()").message(),
            "script.lua:1: attempt to call a nil value (global 'nxt')");
}

TEST(LuaHostBudget, HookIsInheritedByCoroutines) {
  LuaHost host(small_limits(), 1);
  const char* scripts[] = {
      "local co = coroutine.create(function()\n while true do end\nend)\nreturn "
      "coroutine.resume(co)",
      "coroutine.wrap(function()\n while true do end\nend)()",
      "local co = coroutine.wrap(function() while true do coroutine.yield() end end)\n"
      "while true do co() end",
      "local a = coroutine.wrap(function() while true do coroutine.yield(1) end end)\n"
      "local b = coroutine.wrap(function() while true do coroutine.yield(a()) end end)\n"
      "local n = 0 while true do n = n + b() end"};
  for (const char* script : scripts) {
    const ScriptError error = run_error(host, script);
    EXPECT_EQ(error.kind(), Kind::kBudget) << script << " -> " << error.what();
    EXPECT_NE(error.message().find("instruction budget of 1000000 exceeded"), std::string::npos)
        << error.message();
    expect_works(host);
  }
}

TEST(LuaHostBudget, PcallAndXpcallCannotSwallowIt) {
  LuaHost host(small_limits(), 1);
  const char* scripts[] = {
      "local ok = pcall(function() while true do end end)\nreturn 'survived'",
      "local ok = xpcall(function() while true do end end, function(m) return m end)\n"
      "return 'survived'",
      "for i = 1, 3 do pcall(function() while true do end end) end\nreturn 'survived'",
      "local co = coroutine.create(function() while true do end end)\n"
      "local ok = coroutine.resume(co) return 'survived'",
      "local ok = pcall(coroutine.wrap(function() while true do end end)) return 'survived'",
      "local ok = pcall(table.sort, {3, 2, 1}, function(a, b) while true do end end)\n"
      "return 'survived'"};
  for (const char* script : scripts) {
    const ScriptError error = run_error(host, script);
    EXPECT_EQ(error.kind(), Kind::kBudget) << script << " -> " << error.what();
    EXPECT_NE(error.message().find("instruction budget of 1000000 exceeded"), std::string::npos)
        << error.message();
  }
  expect_works(host);
}

TEST(LuaHostBudget, BudgetIsPerCall) {
  LuaHost host(small_limits(), 1);
  const std::string loop = "local n = 0 for i = 1, 150000 do n = n + i end return tostring(n)";
  for (int i = 0; i < 5; ++i) EXPECT_EQ(run(host, loop), "11250075000");
  EXPECT_GE(host.instructions_used(), 5 * 250'000u);
  // call() also starts a fresh budget.
  host.run_string("function spin(n) local x = 0 for i = 1, n do x = x + 1 end return x end",
                  "f.lua", 0);
  for (int i = 0; i < 3; ++i) {
    host.push_env();
    lua_getfield(host.state(), -1, "spin");
    lua_remove(host.state(), -2);
    lua_pushinteger(host.state(), 200000);
    host.call(1, 1);
    EXPECT_EQ(lua_tointeger(host.state(), -1), 200000);
    lua_pop(host.state(), 1);
  }
  host.push_env();
  lua_getfield(host.state(), -1, "spin");
  lua_remove(host.state(), -2);
  lua_pushinteger(host.state(), 10'000'000);
  try {
    host.call(1, 1);
    ADD_FAILURE() << "no budget error";
  } catch (const ScriptError& error) {
    EXPECT_EQ(error.kind(), Kind::kBudget);
    EXPECT_EQ(error.message().rfind("f.lua:1: instruction budget", 0), 0u) << error.message();
  }
  EXPECT_EQ(lua_gettop(host.state()), 0);
}

TEST(LuaHostBudget, TableMoveCountsEachElement) {
  LuaHost host(small_limits(), 1);
  const ScriptError error = run_error(host, "table.move({}, 1, math.maxinteger - 1, 2)");
  EXPECT_EQ(error.kind(), Kind::kBudget);
  EXPECT_EQ(run(host, "return table.concat(table.move({1, 2, 3}, 1, 3, 2), ',')"), "1,1,2,3");
}

TEST(LuaHostBudget, WallClockGuard) {
  SandboxLimits limits = small_limits();
  limits.instructions_per_call = 1'000'000'000'000;
  limits.wall_seconds_per_call = 0.05;
  LuaHost host(limits, 1);
  const auto start = std::chrono::steady_clock::now();
  const ScriptError error = run_error(host, "while true do end");
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(error.kind(), Kind::kTime);
  EXPECT_EQ(error.message(), "script.lua:1: wall-clock limit of 0.05 s exceeded");
  EXPECT_LT(seconds, 1.0);
  expect_works(host);
}

// The guards cannot stop a library function from inside, so patterns that
// could backtrack for very long are refused before they run, by a bound that
// depends on the subject's length and the pattern only (the same every run).
TEST(LuaHostBudget, BacktrackingPatternsAreRefusedByTheirBound) {
  LuaHost host(small_limits(), 1);
  const struct {
    const char* subject;
    const char* call;
    const char* cost;
  } refused[] = {
      {"string.rep('a', 3000)", "s:find('.-.-.-b')", "3 repetitions and 0 optional"},
      {"string.rep('a', 3000)", "string.match(s, 'a*a*a*b')", "3 repetitions and 0 optional"},
      {"string.rep('a', 3000)", "s:gsub('(.+)(.+)(.+)x', '')", "3 repetitions and 0 optional"},
      {"string.rep('a', 3000)", "for w in s:gmatch('a-a-a-b') do end", "3 repetitions"},
      // A set that starts with an escape, a final anchor, a balance, optional items.
      {"'%' .. string.rep('a', 3000)", "s:find('[%%].-.-.-b')", "3 repetitions and 0 optional"},
      {"string.rep(' ', 60000) .. 'x'", "s:gsub('%s+$', '')", "1 repetitions and 0 optional"},
      {"string.rep('(', 60000)", "s:find('%b()')", "1 repetitions and 0 optional"},
      {"string.rep('a', 40)", "s:find(string.rep('a?', 40) .. string.rep('a', 40) .. '$')",
       "0 repetitions and 40 optional"},
  };
  for (const auto& r : refused) {
    const ScriptError error =
        run_error(host, std::string("local s = ") + r.subject + "\n" + r.call);
    EXPECT_EQ(error.kind(), Kind::kRuntime) << r.call;
    EXPECT_EQ(error.message().rfind("script.lua:2: string.", 0), 0u) << error.message();
    EXPECT_NE(error.message().find(r.cost), std::string::npos) << error.message();
  }
  // Ordinary patterns, on long subjects too: a final repetition, one that
  // backtracks on a short subject, sets, anchors, captures, plain search, a
  // literal '*' after a back-reference.
  EXPECT_EQ(run(host,
                "local a, b = ('key=value'):match('^(%w+)=(%w+)$')\n"
                "local t, n = string.rep('a  b ', 20000):gsub('%s+', '_')\n"
                "local words = 0 for w in ('a,b,,c'):gmatch('[^,]+') do words = words + 1 end\n"
                "local plain = string.rep('x', 100000):find('.-.-.-y', 1, true)\n"
                "local trimmed = ('  hi  '):match('^%s*(.-)%s*$')\n"
                "local set = ('[x]'):find('[]]')\n"
                "local star = (string.rep('ab', 100000) .. 'aa*'):find('(a)%1*')\n"
                "return a .. b .. n .. words .. tostring(plain) .. trimmed .. set .. star"),
            "keyvalue40000"
            "3nilhi3200001");
  // The library's own errors keep their names and positions.
  EXPECT_EQ(run_error(host, "local x = 1\nlocal y = ('a'):find('%')").message(),
            "script.lua:2: malformed pattern (ends with '%')");
  EXPECT_EQ(run_error(host, "local y = ('a'):find('a', 'x')").message(),
            "script.lua:1: bad argument #2 to 'find' (number expected, got string)");
  expect_works(host);
}

TEST(LuaHostBudget, LongSearchesInAShortLoopMeetTheWallClock) {
  // Each search is allowed (a bound of 9001^2, below 10^8 tries) and the
  // loop runs too few instructions for the count hook to look at the
  // clock: the guard looks again when a search returns, and after each
  // step of a gmatch.
  SandboxLimits limits = small_limits();
  limits.wall_seconds_per_call = 0.2;
  LuaHost host(limits, 1);
  for (const char* search : {"  s:find('a-b')", "  for w in s:gmatch('a-b') do end"}) {
    const ScriptError error = run_error(host, std::string("local s = string.rep('a', 9000)\n"
                                                          "for i = 1, 30 do\n") +
                                                  search + "\nend");
    EXPECT_EQ(error.kind(), Kind::kTime) << error.message();
    EXPECT_EQ(error.message(), "script.lua:3: wall-clock limit of 0.2 s exceeded");
  }
  expect_works(host);
}

// ---- 3. memory cap

TEST(LuaHostMemory, StringRepBombIsRefusedByName) {
  LuaHost host(small_limits(), 1);
  for (const char* script : {"local s = string.rep('x', 2^40)", "local s = ('x'):rep(2^40)",
                             "local ok = pcall(string.rep, 'x', 2^40) return 'survived'"}) {
    const ScriptError error = run_error(host, script);
    EXPECT_EQ(error.kind(), Kind::kMemory) << script;
    EXPECT_EQ(
        error.message().rfind(
            "script.lua:1: string.rep: a result of 1099511627776 bytes exceeds the memory left", 0),
        0u)
        << error.message();
    expect_works(host);
  }
}

TEST(LuaHostMemory, TableGrowthBombHitsTheCap) {
  LuaHost host(small_limits(), 1);
  const ScriptError error =
      run_error(host, "local t = {}\nwhile true do t[#t + 1] = ('x'):rep(1000) end");
  EXPECT_EQ(error.kind(), Kind::kMemory);
  // Either the allocator or string.rep's own check sees the cap first.
  EXPECT_TRUE(error.message().find("memory limit of 16777216 bytes exceeded") !=
                  std::string::npos ||
              error.message().find("string.rep: a result of 1000 bytes exceeds the memory left") !=
                  std::string::npos)
      << error.what();
  EXPECT_EQ(error.message().rfind("script.lua:2:", 0), 0u) << error.message();
  EXPECT_LE(host.memory_used(), 16u << 20);
  EXPECT_LT(host.memory_used(), 1u << 20) << "the garbage is collected after the failure";
  expect_works(host);
}

TEST(LuaHostMemory, AFailureBeforeTheFirstHookNamesItsLine) {
  // Twenty-odd doublings reach the cap long before the count hook first
  // fires: the line comes from where the script is when the cap is hit.
  LuaHost host(small_limits(), 1);
  const ScriptError error = run_error(host, "local s = 'x'\n\nwhile true do s = s .. s end");
  EXPECT_EQ(error.kind(), Kind::kMemory);
  EXPECT_EQ(error.message().rfind("script.lua:3: memory limit of 16777216 bytes exceeded", 0), 0u)
      << error.what();
  expect_works(host);
}

TEST(LuaHostMemory, AFailureNamesTheLineItHappensOnNotTheHooksLast) {
  // The count hook last fires in the loop of line 2; the cap is reached a
  // few instructions later, on line 4, before the hook fires again. In a
  // coroutine the line is the coroutine's own, not the one resuming it.
  LuaHost host(small_limits(), 1);
  const char* straight =
      "local t = {}\nfor i = 1, 5000 do t[i] = i end\nlocal s = string.rep('x', 1 << 20)\n"
      "while true do s = s .. s end";
  ScriptError error = run_error(host, straight);
  EXPECT_EQ(error.kind(), Kind::kMemory);
  EXPECT_EQ(error.message().rfind("script.lua:4: memory limit of 16777216 bytes exceeded", 0), 0u)
      << error.what();
  expect_works(host);

  const char* in_coroutine =
      "local t = {}\nfor i = 1, 5000 do t[i] = i end\nlocal co = coroutine.wrap(function()\n"
      "  local s = string.rep('x', 1 << 20)\n  while true do s = s .. s end\nend)\nco()";
  error = run_error(host, in_coroutine);
  EXPECT_EQ(error.kind(), Kind::kMemory);
  EXPECT_EQ(error.message().rfind("script.lua:5: memory limit of 16777216 bytes exceeded", 0), 0u)
      << error.what();
  expect_works(host);
}

TEST(LuaHostMemory, PcallCannotSwallowIt) {
  SandboxLimits limits = small_limits();
  limits.instructions_per_call = 20'000'000;  // the cap must come first
  LuaHost host(limits, 1);
  for (const char* script :
       {"local ok = pcall(function() local t = {} while true do t[#t + 1] = {1, 2, 3, 4, 5, 6} end "
        "end)\nreturn 'survived'",
        "local co = coroutine.wrap(function() local t = {} while true do t[#t + 1] = {1, 2, 3, 4, "
        "5, "
        "6} end end)\nlocal ok = pcall(co) return 'survived'",
        "local ok = pcall(function() local s = 'x' while true do s = s .. s end end)\n"
        "return 'survived'"}) {
    const ScriptError error = run_error(host, script);
    EXPECT_EQ(error.kind(), Kind::kMemory) << script << " -> " << error.what();
    EXPECT_EQ(error.message().rfind("script.lua:1: memory limit of 16777216 bytes exceeded", 0), 0u)
        << error.what();
    expect_works(host);
  }
}

// ---- errors: position, traceback, recursion

TEST(LuaHostErrors, RuntimeErrorHasFileLineAndTraceback) {
  LuaHost host(small_limits(), 1);
  const ScriptError error = run_error(host,
                                      "local function check(x)\n"
                                      "  return x.field\n"
                                      "end\n"
                                      "\n"
                                      "local function step()\n"
                                      "  local ok = true\n"
                                      "  error('part not found')\n"
                                      "end\n"
                                      "step()\n",
                                      "scenario.lua");
  EXPECT_EQ(error.kind(), Kind::kRuntime);
  EXPECT_EQ(
      std::string(error.what()).rfind("scenario.lua:7: part not found\nstack traceback:\n", 0), 0u)
      << error.what();
  EXPECT_NE(std::string(error.what()).find("scenario.lua:9:"), std::string::npos);
  EXPECT_EQ(error.message(), "scenario.lua:7: part not found");
  EXPECT_STREQ(kind_name(error.kind()), "runtime");
}

TEST(LuaHostErrors, SyntaxErrorHasFileLine) {
  LuaHost host(small_limits(), 1);
  const ScriptError error = run_error(host, "local a = 1\nlocal b = = 2\n", "bad.lua");
  EXPECT_EQ(error.kind(), Kind::kSyntax);
  EXPECT_EQ(error.message(), "bad.lua:2: unexpected symbol near '='");
  expect_works(host);
}

TEST(LuaHostErrors, ErrorObjectsThatAreNotStrings) {
  LuaHost host(small_limits(), 1);
  // Lua adds no position to an error object that is not a string; the host does.
  EXPECT_EQ(run_error(host, "error({})").message(),
            "script.lua:1: (error object is a table value)");
  EXPECT_EQ(run_error(host, "local x = 1\nerror(nil)").message(),
            "script.lua:2: (error object is a nil value)");
  EXPECT_EQ(run_error(host,
                      "error(setmetatable({}, {__tostring = function() return 'custom' "
                      "end}))")
                .message(),
            "script.lua:1: custom");
  // Nor to a text raised without one: at level 0, at a level above the
  // script, or by a library function.
  EXPECT_EQ(run_error(host, "\nerror('plain', 0)").message(), "script.lua:2: plain");
  EXPECT_EQ(run_error(host, "local function f() error('up', 2) end\nf()").message(),
            "script.lua:2: up");
  EXPECT_EQ(run_error(host, "error('outside', 2)").message(), "script.lua:1: outside");
  EXPECT_EQ(run_error(host, "error(42)").message(), "script.lua:1: 42");
  EXPECT_EQ(run_error(host, "coroutine.yield()").message(),
            "script.lua:1: attempt to yield from outside a coroutine");
  // A chunk whose name holds ": " is given its position once.
  EXPECT_EQ(run_error(host, "\nerror('boom')", "sp: ace.lua").message(), "sp: ace.lua:2: boom");
  EXPECT_EQ(run_error(host, "\nerror('boom', 0)", "sp: ace.lua").message(), "sp: ace.lua:2: boom");
}

TEST(LuaHostErrors, ErrorInsideWrappedCoroutineKeepsBothPositions) {
  LuaHost host(small_limits(), 1);
  const ScriptError error =
      run_error(host, "local f = coroutine.wrap(function()\n  error('inner')\nend)\nf()");
  EXPECT_EQ(error.message(), "script.lua:4: script.lua:2: inner");
  EXPECT_EQ(run(host,
                "local co = coroutine.create(function() error('x', 0) end) "
                "return table.concat({tostring(coroutine.resume(co))}, ' ') .. ' ' .. "
                "select(2, coroutine.resume(co))"),
            "false cannot resume dead coroutine");
}

TEST(LuaHostErrors, DeepRecursionEndsCleanly) {
  {
    LuaHost host(small_limits(), 1);  // 16 MiB: the memory cap comes first
    const ScriptError error = run_error(host, "local function f() return 1 + f() end\nreturn f()");
    EXPECT_TRUE(error.kind() == Kind::kMemory ||
                error.message().find("stack overflow") != std::string::npos)
        << error.what();
    expect_works(host);
  }
  {
    SandboxLimits limits = small_limits();
    limits.memory_bytes = 256u << 20;
    limits.instructions_per_call = 100'000'000;
    LuaHost host(limits, 1);  // Lua's own stack limit comes first
    const ScriptError error = run_error(host, "local function f() return 1 + f() end\nreturn f()");
    EXPECT_EQ(error.kind(), Kind::kRuntime);
    EXPECT_NE(error.message().find("stack overflow"), std::string::npos) << error.message();
    expect_works(host);
  }
  LuaHost host(small_limits(), 1);
  const ScriptError error = run_error(
      host, "local t = setmetatable({}, {__index = function(t, k) return t[k] end}) return t.x");
  EXPECT_NE(error.message().find("stack overflow"), std::string::npos) << error.message();
  expect_works(host);
}

TEST(LuaHostErrors, RunFileNamesThePath) {
  LuaHost host(small_limits(), 1);
  const test::TempDir folder("dovetail_lua_host");
  const auto script = folder / "scenario.lua";
  std::ofstream(script) << "#!/usr/bin/env lua\nlocal x = 1\nerror('bad ' .. x)\n";
  EXPECT_EQ(run_file_error(host, script).message(), script.string() + ":3: bad 1");
  std::ofstream(script) << "return 6 * 7\n";
  host.run_file(script, 1);
  EXPECT_EQ(lua_tointeger(host.state(), -1), 42);
  lua_pop(host.state(), 1);
  std::ofstream(script, std::ios::binary) << "\x1bLua\x54";
  const ScriptError binary = run_file_error(host, script);
  EXPECT_EQ(binary.kind(), Kind::kSyntax);
  EXPECT_NE(binary.message().find("binary chunk"), std::string::npos) << binary.message();
  const auto missing = folder / "missing.lua";
  EXPECT_EQ(run_file_error(host, missing).message(), missing.string() + ": file not found");
  expect_works(host);
}

TEST(LuaHostErrors, ALongPathIsGivenWholeInPositionsAndTracebacks) {
  // Lua shortens a chunk name to 59 characters ("..." and the end); the
  // host gives the path back as it was given.
  LuaHost host(small_limits(), 1);
  const test::TempDir folder("dovetail_lua_host");
  const auto deep = folder / "a_rather_long_folder_name" / "another_long_folder_name_here";
  std::filesystem::create_directories(deep);
  const auto script = deep / "scenario_with_an_error.lua";
  ASSERT_GT(script.string().size(), 80u);
  std::ofstream(script) << "local function f()\n  error('bad')\nend\nf()\n";
  const ScriptError runtime = run_file_error(host, script);
  EXPECT_EQ(runtime.message(), script.string() + ":2: bad");
  const std::string all = runtime.what();
  EXPECT_NE(all.find(script.string() + ":2: in"), std::string::npos) << all;
  EXPECT_EQ(all.find("..."), std::string::npos) << all;
  std::ofstream(script) << "local t = {\n";
  const ScriptError syntax = run_file_error(host, script);
  EXPECT_EQ(syntax.kind(), Kind::kSyntax);
  EXPECT_EQ(syntax.message().rfind(script.string() + ":", 0), 0u) << syntax.message();
  expect_works(host);
}

// ---- 5 and 6. determinism: random, pairs, sort

TEST(LuaHostRandom, SeededSequenceWithLuaSemantics) {
  const std::string draw =
      "local t = {} for i = 1, 4 do t[#t + 1] = math.random(1000000) end "
      "return table.concat(t, ' ')";
  LuaHost a(small_limits(), 7);
  LuaHost b(small_limits(), 7);
  LuaHost c(small_limits(), 8);
  const std::string first = run(a, draw);
  EXPECT_EQ(first, run(b, draw));
  EXPECT_NE(first, run(c, draw));
  EXPECT_NE(first, run(a, draw)) << "the sequence continues";
  EXPECT_EQ(run(a, "math.randomseed() " + draw), first) << "randomseed() restarts it";
  EXPECT_EQ(run(a, "math.randomseed(5, 1) " + draw), run(b, "math.randomseed(5, 1) " + draw));
  EXPECT_EQ(
      run(a,
          "for i = 1, 1000 do\n"
          "  local f = math.random() assert(f >= 0 and f < 1)\n"
          "  local m = math.random(6) assert(m >= 1 and m <= 6 and math.type(m) == 'integer')\n"
          "  local r = math.random(-3, 3) assert(r >= -3 and r <= 3)\n"
          "  assert(math.type(math.random(0)) == 'integer')\n"
          "  assert(math.random(math.mininteger, math.maxinteger))\n"
          "  assert(math.random(5, 5) == 5)\n"
          "end return 'ok'"),
      "ok");
  EXPECT_NE(run_error(a, "math.random(3, 2)").message().find("interval is empty"),
            std::string::npos);
  EXPECT_NE(run_error(a, "math.random(0.5)").message().find("number has no integer representation"),
            std::string::npos);
  EXPECT_NE(run_error(a, "math.random(1, 2, 3)").message().find("wrong number of arguments"),
            std::string::npos);
}

TEST(LuaHostDeterminism, PairsVisitsKeysInSortedOrder) {
  LuaHost host(small_limits(), 1);
  EXPECT_EQ(run(host,
                "local t = {10, 20, [2.5] = 1, [-1] = 1, b = 1, a = 1, aa = 1, B = 1,\n"
                "  [true] = 1, [false] = 1, [math.huge] = 1, [-0.5] = 1, [2^63] = 1}\n"
                "local out = {} for k in pairs(t) do out[#out + 1] = tostring(k) end\n"
                "return table.concat(out, ' ')"),
            "-1 -0.5 1 2 2.5 9.2233720368548e+18 inf B a aa b false true");
  // Fields may be cleared while iterating; cleared ones are not visited.
  EXPECT_EQ(run(host,
                "local t = {a = 1, b = 2, c = 3} local out = {}\n"
                "for k, v in pairs(t) do out[#out + 1] = k .. v t.b = nil end\n"
                "return table.concat(out, ' ')"),
            "a1 c3");
  // __pairs is honoured.
  EXPECT_EQ(run(host,
                "local t = setmetatable({}, {__pairs = function(t) return function(_, k) "
                "if not k then return 1, 'one' end end, t, nil end})\n"
                "for k, v in pairs(t) do return v end"),
            "one");
  const ScriptError error = run_error(host, "for k in pairs({[{}] = 1}) do end");
  EXPECT_NE(error.message().find("key of type table has no defined order"), std::string::npos)
      << error.message();
}

TEST(LuaHostDeterminism, TableSortIsAStableMergeSort) {
  LuaHost host(small_limits(), 1);
  EXPECT_EQ(run(host, "local t = {5, 3, 9, 1, 3, 7} table.sort(t) return table.concat(t, ' ')"),
            "1 3 3 5 7 9");
  EXPECT_EQ(run(host,
                "local t = {'pear', 'apple', 'fig'} table.sort(t, function(a, b) "
                "return a > b end) return table.concat(t, ' ')"),
            "pear fig apple");
  // Stable: equal keys keep their order.
  EXPECT_EQ(run(host,
                "local t = {} for i = 1, 50 do t[i] = {key = i % 3, id = i} end\n"
                "table.sort(t, function(a, b) return a.key < b.key end)\n"
                "local out = {} for i = 1, 6 do out[i] = t[i].id end\n"
                "for i = 2, 50 do assert(t[i - 1].key < t[i].key or\n"
                "  (t[i - 1].key == t[i].key and t[i - 1].id < t[i].id)) end\n"
                "return table.concat(out, ' ')"),
            "3 6 9 12 15 18");
  EXPECT_EQ(run(host,
                "local t = {} for i = 1, 1000 do t[i] = math.random(100) end table.sort(t)\n"
                "for i = 2, #t do assert(t[i - 1] <= t[i]) end return 'sorted'"),
            "sorted");
  EXPECT_NE(run_error(host, "table.sort({3, 1, 2}, function(a, b) return true end)")
                .message()
                .find("invalid order function for sorting"),
            std::string::npos);
  EXPECT_NE(run_error(host, "table.sort({3, 1, 2, 2}, function(a, b) return a <= b end)")
                .message()
                .find("invalid order function for sorting"),
            std::string::npos);
  EXPECT_NE(run_error(host, "table.sort({1, 'x'})").message().find("attempt to compare"),
            std::string::npos);
  EXPECT_EQ(run_error(host, "table.sort(5)").message(),
            "script.lua:1: bad argument #1 to 'sort' (table expected, got number)");
}

TEST(LuaHostDeterminism, SameSeedSameScriptSameResults) {
  const std::string script =
      "local t = {} for i = 1, 200 do t['key' .. math.random(1000)] = i end\n"
      "local out = {} for k, v in pairs(t) do out[#out + 1] = k .. '=' .. v end\n"
      "local objects = {} for i = 1, 3 do objects[i] = tostring({}) end\n"
      "local list = {} for i = 1, 100 do list[i] = {k = math.random(10), i = i} end\n"
      "table.sort(list, function(a, b) return a.k < b.k end)\n"
      "local order = {} for i = 1, 100 do order[i] = list[i].i end\n"
      "return table.concat(out, ',') .. table.concat(objects) .. table.concat(order, ',')";
  LuaHost a(small_limits(), 99);
  LuaHost b(small_limits(), 99);
  LuaHost c(small_limits(), 100);
  const std::string result = run(a, script);
  EXPECT_EQ(result, run(b, script));
  EXPECT_NE(result, run(c, script));
}

// ---- 11. the host survives everything

TEST(LuaHostLifecycle, SurvivesEveryHostileScript) {
  LuaHost host(small_limits(), 3);
  host.run_string("kept = 'still here'", "setup.lua", 0);
  const char* hostile[] = {"while true do end",
                           "string.rep('x', 2^40)",
                           "local t = {} while true do t[#t + 1] = ('x'):rep(1000) end",
                           "local function f() return 1 + f() end f()",
                           "local g = coroutine.wrap(function() while true do coroutine.yield() "
                           "end end) while true do g() end",
                           "os.exit()",
                           "io.open('/etc/passwd')",
                           "require'x'",
                           "debug.sethook()",
                           "package.loadlib('a', 'b')",
                           "assert(load('\\27Lua'))",
                           "setmetatable(_G, nil)",
                           "x = = 1",
                           "pcall(function() while true do end end) local y = 1",
                           "error({})",
                           "table.move({}, 1, math.maxinteger - 1, 2)"};
  for (const char* script : hostile) {
    run_error(host, script);
    expect_works(host);
    EXPECT_EQ(run(host, "return kept"), "still here") << script;
  }
  EXPECT_EQ(lua_gettop(host.state()), 0);
  EXPECT_LE(host.memory_used(), 16u << 20);
  LuaHost fresh(small_limits(), 3);
  expect_works(fresh);
}

TEST(LuaHostLifecycle, CallLeavesResultsAndPopsOnError) {
  LuaHost host(small_limits(), 1);
  host.run_string("function triple(a, b) return a, b, a + b end", "api.lua", 0);
  lua_State* L = host.state();
  host.push_env();
  lua_getfield(L, -1, "triple");
  lua_remove(L, -2);
  lua_pushinteger(L, 2);
  lua_pushinteger(L, 3);
  host.call(2, LUA_MULTRET);
  ASSERT_EQ(lua_gettop(L), 3);
  EXPECT_EQ(lua_tointeger(L, 3), 5);
  lua_settop(L, 0);
  host.push_env();
  lua_getfield(L, -1, "triple");
  lua_remove(L, -2);
  lua_pushinteger(L, 2);
  lua_pushnil(L);
  EXPECT_THROW(host.call(2, 1), ScriptError);
  EXPECT_EQ(lua_gettop(L), 0);
  host.run_string("return 1, 2", "two.lua", LUA_MULTRET);
  EXPECT_EQ(lua_gettop(L), 2);
  lua_settop(L, 0);
}

}  // namespace
}  // namespace dovetail::scripting
