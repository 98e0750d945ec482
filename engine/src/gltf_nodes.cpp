#include "gltf_nodes.h"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

namespace dovetail::engine::detail {

namespace {

/// JSON nested deeper than this is not read (glTF's own nesting is a few levels).
constexpr int kMaxJsonNesting = 256;

/// Reads just enough of glTF JSON to find every node's children. Any
/// malformed input makes ok() false; nothing is thrown.
class NodeReader {
 public:
  explicit NodeReader(std::string_view text) : s_(text) {}

  bool ok() const { return ok_; }
  /// The JSON nests deeper than kMaxJsonNesting.
  bool too_deep() const { return too_deep_; }
  const std::vector<std::vector<std::uint64_t>>& children() const { return children_; }

  /// The top-level object, its "nodes" array read, everything else skipped.
  void read() {
    object([&](std::string_view key) {
      if (key == "nodes") {
        nodes();
      } else {
        skip(1);
      }
    });
    space();
    if (i_ != s_.size()) ok_ = false;
  }

 private:
  /// White space, and comments (// to the line's end, /* to */), which the
  /// importer's JSON reader also skips.
  void space() {
    while (i_ < s_.size()) {
      const char c = s_[i_];
      if (c == ' ' || c == '\t' || c == '\n' || c == '\r') {
        ++i_;
      } else if (c == '/' && i_ + 1 < s_.size() && s_[i_ + 1] == '/') {
        const std::size_t end = s_.find('\n', i_);
        i_ = end == std::string_view::npos ? s_.size() : end;
      } else if (c == '/' && i_ + 1 < s_.size() && s_[i_ + 1] == '*') {
        const std::size_t end = s_.find("*/", i_ + 2);
        i_ = end == std::string_view::npos ? s_.size() : end + 2;
      } else {
        return;
      }
    }
  }
  bool take(char c) {
    space();
    if (i_ < s_.size() && s_[i_] == c) {
      ++i_;
      return true;
    }
    return false;
  }
  bool at(char c) {
    space();
    return i_ < s_.size() && s_[i_] == c;
  }

  /// A string's text between its quotes, escapes decoded (\uXXXX outside
  /// ASCII as '?': keys that matter here are ASCII), so that "node\u0073"
  /// is the key "nodes", as the importer reads it.
  std::string string() {
    std::string out;
    if (!take('"')) {
      ok_ = false;
      return out;
    }
    while (i_ < s_.size() && s_[i_] != '"') {
      if (s_[i_] != '\\') {
        out += s_[i_++];
        continue;
      }
      if (i_ + 1 >= s_.size()) break;
      const char e = s_[i_ + 1];
      i_ += 2;
      if (e == 'u') {
        unsigned code = 0;
        for (int k = 0; k < 4 && i_ < s_.size(); ++k, ++i_) {
          const char h = s_[i_];
          const int digit = h >= '0' && h <= '9'   ? h - '0'
                            : h >= 'a' && h <= 'f' ? h - 'a' + 10
                            : h >= 'A' && h <= 'F' ? h - 'A' + 10
                                                   : -1;
          if (digit < 0) {
            ok_ = false;
            return out;
          }
          code = code * 16 + static_cast<unsigned>(digit);
        }
        out += code < 0x80 ? static_cast<char>(code) : '?';
      } else {
        const char* from = "\"\\/bfnrt";
        const char* to = "\"\\/\b\f\n\r\t";
        const char* at = std::strchr(from, e);
        if (at == nullptr || e == '\0') {
          ok_ = false;
          return out;
        }
        out += to[at - from];
      }
    }
    if (i_ >= s_.size()) {
      ok_ = false;
      return out;
    }
    ++i_;
    return out;
  }

  /// `open`, items separated by commas, `close`; item() reads one.
  template <typename Item>
  void sequence(char open, char close, Item&& item) {
    if (!take(open)) {
      ok_ = false;
      return;
    }
    if (take(close)) return;
    while (ok_) {
      item();
      if (take(',')) continue;
      if (!take(close)) ok_ = false;
      return;
    }
  }

  /// An object, calling member(key) with the position at its value.
  template <typename Member>
  void object(Member&& member) {
    sequence('{', '}', [&] {
      const std::string key = string();
      if (!ok_ || !take(':')) {
        ok_ = false;
        return;
      }
      member(key);
    });
  }

  /// An array, calling element() with the position at each element.
  template <typename Element>
  void array(Element&& element) {
    sequence('[', ']', element);
  }

  void nodes() {
    array([&] {
      std::vector<std::uint64_t>& kids = children_.emplace_back();
      if (!at('{')) {
        skip(2);
        return;
      }
      object([&](std::string_view key) {
        if (key != "children") {
          skip(3);
          return;
        }
        array([&] { kids.push_back(index()); });
      });
    });
  }

  /// A node index: a number with an integral value (1, 1.0, 1e0).
  std::uint64_t index() {
    space();
    const std::size_t begin = i_;
    while (i_ < s_.size() && std::strchr(",]} \t\r\n", s_[i_]) == nullptr) ++i_;
    double value = -1;
    const auto [end, ec] = std::from_chars(s_.data() + begin, s_.data() + i_, value);
    if (ec != std::errc() || end != s_.data() + i_ || !(value >= 0) || value > 0x1p40 ||
        value != std::floor(value)) {
      ok_ = false;
      return 0;
    }
    return static_cast<std::uint64_t>(value);
  }

  /// Any value, nested at most kMaxJsonNesting deep.
  void skip(int depth) {
    if (depth > kMaxJsonNesting) {
      ok_ = false;
      too_deep_ = true;
      return;
    }
    space();
    if (i_ >= s_.size()) {
      ok_ = false;
    } else if (s_[i_] == '{') {
      object([&](std::string_view) { skip(depth + 1); });
    } else if (s_[i_] == '[') {
      array([&] { skip(depth + 1); });
    } else if (s_[i_] == '"') {
      string();
    } else {
      // A number or a literal: up to the next delimiter.
      const std::size_t begin = i_;
      while (i_ < s_.size() && std::strchr(",]} \t\r\n", s_[i_]) == nullptr) ++i_;
      if (i_ == begin) ok_ = false;
    }
  }

  std::string_view s_;
  std::size_t i_ = 0;
  bool ok_ = true;
  bool too_deep_ = false;
  std::vector<std::vector<std::uint64_t>> children_;
};

std::uint32_t little_u32(std::string_view bytes, std::size_t at) {
  std::uint32_t v = 0;
  for (int k = 3; k >= 0; --k) v = (v << 8) | static_cast<unsigned char>(bytes[at + k]);
  return v;
}

}  // namespace

std::optional<std::string> gltf_json(const std::filesystem::path& path, bool binary,
                                     std::uintmax_t file_size) {
  std::ifstream in(path, std::ios::binary);
  if (!binary) {
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  // GLB: "glTF", version, length; then the first chunk: length, "JSON", data.
  // The binary buffer after it is not read.
  std::string header(20, '\0');
  in.read(header.data(), 20);
  if (in.gcount() < 20 || header.compare(0, 4, "glTF") != 0 || header.compare(16, 4, "JSON") != 0) {
    return std::nullopt;
  }
  const std::uint32_t length = little_u32(header, 12);
  if (length > file_size) return std::nullopt;  // the importer names a truncated file
  std::string json(length, '\0');
  in.read(json.data(), length);
  if (static_cast<std::uint64_t>(in.gcount()) != length) return std::nullopt;
  return json;
}

std::optional<std::size_t> gltf_node_depth(std::string_view json) {
  NodeReader reader(json);
  reader.read();
  if (reader.too_deep()) return kJsonTooDeep;
  if (!reader.ok()) return std::nullopt;
  const auto& children = reader.children();
  const std::size_t n = children.size();
  // depth[v] once known; a stack of (node, next child) walks each node once.
  constexpr std::size_t kUnknown = 0, kOnPath = SIZE_MAX;
  std::vector<std::size_t> depth(n, kUnknown);
  std::size_t deepest = 0;
  for (std::size_t root = 0; root < n; ++root) {
    if (depth[root] != kUnknown) continue;
    std::vector<std::pair<std::size_t, std::size_t>> path{{root, 0}};
    depth[root] = kOnPath;
    while (!path.empty()) {
      auto& [node, next] = path.back();
      if (next < children[node].size()) {
        const std::uint64_t child = children[node][next++];
        if (child >= n) return std::nullopt;
        if (depth[child] == kOnPath) return std::nullopt;  // a cycle
        if (depth[child] == kUnknown) {
          depth[child] = kOnPath;
          path.emplace_back(child, 0);
        }
        continue;
      }
      std::size_t d = 1;
      for (const std::uint64_t child : children[node]) d = std::max(d, depth[child] + 1);
      depth[node] = d;
      deepest = std::max(deepest, d);
      path.pop_back();
    }
  }
  return deepest;
}

}  // namespace dovetail::engine::detail
