#pragma once
/// \file import_process.h
/// Running the mesh importer in a child process.
///
/// Why: assimp is a large C++ library that reads hostile bytes. Dovetail
/// checks what it can before assimp runs (declared sizes, node depth, the
/// lines of text formats), but fuzzing keeps finding inputs on which assimp
/// itself reads through a null pointer. A crash there must not take down a
/// run, a regression or an editor session: it must be an error naming the
/// file. So the import runs in a forked child, which sends its result (or
/// its error) back through a pipe; when the child dies of a signal, the
/// parent names the file and the signal. The result is the same bits as an
/// import in the process itself: numbers cross the pipe as their bytes.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>

#include "dovetail/engine/mesh_import.h"

namespace dovetail::engine::detail {

/// Calls `import` in a child process and returns its report. An ImportError
/// the child throws is thrown again here with the same message; any other
/// failure of the child (another exception, a signal, memory beyond
/// `memory_budget_bytes` more than the parent's) becomes an ImportError
/// whose message starts with `path`. When no process can be started (no
/// pipe or process to spare), `import` runs here, and the report's notes
/// say so.
///
/// The child is forked, not executed afresh: it must not need a lock that
/// another thread of the process may hold. Imports happen while no collision
/// work runs (scenario loading, the commands' reading of their inputs), and
/// glibc's allocator and stdio are fork-safe.
ImportReport import_in_child(const std::filesystem::path& path,
                             const std::function<ImportReport()>& import,
                             std::uintmax_t memory_budget_bytes);

/// The bytes a report crosses the pipe as, and back; exposed for tests.
std::string encode_report(const ImportReport& report);
/// Throws std::runtime_error when `bytes` are not a whole encoded report.
ImportReport decode_report(std::string_view bytes);

}  // namespace dovetail::engine::detail
