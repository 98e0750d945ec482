#include "folder_io_system.h"

#include <assimp/MemoryIOWrapper.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <system_error>
#include <utility>

namespace dovetail::engine::detail {

namespace fs = std::filesystem;

FolderIOSystem::FolderIOSystem(fs::path root) : root_(fs::absolute(root).lexically_normal()) {
  // "dir/" normalises with an empty last element; drop it for the prefix test.
  if (!root_.has_filename() && root_.has_parent_path() && root_ != root_.root_path()) {
    root_ = root_.parent_path();
  }
}

fs::path FolderIOSystem::resolve(const char* file, bool remember) const {
  if (file == nullptr || *file == '\0') return {};
  fs::path p(file);
  if (p.is_relative()) p = root_ / p;
  p = p.lexically_normal();
  // Inside root_ when root_'s components are a prefix of p's.
  const auto [root_end, p_end] = std::mismatch(root_.begin(), root_.end(), p.begin(), p.end());
  (void)p_end;
  if (root_end != root_.end() || p == root_) {
    const std::string shown = p.string();
    if (remember && std::find(refused_.begin(), refused_.end(), shown) == refused_.end()) {
      refused_.push_back(shown);
    }
    return {};
  }
  std::error_code ec;
  if (!fs::is_regular_file(p, ec)) return {};
  return p;
}

bool FolderIOSystem::Exists(const char* file) const { return !resolve(file, false).empty(); }

char FolderIOSystem::getOsSeparator() const { return '/'; }

Assimp::IOStream* FolderIOSystem::Open(const char* file, const char* mode) {
  // Read-only: any mode that writes, appends or updates is refused.
  if (mode == nullptr || std::strpbrk(mode, "wa+") != nullptr) return nullptr;
  const fs::path p = resolve(file, true);
  if (p.empty()) return nullptr;
  Assimp::IOStream* stream = nullptr;
  if (!substituted_.empty() && p == substituted_) {
    // The stream owns its copy, so the importer may open the file twice.
    auto* bytes = new std::uint8_t[std::max<std::size_t>(substitute_text_.size(), 1)];
    std::memcpy(bytes, substitute_text_.data(), substitute_text_.size());
    stream = new Assimp::MemoryIOStream(bytes, substitute_text_.size(), true);
  } else {
    stream = files_.Open(p.string().c_str(), mode);
  }
  if (stream != nullptr && std::find(opened_.begin(), opened_.end(), p.string()) == opened_.end()) {
    opened_.push_back(p.string());
  }
  return stream;
}

void FolderIOSystem::Close(Assimp::IOStream* stream) { files_.Close(stream); }

void FolderIOSystem::substitute(const fs::path& file, std::string text) {
  substituted_ = file.lexically_normal();
  substitute_text_ = std::move(text);
}

}  // namespace dovetail::engine::detail
