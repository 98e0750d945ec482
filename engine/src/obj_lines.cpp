#include "obj_lines.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "dovetail/engine/pose_list.h"

namespace dovetail::engine::detail {

namespace {

bool space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

/// The next word of `line` from `at` (empty at the end of the line); `at`
/// moves past it. A '#' after the keyword is a word like any other: assimp
/// reads no comment there (a face "f 1 2 3 # c" fails in it).
std::string_view next_word(std::string_view line, std::size_t& at) {
  while (at < line.size() && space(line[at])) ++at;
  const std::size_t start = at;
  while (at < line.size() && !space(line[at])) ++at;
  return line.substr(start, at - start);
}

/// The whole word as a vertex number (an integer, maybe negative), or
/// nullopt.
std::optional<std::int64_t> vertex_number(std::string_view word) {
  const char* first = word.data();
  const char* last = word.data() + word.size();
  if (first != last && *first == '+') ++first;
  std::int64_t value = 0;
  const auto [ptr, ec] = std::from_chars(first, last, value);
  if (first == last || ptr != last || ec != std::errc()) return std::nullopt;
  return value;
}

/// `text` in quotes for a message: at most 60 characters, a tab as \t,
/// other control characters and bytes outside ASCII as '?'.
std::string quoted(std::string_view text) {
  constexpr std::size_t kLongest = 60;
  std::string out(1, '\'');
  for (const char c : text.substr(0, kLongest)) {
    if (c == '\t')
      out += "\\t";
    else
      out.push_back(c >= 0x20 && c < 0x7f ? c : '?');
  }
  if (text.size() > kLongest) out.append("...");
  out.push_back('\'');
  return out;
}

std::string at_line(std::uint64_t line, const std::string& what) {
  return "line " + std::to_string(line) + ": " + what;
}

}  // namespace

std::optional<std::string> check_obj_lines(const std::filesystem::path& path,
                                           const collision::MeshLimits& limits) {
  std::ifstream in(path, std::ios::binary);
  std::string text;
  std::uint64_t line_number = 0;
  std::uint64_t vertices = 0;
  std::uint64_t faces = 0;
  // Faces naming a vertex not defined yet (line, highest such vertex),
  // checked at the end: a vertex may be defined further down.
  std::vector<std::pair<std::uint64_t, std::uint64_t>> ahead;
  while (std::getline(in, text)) {
    ++line_number;
    if (line_number == 1 && text.starts_with("\xEF\xBB\xBF")) {
      return at_line(1,
                     "starts with a byte-order mark, which the OBJ reader does not skip; "
                     "save the file without it (as plain UTF-8 or ASCII)");
    }
    const std::string_view line = text;
    std::size_t at = 0;
    const std::string_view keyword = next_word(line, at);
    if ((keyword == "v" || keyword == "f") && space(line[0])) {
      // assimp passes over such a line without a word.
      return at_line(line_number, quoted(line) + " is indented; a " +
                                      (keyword == "v" ? "vertex" : "face") +
                                      " line must start at the beginning of the line");
    }
    if (keyword == "v") {
      ++vertices;
      if (vertices > limits.max_vertices) {
        return "has more than " + std::to_string(limits.max_vertices) +
               " vertex lines, over the limit";
      }
      for (int k = 0; k < 3; ++k) {
        const std::string_view word = next_word(line, at);
        if (word.empty()) {
          return at_line(line_number, "a vertex needs three numbers (x y z), this one has " +
                                          std::to_string(k) + ": " + quoted(line));
        }
        const std::optional<double> x = parse_real(word);
        if (!x) {
          return at_line(line_number,
                         quoted(word) + " is not a number, in the vertex " + quoted(line));
        }
        if (!std::isfinite(*x)) {
          // Checked here: the OBJ reader drops a vertex no face uses unseen.
          return at_line(line_number, quoted(word) + " is not finite, in the vertex " +
                                          quoted(line) + "; a vertex must be, used or not");
        }
        if (word.front() == '.') {
          // assimp 5.2 drops such a line without a word, and every later
          // vertex number then names the vertex after the one meant.
          return at_line(line_number,
                         quoted(word) + " has no digit before its decimal point, in the vertex " +
                             quoted(line) + "; the OBJ reader cannot read it: write 0" +
                             std::string(word));
        }
      }
    } else if (keyword == "f") {
      ++faces;
      std::uint64_t highest = 0;
      if (faces > limits.max_triangles) {
        return "has more than " + std::to_string(limits.max_triangles) +
               " face lines, over the triangle limit";
      }
      for (std::string_view word = next_word(line, at); !word.empty(); word = next_word(line, at)) {
        const std::string_view corner = word.substr(0, word.find('/'));
        const std::optional<std::int64_t> v = vertex_number(corner);
        if (!v || *v == 0) {
          return at_line(line_number, quoted(word) +
                                          " is not a vertex number (1, 2, ... or -1, -2, ...), "
                                          "in the face " +
                                          quoted(line));
        }
        if (*v < 0 && static_cast<std::uint64_t>(-(*v + 1)) >= vertices) {
          return at_line(line_number, "the face " + quoted(line) + " refers to vertex " +
                                          std::to_string(*v) + ", but only " +
                                          std::to_string(vertices) + " vertices come before it");
        }
        if (*v > 0) highest = std::max(highest, static_cast<std::uint64_t>(*v));
      }
      if (highest > vertices) ahead.emplace_back(line_number, highest);
    }
  }
  if (in.bad()) return std::string("cannot be read");
  for (const auto& [line, vertex] : ahead) {
    if (vertex <= vertices) continue;
    return at_line(line, "a face refers to vertex " + std::to_string(vertex) +
                             ", but the file has " + std::to_string(vertices) +
                             (vertices == 1 ? " vertex" : " vertices"));
  }
  return std::nullopt;
}

std::optional<UniqueObjects> obj_with_unique_objects(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream read;
  read << in.rdbuf();
  if (in.bad() || !read) return std::nullopt;
  const std::string text = read.str();

  // Lines as [start, end) without the line break, which stays where it was.
  std::vector<std::pair<std::size_t, std::size_t>> lines;
  for (std::size_t start = 0; start < text.size();) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    lines.emplace_back(start, end);
    start = end + 1;
  }
  // The name an `o` line gives (the word after the keyword, as assimp reads
  // it) and where it lies in the text; the name a `g` line gives (the rest of
  // the line, trailing blanks trimmed).
  struct ObjectLine {
    std::size_t at;
    std::string name;
    std::size_t line;
  };
  std::vector<ObjectLine> objects;
  std::set<std::string> taken;
  std::vector<std::pair<std::size_t, bool>> order;  // (index into objects or groups, is `o`)
  std::vector<std::string> groups;
  for (std::size_t k = 0; k < lines.size(); ++k) {
    const auto [start, end] = lines[k];
    const std::string_view line(text.data() + start, end - start);
    std::size_t at = 0;
    const std::string_view keyword = next_word(line, at);
    if (keyword == "o") {
      const std::string_view name = next_word(line, at);
      if (name.empty()) continue;
      objects.push_back(
          {start + static_cast<std::size_t>(name.data() - line.data()), std::string(name), k + 1});
      taken.insert(std::string(name));
      order.emplace_back(objects.size() - 1, true);
    } else if (keyword == "g") {
      while (at < line.size() && space(line[at])) ++at;
      std::size_t last = line.size();
      while (last > at && space(line[last - 1])) --last;
      if (last == at) continue;
      groups.emplace_back(line.substr(at, last - at));
      taken.insert(groups.back());
      order.emplace_back(groups.size() - 1, false);
    }
  }

  // Which `o` lines repeat a name seen before them, in file order.
  std::set<std::string> seen;
  std::vector<std::pair<std::size_t, std::string>> renames;  // (object, new name)
  for (const auto& [index, is_object] : order) {
    if (!is_object) {
      seen.insert(groups[index]);
      continue;
    }
    const std::string& name = objects[index].name;
    if (seen.insert(name).second) continue;
    std::string fresh;
    for (std::size_t k = 2;; ++k) {
      fresh = name + "_" + std::to_string(k);
      if (taken.count(fresh) == 0) break;
    }
    taken.insert(fresh);
    renames.emplace_back(index, fresh);
  }
  if (renames.empty()) return std::nullopt;

  UniqueObjects out;
  std::size_t copied = 0;
  for (const auto& [index, fresh] : renames) {
    const ObjectLine& object = objects[index];
    out.text.append(text, copied, object.at - copied);
    out.text += fresh;
    copied = object.at + object.name.size();
    // As string_view: std::quoted would be found for a std::string.
    out.notes.push_back(at_line(object.line, "the object " + quoted(std::string_view(object.name)) +
                                                 " repeats an earlier name; it is read as " +
                                                 quoted(std::string_view(fresh))));
  }
  out.text.append(text, copied, std::string::npos);
  return out;
}

}  // namespace dovetail::engine::detail
