#pragma once
/// \file sandbox_env.h
/// The environment scripts run in: the whitelisted base functions, the
/// read-only library tables and the functions replaced for safety (pcall,
/// load, string.rep, ...) or determinism (pairs, tostring, table.sort,
/// math.random).
///
/// Why: the sandbox is an allow list built once per state; the host's own
/// global table keeps the unrestricted libraries out of the scripts' reach.

#include <lua.hpp>

namespace dovetail::scripting {

/// A lua_CFunction that opens the standard libraries it needs and builds the
/// sandbox environment, stored in the registry. Call it with lua_pcall once,
/// on a fresh state whose allocator data is a HostState.
int open_sandbox(lua_State* L);

/// Pushes the environment open_sandbox built. Never allocates.
void push_sandbox_env(lua_State* L);

}  // namespace dovetail::scripting
