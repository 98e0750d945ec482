#pragma once
/// \file folder_io_system.h
/// An assimp file system that only reads inside one folder.
///
/// Why: glTF buffers and images, OBJ material libraries and similar references
/// are paths written by whoever made the file. A model must not make the
/// importer read `../../secret` or `/etc/...`, so every path the importer asks
/// for is made absolute, normalised lexically (`..` removed without following
/// links) and refused unless it lies inside the input file's folder. Refused
/// paths are remembered so the error can name them.

#include <assimp/DefaultIOSystem.h>

#include <assimp/IOSystem.hpp>
#include <filesystem>
#include <string>
#include <vector>

namespace dovetail::engine::detail {

/// Reads files below `root` only, read-only; everything else does not exist.
class FolderIOSystem : public Assimp::IOSystem {
 public:
  explicit FolderIOSystem(std::filesystem::path root);

  bool Exists(const char* file) const override;
  char getOsSeparator() const override;
  Assimp::IOStream* Open(const char* file, const char* mode = "rb") override;
  void Close(Assimp::IOStream* stream) override;

  /// Serves `text` in place of the file `file` (an absolute path inside the
  /// folder), which is still reported as opened: for an input read with a
  /// correction the importer needs (obj_with_unique_objects).
  void substitute(const std::filesystem::path& file, std::string text);

  /// Paths the importer tried to open and was refused, in order, without repeats.
  const std::vector<std::string>& refused() const { return refused_; }
  /// Files the importer opened (normalised absolute paths), in order, without repeats.
  const std::vector<std::string>& opened() const { return opened_; }

 private:
  /// The normalised absolute path of `file` when it lies inside root_ and is a
  /// regular file; empty otherwise. A path outside root_ is remembered when
  /// `remember` is set (Open only: importers probe many guessed names with Exists).
  std::filesystem::path resolve(const char* file, bool remember) const;

  std::filesystem::path root_;
  Assimp::DefaultIOSystem files_;
  std::filesystem::path substituted_;
  std::string substitute_text_;
  mutable std::vector<std::string> refused_;
  std::vector<std::string> opened_;
};

}  // namespace dovetail::engine::detail
