#pragma once
/// \file gltf_nodes.h
/// The depth of a glTF file's node hierarchy, read before the importer.
///
/// Why: the importer walks the hierarchy recursively, one stack frame per
/// level, and a file of a few hundred kilobytes chaining 20,000 nodes
/// overflows the stack (a crash, not an error). Real assemblies are a few
/// dozen levels deep; a file deeper than the limit is refused with a message.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace dovetail::engine::detail {

/// The deepest node hierarchy Dovetail reads.
inline constexpr std::size_t kMaxNodeDepth = 1000;

/// The JSON of a .gltf file, or of a .glb file's first (JSON) chunk, read
/// from `path` (`file_size` bytes); nullopt when a .glb file does not start
/// as one or is cut short (the importer names those).
std::optional<std::string> gltf_json(const std::filesystem::path& path, bool binary,
                                     std::uintmax_t file_size);

/// gltf_node_depth's answer for JSON nested deeper than 256 levels, which
/// the importer's recursive JSON reader may not survive either.
inline constexpr std::size_t kJsonTooDeep = static_cast<std::size_t>(-1);

/// The levels of the deepest chain of nodes ("nodes" and their "children")
/// in glTF JSON, counting a node without children as one; kJsonTooDeep for
/// JSON nested deeper than 256 levels; nullopt when the JSON is malformed
/// or the children form a cycle (the importer names those).
std::optional<std::size_t> gltf_node_depth(std::string_view json);

}  // namespace dovetail::engine::detail
