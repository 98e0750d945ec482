#include "declared_sizes.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string_view>
#include <vector>

#include "gltf_nodes.h"
#include "obj_lines.h"
namespace dovetail::engine::detail {

namespace {

constexpr std::size_t kHeadBytes = 64 * 1024;

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string read_head(const std::filesystem::path& path, std::size_t bytes) {
  std::ifstream in(path, std::ios::binary);
  std::string head(bytes, '\0');
  in.read(head.data(), static_cast<std::streamsize>(bytes));
  head.resize(static_cast<std::size_t>(std::max<std::streamsize>(in.gcount(), 0)));
  return head;
}

/// A count as written in a header: a plain non-negative integer. `overflow`
/// is set when the digits are valid but do not fit 64 bits.
struct Count {
  bool valid = false;
  bool overflow = false;
  std::uint64_t value = 0;
};

Count parse_count(std::string_view token) {
  Count c;
  if (token.empty()) return c;
  const char* first = token.data();
  const char* last = token.data() + token.size();
  if (*first == '+') ++first;
  const auto [ptr, ec] = std::from_chars(first, last, c.value);
  if (ptr != last) return c;
  if (ec == std::errc::result_out_of_range) {
    c.overflow = true;
    c.valid = true;
    return c;
  }
  c.valid = ec == std::errc();
  return c;
}

std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    const std::size_t start = i;
    while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

/// Size in bytes of a PLY scalar type; 0 for an unknown name.
std::size_t ply_type_size(std::string_view type) {
  static constexpr std::array<std::pair<std::string_view, std::size_t>, 16> kSizes = {{
      {"char", 1},
      {"uchar", 1},
      {"int8", 1},
      {"uint8", 1},
      {"short", 2},
      {"ushort", 2},
      {"int16", 2},
      {"uint16", 2},
      {"int", 4},
      {"uint", 4},
      {"int32", 4},
      {"uint32", 4},
      {"float", 4},
      {"float32", 4},
      {"double", 8},
      {"float64", 8},
  }};
  for (const auto& [name, size] : kSizes) {
    if (name == type) return size;
  }
  return 0;
}

std::string too_many(std::uint64_t count, const char* what, std::size_t limit) {
  return "declares " + std::to_string(count) + " " + what + ", over the limit of " +
         std::to_string(limit);
}

std::string beyond_file(std::string_view format, long double needed, std::uintmax_t available) {
  std::ostringstream out;
  out.precision(0);
  out << std::fixed << "the " << format
      << " header declares more data than the file holds (at least " << needed << " bytes needed, "
      << available << " bytes present); truncated or corrupt";
  return out.str();
}

/// PLY headers are checked strictly: importers are fragile on malformed ones
/// (missing end_header, unknown types, malformed element or property lines),
/// so these are refused here with the offending line.
/// One element of a PLY header.
struct PlyElement {
  std::string name;
  Count count;
  std::size_t binary_bytes = 0;  // fixed bytes per element in binary formats
  std::size_t properties = 0;
  bool lists = false;         // has a list property
  std::vector<bool> is_list;  // per property, in order
};

/// An ASCII PLY body line by line: each element's entries one a line, in
/// header order, with as many values as its properties (a list: its count,
/// then that many values), and nothing after them. The importer reads a
/// body that ends early or lists too few values without a word, taking the
/// next line's values for the missing ones.
std::optional<std::string> check_ascii_ply_body(const std::filesystem::path& path,
                                                std::size_t header_lines,
                                                const std::vector<PlyElement>& elements) {
  std::ifstream in(path, std::ios::binary);
  std::string text;
  std::size_t line = 0;
  for (; line < header_lines && std::getline(in, text); ++line) {
  }
  const auto next = [&]() -> std::optional<std::vector<std::string_view>> {
    while (std::getline(in, text)) {
      ++line;
      std::vector<std::string_view> w = split_words(text);
      if (!w.empty()) return w;
    }
    return std::nullopt;
  };
  for (const PlyElement& e : elements) {
    for (std::uint64_t k = 0; k < e.count.value; ++k) {
      const auto w = next();
      if (!w) {
        return "PLY ends after " + std::to_string(k) + " of the " + std::to_string(e.count.value) +
               " " + e.name + " lines its header declares; truncated";
      }
      if (e.lists && e.properties == 1) {  // a face: its corner count, then the corners
        const Count n = parse_count((*w)[0]);
        if (!n.valid || n.value + 1 != w->size()) {
          return "PLY line " + std::to_string(line) + ": a " + e.name + " line gives " +
                 std::string((*w)[0]) + " as its count of values and lists " +
                 std::to_string(w->size() - 1);
        }
      } else if (!e.lists && w->size() != e.properties) {
        return "PLY line " + std::to_string(line) + ": a " + e.name + " has " +
               std::to_string(e.properties) + " values, this line " + std::to_string(w->size());
      } else if (e.lists) {  // values and lists mixed: each list its count, then its values
        std::size_t at = 0;  // the next word; past the end: the line is wrong
        for (const bool list : e.is_list) {
          if (at >= w->size()) {
            at = w->size() + 1;
            break;
          }
          const Count n = list ? parse_count((*w)[at]) : Count{.valid = true, .value = 0};
          if (!n.valid || n.value > w->size()) {
            at = w->size() + 1;
            break;
          }
          at += 1 + n.value;
        }
        if (at != w->size()) {
          return "PLY line " + std::to_string(line) + ": a " + e.name + " line does not hold its " +
                 std::to_string(e.properties) +
                 " properties (a list: its count, then that many values)";
        }
      }
    }
  }
  if (next()) return "PLY line " + std::to_string(line) + ": more lines than the header declares";
  return std::nullopt;
}

std::optional<std::string> check_ply(const std::filesystem::path& path, std::string_view head,
                                     std::uintmax_t file_size,
                                     const collision::MeshLimits& limits) {
  std::vector<PlyElement> elements;
  bool binary = false;
  bool has_format = false;
  std::size_t pos = 0;
  std::size_t line = 0;
  std::size_t header_end = std::string_view::npos;
  auto bad = [&line](const std::string& what) {
    return "PLY header line " + std::to_string(line) + ": " + what;
  };
  while (pos < head.size()) {
    const std::size_t eol = head.find('\n', pos);
    if (eol == std::string_view::npos) break;
    const std::string_view text = head.substr(pos, eol - pos);
    const std::vector<std::string_view> w = split_words(text);
    pos = eol + 1;
    ++line;
    if (line == 1) continue;  // "ply", checked by the caller
    if (w.empty()) continue;
    if (w[0] == "end_header" && w.size() == 1) {
      header_end = pos;
      break;
    }
    if (w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "format") {
      if (has_format || w.size() != 3 ||
          (w[1] != "ascii" && w[1] != "binary_little_endian" && w[1] != "binary_big_endian")) {
        return bad("invalid format line");
      }
      has_format = true;
      binary = w[1] != "ascii";
    } else if (w[0] == "element") {
      if (w.size() != 3) return bad("an element needs a name and a count");
      PlyElement e;
      e.name = std::string(w[1]);
      e.count = parse_count(w[2]);
      if (!e.count.valid) {
        return bad("element '" + e.name + "' has count '" + std::string(w[2]) + "', not a number");
      }
      elements.push_back(std::move(e));
    } else if (w[0] == "property") {
      if (elements.empty()) return bad("property before any element");
      PlyElement& e = elements.back();
      ++e.properties;
      e.is_list.push_back(w.size() >= 2 && w[1] == "list");
      if (w.size() >= 2 && w[1] == "list") {
        if (w.size() != 5) return bad("a list property needs two types and a name");
        const std::size_t count_size = ply_type_size(w[2]);
        const std::string_view count_type = w[2];
        if (count_size == 0 || count_type.find("float") != std::string_view::npos ||
            count_type == "double") {
          return bad("list count type '" + std::string(w[2]) + "' is not an integer type");
        }
        if (ply_type_size(w[3]) == 0) return bad("unknown type '" + std::string(w[3]) + "'");
        e.binary_bytes += count_size;
        e.lists = true;
      } else {
        if (w.size() != 3) return bad("a property needs a type and a name");
        const std::size_t size = ply_type_size(w[1]);
        if (size == 0) return bad("unknown type '" + std::string(w[1]) + "'");
        e.binary_bytes += size;
      }
    }
    // Other lines are skipped: some exporters write comments without `comment`.
  }
  if (header_end == std::string_view::npos) {
    if (head.size() >= file_size) return "PLY header is not terminated by end_header";
    return "PLY header is longer than " + std::to_string(kHeadBytes / 1024) +
           " KiB or not terminated by end_header";
  }
  if (!has_format) return "PLY header has no format line";

  const std::uintmax_t available = file_size - header_end;
  long double needed = 0;
  for (const PlyElement& e : elements) {
    if (e.count.overflow) {
      return "PLY element '" + e.name + "' declares a count beyond 64 bits";
    }
    if (e.name == "vertex" && e.count.value > limits.max_vertices) {
      return too_many(e.count.value, "vertices", limits.max_vertices);
    }
    if (e.name == "face" && e.count.value > limits.max_triangles) {
      return too_many(e.count.value, "faces", limits.max_triangles);
    }
    if (e.count.value > file_size) {
      return "PLY element '" + e.name + "' declares " + std::to_string(e.count.value) +
             " entries, more than the file has bytes; truncated or corrupt";
    }
    // ASCII: every value takes a digit and a separator at least.
    const std::size_t per_element = binary ? e.binary_bytes : 2 * e.properties;
    needed += static_cast<long double>(e.count.value) * static_cast<long double>(per_element);
  }
  if (!binary && needed > 0) needed -= 1;  // the last value may end the file without separator
  if (needed > static_cast<long double>(available)) return beyond_file("PLY", needed, available);
  if (!binary) return check_ascii_ply_body(path, line, elements);
  return std::nullopt;
}

std::optional<std::string> check_binary_stl(std::string_view head, std::uintmax_t file_size,
                                            const collision::MeshLimits& limits) {
  std::size_t i = 0;
  while (i < head.size() && std::isspace(static_cast<unsigned char>(head[i]))) ++i;
  if (lower(head.substr(i, 5)) == "solid") return std::nullopt;  // ASCII (or ambiguous)
  constexpr std::uintmax_t kHeader = 84;
  constexpr std::uintmax_t kPerTriangle = 50;
  if (file_size < kHeader) {
    return "binary STL is shorter than its 84-byte header (" + std::to_string(file_size) +
           " bytes); truncated or not an STL file";
  }
  if (head.size() < kHeader) return std::nullopt;
  std::uint32_t count = 0;
  for (int k = 3; k >= 0; --k) {
    count = (count << 8) | static_cast<unsigned char>(head[80 + static_cast<std::size_t>(k)]);
  }
  const std::uintmax_t needed = kHeader + kPerTriangle * std::uintmax_t{count};
  // Text that does not start with "solid": neither kind of STL.
  const bool text = std::all_of(head.begin(), head.begin() + kHeader, [](char c) {
    return std::isprint(static_cast<unsigned char>(c)) ||
           std::isspace(static_cast<unsigned char>(c));
  });
  if (text && needed != file_size) {
    return "is not an STL file: it is text but does not start with 'solid' (an ASCII STL), "
           "and read as a binary STL its header declares " +
           std::to_string(count) + " triangles, " + std::to_string(needed) +
           " bytes, where the file has " + std::to_string(file_size);
  }
  if (count > limits.max_triangles) return too_many(count, "triangles", limits.max_triangles);
  if (needed > file_size) {
    return "binary STL declares " + std::to_string(count) + " triangles (" +
           std::to_string(needed) + " bytes) but the file has " + std::to_string(file_size) +
           " bytes; truncated";
  }
  return std::nullopt;
}

/// A node hierarchy deeper than kMaxNodeDepth (the importer's recursion
/// would overflow the stack on some thousands of levels).
std::optional<std::string> check_gltf_nodes(const std::filesystem::path& path, bool binary,
                                            std::uintmax_t file_size) {
  const std::optional<std::string> json = gltf_json(path, binary, file_size);
  if (!json) return std::nullopt;
  const std::optional<std::size_t> depth = gltf_node_depth(*json);
  if (depth == kJsonTooDeep) return std::string("its JSON is nested deeper than 256 levels");
  if (!depth || *depth <= kMaxNodeDepth) return std::nullopt;
  return "its node hierarchy is " + std::to_string(*depth) + " levels deep; at most " +
         std::to_string(kMaxNodeDepth) + " are read";
}

}  // namespace

std::optional<std::string> check_declared_sizes(const std::filesystem::path& path,
                                                std::uintmax_t file_size,
                                                const collision::MeshLimits& limits) {
  const std::string head = read_head(path, kHeadBytes);
  const std::string extension = lower(path.extension().string());

  // The PLY reader takes any file that starts with "ply", whatever follows on
  // that line (a first line "ply?" made it hang), and any .ply file whatever
  // its first line, so all of them are checked.
  if (head.compare(0, 3, "ply") == 0 || extension == ".ply") {
    if (head.size() < 4 || (head[3] != '\n' && head[3] != '\r')) {
      return std::string("PLY header line 1: expected 'ply' alone on the line");
    }
    return check_ply(path, head, file_size, limits);
  }
  if (extension == ".stl") return check_binary_stl(head, file_size, limits);
  if (extension == ".obj") return check_obj_lines(path, limits);
  if (extension == ".gltf" || extension == ".glb")
    return check_gltf_nodes(path, extension == ".glb", file_size);
  return std::nullopt;
}

}  // namespace dovetail::engine::detail
