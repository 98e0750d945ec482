// Loading a scenario: run the file once in the sandbox, then read the tables
// the vocabulary's constructors built, check them against the vocabulary and
// resolve every name.
//
// The tables are read with raw access only (lua_rawget, lua_next, type
// checks before conversions), which never runs a metamethod and raises no
// Lua error short of running out of memory, so C++ exceptions can carry the
// loader's errors without crossing Lua's C frames.

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <lua.hpp>
#include <map>
#include <numbers>
#include <set>
#include <sstream>

#include "dovetail/collision/primitives.h"
#include "dovetail/engine/mesh_import.h"
#include "dovetail/engine/pose_list.h"
#include "dovetail/interaction/hand_model.h"
#include "dovetail/interaction/overlap.h"
#include "dovetail/scripting/lua_host.h"
#include "dovetail/scripting/scenario.h"

namespace dovetail::scripting {

namespace {

using collision::Mat3;
using collision::Real;

constexpr const char* kPreludeName = "dovetail prelude";
/// Defines one constructor per word: it packs its arguments and marks the
/// table with the word's name and where it was called. Where each named
/// declaration (a part, mate or region) was made is listed in `made`.
constexpr const char* kPrelude = R"lua(
local words, where, made = ...
local pack = table.pack
for i = 1, #words do
  local name = words[i]
  local list = made[name]
  rawset(_ENV, name, function(...)
    local t = pack(...)
    t.__word = name
    t.__where = where()
    if list then list[#list + 1] = t.__where end
    return t
  end)
end
)lua";

/// `file:line` of the innermost caller outside the prelude. Raises no error
/// and holds no C++ object (it runs inside Lua).
int where_function(lua_State* L) {
  lua_Debug ar;
  char buffer[1024];
  buffer[0] = '\0';
  for (int level = 1; lua_getstack(L, level, &ar) != 0; ++level) {
    if (lua_getinfo(L, "Sl", &ar) == 0) break;
    if (ar.currentline <= 0 || ar.source == nullptr) continue;
    const char* source = ar.source[0] == '@' || ar.source[0] == '=' ? ar.source + 1 : ar.source;
    if (std::strcmp(source, kPreludeName) == 0) continue;
    std::snprintf(buffer, sizeof buffer, "%s:%d", source, ar.currentline);
    break;
  }
  lua_pushstring(L, buffer);
  return 1;
}

/// The sandbox globals' __index while a scenario file is read: a name that
/// is no global is an error, not nil. A word written without its quotes
/// (`steps_in_order { carry }`, `units = m`, `fixed = yes`) would otherwise
/// leave its field unset without a word. Custom actions, run later, read
/// unset globals as nil, as Lua does (`count = (count or 0) + 1`).
int unknown_global(lua_State* L) {
  if (lua_type(L, 2) != LUA_TSTRING) return 0;
  char message[512];
  const char* key = lua_tostring(L, 2);
  try {
    const std::string name(key);
    std::vector<std::string> words;
    for (const Word& w : vocabulary()) words.emplace_back(w.name);
    std::string hint = did_you_mean(name, words);
    if (hint.empty()) {
      hint = " (a name is given in quotes, \"" + name + "\"; true and false without)";
    }
    std::snprintf(message, sizeof message, "unknown name '%s'%s", name.c_str(), hint.c_str());
  } catch (...) {  // no exception may cross Lua's C frames
    std::snprintf(message, sizeof message, "unknown name '%s'", key);
  }  // no C++ object lives on past here: lua_error does not return
  luaL_where(L, 1);
  lua_pushstring(L, message);
  lua_concat(L, 2);
  return lua_error(L);
}

/// The declarations whose tables are keyed by name: the same name given
/// twice in one table leaves only the later, without a word from Lua.
constexpr std::array<const char*, 3> kNamedDeclarations = {"part", "mate", "region"};

/// The name a line gives the first declaration of `word` on it, `peg` in
/// `peg = part {` or `["peg"] = part {`; empty when it gives none.
std::string declared_name(const std::string& line, std::string_view word) {
  const auto name_char = [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_';
  };
  for (std::size_t at = line.find(word); at != std::string::npos; at = line.find(word, at + 1)) {
    const std::size_t end = at + word.size();
    if ((at > 0 && name_char(line[at - 1])) || (end < line.size() && name_char(line[end]))) {
      continue;  // part of a longer name
    }
    std::size_t i = at;
    while (i > 0 && line[i - 1] == ' ') --i;
    if (i == 0 || line[i - 1] != '=') continue;
    --i;
    while (i > 0 && line[i - 1] == ' ') --i;
    if (i > 0 && line[i - 1] == ']') {  // ["name"]
      --i;
      while (i > 0 && line[i - 1] == ' ') --i;
      if (i == 0 || line[i - 1] != '"') continue;
      const std::size_t close = --i;
      const std::size_t open = line.rfind('"', close == 0 ? 0 : close - 1);
      if (open == std::string::npos || open == close) continue;
      return line.substr(open + 1, close - open - 1);
    }
    std::size_t from = i;
    while (from > 0 && name_char(line[from - 1])) --from;
    if (from < i && std::isdigit(static_cast<unsigned char>(line[from])) == 0) {
      return line.substr(from, i - from);
    }
  }
  return "";
}

/// The line of the file's last `return scenario` outside a comment: where
/// a scenario returned directly was declared. Lua keeps no line for it (the
/// call in a `return` is a tail call, whose caller's frame is gone). 0 when
/// there is none.
int return_line(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  std::string text;
  int number = 0, found = 0;
  bool in_block_comment = false;  // --[[ ... ]], as scenarios write them
  const auto word_char = [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_';
  };
  while (std::getline(in, text)) {
    ++number;
    if (number == 1 && text.rfind("\xEF\xBB\xBF", 0) == 0) text.erase(0, 3);  // a BOM
    std::size_t from = 0;
    if (in_block_comment) {
      const std::size_t close = text.find("]]");
      if (close == std::string::npos) continue;
      in_block_comment = false;
      from = close + 2;
    }
    const std::size_t comment = text.find("--", from);
    if (comment != std::string::npos && text.compare(comment, 4, "--[[") == 0 &&
        text.find("]]", comment + 4) == std::string::npos) {
      in_block_comment = true;
    }
    const std::size_t end = comment == std::string::npos ? text.size() : comment;
    for (std::size_t at = text.find("return", from); at < end; at = text.find("return", at + 1)) {
      if (at > 0 && word_char(text[at - 1])) continue;
      std::size_t k = at + 6;
      if (k < text.size() && word_char(text[k])) continue;
      while (k < text.size() && std::isspace(static_cast<unsigned char>(text[k]))) ++k;
      if (text.compare(k, 8, "scenario") == 0 && (k + 8 >= text.size() || !word_char(text[k + 8])))
        found = number;
    }
  }
  return found;
}

SourceLocation parse_where(const std::string& text, const std::string& fallback_file) {
  const std::size_t colon = text.rfind(':');
  if (colon == std::string::npos) return {fallback_file, 0};
  SourceLocation where{text.substr(0, colon), 0};
  try {
    where.line = std::stoi(text.substr(colon + 1));
  } catch (const std::exception&) {
    return {fallback_file, 0};
  }
  return where;
}

/// The largest coordinate a scenario may give, in metres: the collision
/// layer's limit for a mesh (collision::MeshLimits), as a pose list's.
constexpr double kCoordinateLimit_m = 1e30;

/// A size for a warning, to three figures.
std::string brief(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.3g", x);
  return buffer;
}

/// A mesh's size: the diagonal of its box, in its own units.
double across(const collision::Mesh& mesh) {
  const collision::Bounds b = collision::mesh_bounds(mesh);
  return (b.max - b.min).norm();
}

/// Of "mm", "cm" and "m", the unit in which numbers read in `units` as
/// `metres` would give the size nearest `target` metres (by ratio), among
/// those a hundred times or more from `units` (the size warnings fire at
/// hundreds of times: a factor of 10, mm for cm, cannot be the cause); or
/// `units` when none comes nearer.
std::string likely_units(double metres, const std::string& units, double target) {
  const double per_unit = engine::metres_per_unit(units).value_or(1);
  const double numbers = metres / per_unit;
  std::string best = units;
  double best_error = std::abs(std::log(metres / target));
  for (const char* unit : {"mm", "cm", "m"}) {
    const double other = *engine::metres_per_unit(unit);
    if (std::max(other, per_unit) / std::min(other, per_unit) < 100) continue;
    const double error = std::abs(std::log(numbers * other / target));
    if (error < best_error) {
      best = unit;
      best_error = error;
    }
  }
  return best;
}

/// The end of a warning of a mesh file in other units: how its numbers are
/// read, and the `units` that would read them as `likely` (its_or_their:
/// "Its" for a part, "Their" for parts).
std::string units_hint(const std::string& its_or_their, const std::string& units,
                       const std::string& likely, const std::string& the_part_or_parts) {
  std::string hint = its_or_their + " numbers are read in " + units;
  if (likely != units) {
    hint += "; if they are in " + likely + ", give " + the_part_or_parts + " units = \"" + likely +
            "\"";
  }
  return hint;
}

std::string format_number(double x) {
  if (std::isnan(x)) return "nan (not a number, as 0/0 gives)";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.10g", x);
  return buffer;
}

const std::map<std::string, std::array<float, 3>, std::less<>>& color_names() {
  static const std::map<std::string, std::array<float, 3>, std::less<>> names = {
      {"red", {0.86F, 0.16F, 0.16F}},   {"orange", {1.0F, 0.55F, 0.0F}},
      {"yellow", {0.95F, 0.85F, 0.1F}}, {"green", {0.2F, 0.7F, 0.25F}},
      {"blue", {0.2F, 0.4F, 0.9F}},     {"purple", {0.55F, 0.3F, 0.75F}},
      {"grey", {0.6F, 0.6F, 0.6F}},     {"gray", {0.6F, 0.6F, 0.6F}},
      {"white", {0.97F, 0.97F, 0.97F}}, {"black", {0.1F, 0.1F, 0.1F}},
      {"steel", {0.62F, 0.66F, 0.72F}}, {"brass", {0.8F, 0.65F, 0.25F}},
  };
  return names;
}

/// A table whose fields lack a comma gets the question whether one is
/// missing after Lua's own message. (A misspelt word, `touchs(...)`, is
/// named by unknown_global, with the word suggested.)
ScriptError with_comma_hint(const ScriptError& e) {
  const std::string& first = e.message();
  const auto with_hint = [&](const std::string& hint) {
    const std::string what = e.what();
    const std::size_t end = what.find('\n');
    return ScriptError(e.kind(), end == std::string::npos
                                     ? what + hint
                                     : what.substr(0, end) + hint + what.substr(end));
  };
  // A table's fields run on without a comma: Lua stops at the next field,
  // on the line after the one that lacks it.
  // Only where the next field begins (a name, a value), not at a stray ')'.
  if (const std::size_t near = first.find(" near '");
      e.kind() == ScriptError::Kind::kSyntax && first.find("'}' expected") != std::string::npos &&
      near != std::string::npos && near + 7 < first.size()) {
    const char c = first[near + 7];
    if (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '"' || c == '\'' ||
        c == '{' || c == '[') {
      return with_hint(" (is a comma missing at the end of the field before?)");
    }
  }
  return e;
}

class Loader {
 public:
  Loader(LuaHost& host, const std::filesystem::path& file,
         std::vector<std::filesystem::path>* files_read, bool hand_given)
      : host_(host),
        L_(host.state()),
        file_(file.string()),
        folder_(file.parent_path()),
        files_read_(files_read),
        hand_given_(hand_given) {}

  ~Loader() { luaL_unref(L_, LUA_REGISTRYINDEX, made_); }
  Loader(const Loader&) = delete;
  Loader& operator=(const Loader&) = delete;

  Scenario load();
  void warn_about_mesh_sizes();
  void warn_about_parts_beside_the_hand();
  void warn_about_open_surfaces();
  void warn_about_overlapping_parts();
  void warn_about_dropped_declarations();
  void warn_about_gltf_units();
  void warn_about_nodes_taken_twice();
  void warn_about_parts_named_in_custom(const Clause& custom,
                                        const std::vector<std::string>& parts);
  /// The scenario file's lines, read once.
  const std::vector<std::string>& source_lines() {
    if (!source_lines_) {
      source_lines_.emplace();
      std::ifstream in(file_, std::ios::binary);
      for (std::string line; std::getline(in, line);) source_lines_->push_back(line);
    }
    return *source_lines_;
  }
  /// The part of that name, or null.
  const PartSpec* part_named(const std::string& name) const {
    for (const PartSpec& p : scenario_.parts) {
      if (p.name == name) return &p;
    }
    return nullptr;
  }

 private:
  /// Sets a flag for its lifetime.
  class Flag {
   public:
    explicit Flag(bool& flag) : flag_(flag) { flag_ = true; }
    ~Flag() { flag_ = false; }
    Flag(const Flag&) = delete;
    Flag& operator=(const Flag&) = delete;

   private:
    bool& flag_;
  };

  /// A mistake in the file, where it is.
  struct Problem {
    SourceLocation where;
    std::string message;
  };

  /// A problem after which reading cannot go on: reported at once, with
  /// those noted before it.
  [[noreturn]] void fail(const SourceLocation& where, const std::string& message) const {
    if (reading_optional_field_) {
      // An optional field's mistake: noted, the field left unread (its
      // default stands in, and nothing else depends on it), reading goes on.
      noted_.push_back({where, message});
      throw OptionalFieldProblem{};
    }
    if (reading_part_) {
      // A mistake that stops reading a part: noted, the part kept by its
      // name alone (what names it still resolves), reading goes on with
      // the next; the check fails at its end with every mistake.
      noted_.push_back({where, message});
      throw PartProblem{};
    }
    std::vector<Problem> all = noted_;
    all.push_back({where, message});
    // A NUL in a name would end the message there: control bytes as \xNN.
    throw ScenarioError(engine::escape_control_bytes(in_line_order(std::move(all)), "\n\t"));
  }

  /// A problem after which reading can go on: an unknown field or item is
  /// left unread, a name nothing declares unresolved. Kept, and reported
  /// with the others when reading ends (throw_noted), so that one check
  /// names every such mistake, by line.
  void note(const SourceLocation& where, const std::string& message) {
    noted_.push_back({where, message});
  }

  /// The line of `key = ...` in the declaration `word { ... }` that opens
  /// on the line of `where`: the field assigned directly in its table (not
  /// in a table within it), outside strings and comments; where itself when
  /// there is none (a declaration of a table built elsewhere, `part(spec)`,
  /// or by a loop). Lua keeps no line for a table's fields, so a mistake in
  /// one would otherwise be named at the line its declaration opens.
  SourceLocation field_line(const SourceLocation& where, std::string_view word,
                            std::string_view key) {
    if (where.line <= 0 || key.empty()) return where;
    const std::string cache_key = where.file + '\n' + std::to_string(where.line) + '\n' +
                                  std::string(word) + '\n' + std::string(key);
    if (const auto hit = field_lines_.find(cache_key); hit != field_lines_.end()) {
      return {where.file, hit->second};
    }
    auto [it, fresh] = source_text_.try_emplace(where.file);
    if (fresh) {
      std::ifstream in(where.file, std::ios::binary);
      std::ostringstream text;
      text << in.rdbuf();
      it->second = text.str();
    }
    const int line = find_field_line(it->second, where.line, word, key);
    field_lines_.emplace(cache_key, line > 0 ? line : where.line);
    return {where.file, line > 0 ? line : where.line};
  }

  /// field_line's scan of `text`; 0 when the field is not found.
  static int find_field_line(const std::string& text, int declaration_line, std::string_view word,
                             std::string_view key) {
    const auto is_name = [](char c) {
      return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_';
    };
    // The start of the declaration's line.
    std::size_t i = 0;
    int line = 1;
    while (line < declaration_line && i < text.size()) {
      if (text[i++] == '\n') ++line;
    }
    if (line != declaration_line) return 0;
    // `word` then `{` (or `({`) on that line, as a whole name.
    const std::size_t line_end = std::min(text.find('\n', i), text.size());
    std::size_t open = std::string::npos;
    for (std::size_t at = text.find(word, i); at != std::string::npos && at < line_end;
         at = text.find(word, at + 1)) {
      if ((at > 0 && is_name(text[at - 1])) ||
          (at + word.size() < text.size() && is_name(text[at + word.size()]))) {
        continue;
      }
      std::size_t next = at + word.size();
      while (next < line_end && (text[next] == ' ' || text[next] == '\t' || text[next] == '(')) {
        ++next;
      }
      if (next < line_end && text[next] == '{') {
        open = next;
        break;
      }
    }
    if (open == std::string::npos) return 0;
    // Through the table, skipping strings and comments, to `key =` at depth 1.
    int depth = 0;
    for (std::size_t at = open; at < text.size(); ++at) {
      const char c = text[at];
      if (c == '\n') {
        ++line;
      } else if (c == '-' && at + 1 < text.size() && text[at + 1] == '-') {
        // A comment: long (`--[[ ... ]]`, `--[==[`) or to the end of the line.
        std::size_t level_end = at + 2;
        if (level_end < text.size() && text[level_end] == '[') {
          std::size_t eq = level_end + 1;
          while (eq < text.size() && text[eq] == '=') ++eq;
          if (eq < text.size() && text[eq] == '[') {
            const std::string close = "]" + std::string(eq - level_end - 1, '=') + "]";
            const std::size_t end = text.find(close, eq);
            for (std::size_t k = at; k < std::min(end, text.size()); ++k) line += text[k] == '\n';
            if (end == std::string::npos) return 0;
            at = end + close.size() - 1;
            continue;
          }
        }
        const std::size_t end = text.find('\n', at);
        if (end == std::string::npos) return 0;
        at = end - 1;
      } else if (c == '"' || c == '\'') {
        for (++at; at < text.size() && text[at] != c && text[at] != '\n'; ++at) {
          if (text[at] == '\\') ++at;
        }
      } else if (c == '[' && at + 1 < text.size() && (text[at + 1] == '[' || text[at + 1] == '=')) {
        std::size_t eq = at + 1;
        while (eq < text.size() && text[eq] == '=') ++eq;
        if (eq < text.size() && text[eq] == '[') {  // a long string
          const std::string close = "]" + std::string(eq - at - 1, '=') + "]";
          const std::size_t end = text.find(close, eq);
          for (std::size_t k = at; k < std::min(end, text.size()); ++k) line += text[k] == '\n';
          if (end == std::string::npos) return 0;
          at = end + close.size() - 1;
        }
      } else if (c == '{') {
        ++depth;
      } else if (c == '}') {
        if (--depth == 0) return 0;  // the declaration ends without the field
      } else if (depth == 1 && is_name(c) && (at == 0 || !is_name(text[at - 1])) &&
                 text.compare(at, key.size(), key) == 0 &&
                 (at + key.size() >= text.size() || !is_name(text[at + key.size()]))) {
        std::size_t next = at + key.size();
        while (next < text.size() && (text[next] == ' ' || text[next] == '\t')) ++next;
        if (next < text.size() && text[next] == '=' &&
            (next + 1 >= text.size() || text[next + 1] != '=')) {
          return line;
        }
      }
    }
    return 0;
  }

  void throw_noted() const {
    if (!noted_.empty()) {
      throw ScenarioError(engine::escape_control_bytes(in_line_order(noted_), "\n\t"));
    }
  }

  /// One line a problem, in the order of the file (problems of the whole
  /// file first), at most kShownProblems of them.
  static std::string in_line_order(std::vector<Problem> problems) {
    constexpr std::size_t kShownProblems = 20;
    std::stable_sort(problems.begin(), problems.end(), [](const Problem& x, const Problem& y) {
      return x.where.line < y.where.line;
    });
    std::string out;
    for (std::size_t i = 0; i < problems.size() && i < kShownProblems; ++i) {
      if (i > 0) out += '\n';
      out += problems[i].where.str() + ": " + problems[i].message;
    }
    if (problems.size() > kShownProblems) {
      out += "\n(and " + std::to_string(problems.size() - kShownProblems) + " more)";
    }
    return out;
  }

  // ---- raw table access on absolute stack indices
  /// t[key] without metamethods, pushed; `table` is an absolute index.
  int raw_getfield(int table, const char* key) {
    lua_pushstring(L_, key);
    return lua_rawget(L_, table);
  }
  /// The same for a key that may hold NUL bytes (a name read from the file).
  int raw_getfield(int table, const std::string& key) {
    lua_pushlstring(L_, key.data(), key.size());
    return lua_rawget(L_, table);
  }
  int type_of_field(int table, const char* key) {
    lua_pushstring(L_, key);
    return lua_rawget(L_, table);  // leaves the value on the stack
  }
  /// The string at `index` whole, NUL bytes included (a number is converted).
  std::string string_at(int index) {
    std::size_t length = 0;
    const char* text = lua_tolstring(L_, index, &length);
    return text != nullptr ? std::string(text, length) : std::string();
  }
  std::string string_field(int table, const char* key) {
    std::string out;
    if (type_of_field(table, key) == LUA_TSTRING) out = string_at(-1);
    lua_pop(L_, 1);
    return out;
  }
  std::string word_of(int index) {
    return lua_type(L_, index) == LUA_TTABLE ? string_field(index, "__word") : std::string();
  }
  SourceLocation where_of(int index, const SourceLocation& fallback) {
    if (lua_type(L_, index) != LUA_TTABLE) return fallback;
    const std::string text = string_field(index, "__where");
    return text.empty() ? fallback : parse_where(text, file_);
  }
  /// The number of positional arguments a word was called with (its `n`).
  int packed_count(int index) {
    int n = 0;
    if (type_of_field(index, "n") == LUA_TNUMBER) n = static_cast<int>(lua_tointeger(L_, -1));
    lua_pop(L_, 1);
    return n;
  }
  /// A short rendering of the value at `index` for messages.
  std::string describe(int index) {
    switch (lua_type(L_, index)) {
      case LUA_TSTRING:
        return "\"" + string_at(index) + "\"";
      case LUA_TNUMBER:
        return format_number(lua_tonumber(L_, index));
      case LUA_TBOOLEAN:
        return lua_toboolean(L_, index) ? "true" : "false";
      case LUA_TNIL:
        return "nil";
      case LUA_TFUNCTION:
        return "function";
      case LUA_TTABLE: {
        const std::string word = word_of(index);
        if (!word.empty()) return word + "(...)";
        // A short list of names or numbers is shown as written.
        const lua_Unsigned n = lua_rawlen(L_, index);
        if (n == 0 || n > 8) return "{...}";
        std::string list = "{ ";
        for (lua_Unsigned i = 1; i <= n; ++i) {
          lua_rawgeti(L_, index, static_cast<lua_Integer>(i));
          const int item = lua_gettop(L_);
          const bool simple =
              lua_type(L_, item) == LUA_TSTRING || lua_type(L_, item) == LUA_TNUMBER;
          const std::string text = simple ? describe(item) : "";
          lua_pop(L_, 1);
          if (!simple) return "{...}";
          list += (i > 1 ? ", " : "") + text;
        }
        return list + " }";
      }
      default:
        return lua_typename(L_, lua_type(L_, index));
    }
  }
  /// Keys of the table at `index`: strings sorted, then the integer keys.
  void keys_of(int index, std::vector<std::string>& strings, std::vector<lua_Integer>& integers,
               const SourceLocation& where, const std::string& what) {
    lua_pushnil(L_);
    while (lua_next(L_, index) != 0) {
      lua_pop(L_, 1);
      if (lua_type(L_, -1) == LUA_TSTRING) {
        strings.push_back(string_at(-1));
      } else if (lua_isinteger(L_, -1)) {
        integers.push_back(lua_tointeger(L_, -1));
      } else {
        lua_pop(L_, 1);
        fail(where, what + ": a key that is neither a name nor a position");
      }
    }
    std::sort(strings.begin(), strings.end());
    std::sort(integers.begin(), integers.end());
  }

  // ---- values
  double number_at(int index, const SourceLocation& where, const std::string& what) {
    if (lua_type(L_, index) != LUA_TNUMBER) {
      fail(where, what + " must be a number, not " + describe(index));
    }
    const double x = lua_tonumber(L_, index);
    if (!std::isfinite(x)) fail(where, what + " must be finite");
    return x;
  }
  Vec3 vector_at(int index, const SourceLocation& where, const std::string& what) {
    if (lua_type(L_, index) != LUA_TTABLE || !word_of(index).empty()) {
      fail(where, what + " must be three numbers { x, y, z }, not " + describe(index));
    }
    Vec3 v;
    for (int i = 0; i < 3; ++i) {
      lua_rawgeti(L_, index, i + 1);
      if (lua_type(L_, -1) != LUA_TNUMBER) {
        lua_pop(L_, 1);
        fail(where, what + " must be three numbers { x, y, z }");
      }
      v[i] = lua_tonumber(L_, -1);
      lua_pop(L_, 1);
      if (!std::isfinite(v[i])) fail(where, what + " must be finite");
      // As a pose list's: beyond it, products of coordinates overflow.
      if (std::abs(v[i]) * scenario_.metres_per_unit > kCoordinateLimit_m) {
        fail(where, what + ": " + format_number(v[i]) + " is beyond the coordinate limit of " +
                        format_number(kCoordinateLimit_m / scenario_.metres_per_unit) + " " +
                        scenario_.units);
      }
    }
    if (lua_rawlen(L_, index) != 3) fail(where, what + " must be exactly three numbers");
    return v;
  }
  Vec3 direction_at(int index, const SourceLocation& where, const std::string& what) {
    if (lua_type(L_, index) == LUA_TSTRING) {
      const std::string s = string_at(index);
      static const std::map<std::string, Vec3> axes = {
          {"x", Vec3::UnitX()},   {"y", Vec3::UnitY()},   {"z", Vec3::UnitZ()},
          {"+x", Vec3::UnitX()},  {"+y", Vec3::UnitY()},  {"+z", Vec3::UnitZ()},
          {"-x", -Vec3::UnitX()}, {"-y", -Vec3::UnitY()}, {"-z", -Vec3::UnitZ()}};
      const auto it = axes.find(s);
      if (it == axes.end())
        fail(where, what + " must be \"x\", \"-y\", ... or { x, y, z }, not \"" + s + "\"");
      return it->second;
    }
    const Vec3 v = vector_at(index, where, what);
    if (!(v.norm() > 0)) fail(where, what + " must not be zero");
    return v.normalized();
  }
  std::array<float, 3> color_at(int index, const SourceLocation& where, const std::string& what) {
    if (lua_type(L_, index) == LUA_TSTRING) {
      const std::string s = string_at(index);
      const auto it = color_names().find(s);
      if (it == color_names().end()) {
        std::vector<std::string> names;
        for (const auto& [name, rgb] : color_names()) names.push_back(name);
        std::string hint = did_you_mean(s, names);
        if (hint.empty()) {
          hint = " (a colour is one of";
          for (const std::string& n : names) hint += (n == names.front() ? " " : ", ") + n;
          hint += ", or {r, g, b} in [0, 1])";
        }
        fail(where, what + ": unknown colour '" + s + "'" + hint);
      }
      return it->second;
    }
    const Vec3 v = vector_at(index, where, what);
    if (v.minCoeff() < 0 || v.maxCoeff() > 1) fail(where, what + " must be in [0, 1]");
    return {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z())};
  }
  std::vector<std::string> names_at(int index, const SourceLocation& where,
                                    const std::string& what) {
    if (lua_type(L_, index) == LUA_TSTRING) return {string_at(index)};
    if (lua_type(L_, index) != LUA_TTABLE || !word_of(index).empty()) {
      fail(where, what + " must be a list of names { \"a\", \"b\" }, not " + describe(index));
    }
    std::vector<std::string> names;
    const lua_Integer n = static_cast<lua_Integer>(lua_rawlen(L_, index));
    for (lua_Integer i = 1; i <= n; ++i) {
      lua_rawgeti(L_, index, i);
      if (lua_type(L_, -1) != LUA_TSTRING) {
        lua_pop(L_, 1);
        fail(where, what + " must be a list of names");
      }
      names.push_back(string_at(-1));
      lua_pop(L_, 1);
    }
    return names;
  }

  /// Reads the value at `index` as `param` says into an Arg (not for kWord/kList/kMap/kTable).
  Arg arg_at(int index, const Param& param, const SourceLocation& where, const std::string& what) {
    Arg arg;
    arg.given = true;
    const std::string name = what + " '" + std::string(param.name) + "'";
    switch (param.type) {
      case ArgType::kPart:
      case ArgType::kPartOrHand:
      case ArgType::kMate:
      case ArgType::kStep:
      case ArgType::kRegion:
      case ArgType::kText:
      case ArgType::kGraspType:
      case ArgType::kFile:
        if (lua_type(L_, index) != LUA_TSTRING) {
          fail(where, name + " must be " +
                          (param.type == ArgType::kText ? std::string("text in quotes")
                                                        : "a name in quotes") +
                          ", not " + describe(index));
        }
        arg.text = string_at(index);
        if (param.type == ArgType::kFile && arg.text.find('\0') != std::string::npos) {
          fail(where, name + ": a file name cannot hold a NUL byte: \"" + arg.text + "\"");
        }
        if (param.type == ArgType::kGraspType && arg.text != "precision" && arg.text != "tripod" &&
            arg.text != "power") {
          fail(where,
               name + " must be \"precision\", \"tripod\" or \"power\", not \"" + arg.text + "\"");
        }
        break;
      case ArgType::kSeconds:
      case ArgType::kLength:
      case ArgType::kNumber:
      case ArgType::kCount:
        arg.number = number_at(index, where, name);
        if (param.type != ArgType::kNumber && arg.number < 0)
          fail(where, name + " must not be negative");
        if (param.type == ArgType::kCount && arg.number != std::floor(arg.number)) {
          fail(where, name + " must be a whole number");
        }
        if (param.type == ArgType::kLength) arg.number *= scenario_.metres_per_unit;
        break;
      case ArgType::kVector:
        arg.vector = vector_at(index, where, name) * scenario_.metres_per_unit;
        break;
      case ArgType::kDirection:
        arg.vector = direction_at(index, where, name);
        break;
      case ArgType::kTurn: {
        if (lua_type(L_, index) != LUA_TTABLE)
          fail(where, name + " must be { x = deg, y = deg, z = deg }");
        std::vector<std::string> keys;
        std::vector<lua_Integer> positions;
        keys_of(index, keys, positions, where, name);
        if (!positions.empty()) fail(where, name + " must name its axes: { x = 90 }");
        for (const std::string& key : keys) {
          if (key != "x" && key != "y" && key != "z")
            fail(where, name + ": unknown axis '" + key + "'");
          raw_getfield(index, key);
          const double deg = number_at(lua_gettop(L_), where, name + "." + key);
          lua_pop(L_, 1);
          arg.vector[key[0] - 'x'] = deg;
        }
        break;
      }
      case ArgType::kColor:
        arg.color = color_at(index, where, name);
        break;
      case ArgType::kFunction:
        if (lua_type(L_, index) != LUA_TFUNCTION) fail(where, name + " must be a function");
        lua_pushvalue(L_, index);
        arg.function_ref = luaL_ref(L_, LUA_REGISTRYINDEX);
        break;
      case ArgType::kFlag:
        if (lua_type(L_, index) != LUA_TBOOLEAN) fail(where, name + " must be true or false");
        arg.number = lua_toboolean(L_, index) ? 1 : 0;
        break;
      case ArgType::kNames:
        arg.names = names_at(index, where, name);
        break;
      case ArgType::kTable:
      case ArgType::kList:
      case ArgType::kMap:
      case ArgType::kWord:
        fail(where, name + ": internal error, structured field read as a value");
    }
    return arg;
  }

  /// The vocabulary word whose constructor the value at `index` is (a word
  /// written without its arguments, `mate_made,`), or "".
  std::string word_function(int index) {
    if (lua_type(L_, index) != LUA_TFUNCTION) return "";
    index = lua_absindex(L_, index);
    host_.push_env();
    std::string found;
    for (const Word& w : vocabulary()) {
      lua_pushlstring(L_, w.name.data(), w.name.size());
      lua_rawget(L_, -2);
      const bool same = lua_rawequal(L_, -1, index) != 0;
      lua_pop(L_, 1);
      if (same) {
        found = w.name;
        break;
      }
    }
    lua_pop(L_, 1);
    return found;
  }

  /// A use of an event/state/action/expectation word at `index`, of one of `kinds`.
  Clause clause_at(int index, std::initializer_list<WordKind> kinds, const SourceLocation& outer,
                   const std::string& what) {
    const std::string word_name = word_of(index);
    const Word* word = word_name.empty() ? nullptr : find_word(word_name);
    const auto with_article = [](std::string_view noun) {
      return std::string(std::string_view("aeiou").find(noun.front()) != std::string_view::npos
                             ? "an "
                             : "a ") +
             std::string(noun);
    };
    std::string expected;
    for (const WordKind k : kinds) {
      expected += (expected.empty() ? "" : " or ") + with_article(word_kind_name(k));
    }
    if (word == nullptr) {
      if (const std::string bare = word_function(index); !bare.empty()) {
        fail(outer, what + " is the word '" + bare + "' without its arguments: write, say, " +
                        std::string(find_word(bare)->example));
      }
      fail(outer, what + " must be " + expected + ", not " + describe(index));
    }
    const SourceLocation where = where_of(index, outer);
    if (std::find(kinds.begin(), kinds.end(), word->kind) == kinds.end()) {
      fail(where, what + " must be " + expected + "; '" + word_name + "' is " +
                      with_article(word_kind_name(word->kind)));
    }
    Clause clause;
    clause.word = word;
    clause.where = where;
    clause.args.resize(word->params.size());
    const int n = packed_count(index);
    if (n > static_cast<int>(word->params.size())) {
      fail(where, word_name + " takes at most " + std::to_string(word->params.size()) +
                      " argument(s), got " + std::to_string(n));
    }
    clause.text = word_name + "(";
    for (int i = 0; i < n; ++i) {
      lua_rawgeti(L_, index, i + 1);
      const int value = lua_gettop(L_);
      clause.text += (i ? ", " : "") + describe(value);
      if (lua_type(L_, value) != LUA_TNIL) {
        clause.args[static_cast<std::size_t>(i)] =
            arg_at(value, word->params[static_cast<std::size_t>(i)], where, word_name);
      }
      lua_pop(L_, 1);
    }
    clause.text += ")";
    for (std::size_t i = 0; i < word->params.size(); ++i) {
      if (!word->params[i].optional && !clause.args[i].given) {
        fail(where, word_name + ": missing argument '" + std::string(word->params[i].name) + "'");
      }
    }
    if (word_name == "every" && !(clause.args[0].number > 0)) {
      fail(where, "every: the period must be more than 0 seconds");
    }
    return clause;
  }

  /// Checks that the declaration at `index` is `word_name { ... }` and pushes its field table.
  SourceLocation open_declaration(int index, const char* word_name, const SourceLocation& outer,
                                  const std::string& what) {
    const std::string word = word_of(index);
    if (word != word_name) {
      fail(outer, what + " must be " + word_name + " { ... }, not " + describe(index));
    }
    const SourceLocation where = where_of(index, outer);
    if (packed_count(index) != 1)
      fail(where, std::string(word_name) + " takes one table: " + word_name + " { ... }");
    lua_rawgeti(L_, index, 1);
    if (lua_type(L_, -1) != LUA_TTABLE || !word_of(lua_gettop(L_)).empty()) {
      fail(where, std::string(word_name) + " takes one table: " + word_name + " { ... }");
    }
    return where;
  }

  /// Checks the field names of the table at `index` against `word`; integer keys allowed up to
  /// `positional`.
  void check_fields(int index, const Word& word, const SourceLocation& where,
                    const std::string& what, lua_Integer positional = 0) {
    std::vector<std::string> keys;
    std::vector<lua_Integer> positions;
    keys_of(index, keys, positions, where, what);
    std::vector<std::string> known;
    for (const Param& p : word.params) known.emplace_back(p.name);
    for (const std::string& key : keys) {
      if (std::find(known.begin(), known.end(), key) == known.end()) {
        note(field_line(where, word.name, key),
             what + ": unknown field '" + key + "'" + did_you_mean(key, known));
      }
    }
    for (const lua_Integer p : positions) {
      if (p < 1 || p > positional) note(where, what + ": unexpected item " + std::to_string(p));
    }
  }
  const Param& param(const Word& word, std::string_view name) {
    for (const Param& p : word.params) {
      if (p.name == name) return p;
    }
    throw ScenarioError("internal error: no field " + std::string(name));
  }
  /// Reads field `name` of the table at `index` as its Param says; not given when absent.
  Arg field(int index, const Word& word, std::string_view name, const SourceLocation& where,
            const std::string& what) {
    const Param& p = param(word, name);
    Arg arg;
    const int top = lua_gettop(L_);
    raw_getfield(index, std::string(name));
    if (lua_type(L_, -1) != LUA_TNIL && p.optional && !reading_optional_field_) {
      // A mistake here is noted and reading goes on, so that one check
      // names the mistakes of every field.
      try {
        const Flag reading(reading_optional_field_);
        arg = arg_at(lua_gettop(L_), p, field_line(where, word.name, name), what);
      } catch (const OptionalFieldProblem&) {
        arg = Arg{};
        lua_settop(L_, top + 1);
      }
    } else if (lua_type(L_, -1) != LUA_TNIL) {
      arg = arg_at(lua_gettop(L_), p, field_line(where, word.name, name), what);
    } else if (!p.optional) {
      lua_pop(L_, 1);
      fail(where, what + ": missing field '" + std::string(name) + "'");
    }
    lua_pop(L_, 1);
    return arg;
  }

  /// A part's mesh file read (whole, or the nodes selected), scaled from its
  /// units to metres; for a selection, `taken` gets which of the file's
  /// imported parts it took.
  std::shared_ptr<const collision::Mesh> read_mesh_file(const std::filesystem::path& path,
                                                        const Arg& nodes, const Arg& without,
                                                        double metres_per_unit,
                                                        const SourceLocation& where,
                                                        const std::string& what,
                                                        std::vector<char>& taken) {
    collision::Mesh loaded;
    try {
      if (nodes.given || without.given) {
        loaded = select_nodes(path, nodes.given ? nodes.names : without.names, nodes.given, where,
                              what, taken);
      } else {
        auto [it, fresh] = whole_imports_.try_emplace(path.string());
        if (fresh) {
          try {
            it->second = engine::import_file(path, {});
          } catch (...) {
            whole_imports_.erase(it);
            throw;
          }
        }
        for (const std::string& f : it->second.files) note_file(f);
        loaded = it->second.parts.front().mesh;
      }
    } catch (const ScenarioError&) {
      throw;
    } catch (const std::exception& e) {
      fail(where, what + ": " + e.what());
    }
    for (Vec3& v : loaded.vertices) v *= metres_per_unit;
    return std::make_shared<const collision::Mesh>(std::move(loaded));
  }

  /// The named nodes of a mesh file (or all but them) as one mesh in the
  /// file's frame; `taken` gets which of the file's imported parts it took.
  collision::Mesh select_nodes(const std::filesystem::path& path,
                               const std::vector<std::string>& names, bool keep,
                               const SourceLocation& where, const std::string& what,
                               std::vector<char>& taken) {
    auto [it, fresh] = imports_.try_emplace(path.string());
    if (fresh) {
      engine::ImportOptions options;
      options.merge = false;
      try {
        it->second = engine::import_file(path, options);
      } catch (...) {
        imports_.erase(it);  // a file that failed is not an empty one
        throw;
      }
      for (const std::string& f : it->second.files) note_file(f);
    }
    const engine::ImportReport& report = it->second;
    // A name takes its node whole (all its meshes: a glTF node's primitives
    // are imported as parts `name`, `name_2`, ...), and a group's name every
    // part below the group (a sub-assembly).
    std::vector<char> listed(report.parts.size(), 0);
    for (const std::string& name : names) {
      std::set<std::size_t> nodes;
      for (const engine::ImportedPart& p : report.parts) {
        if (p.name == name) nodes.insert(p.node);
      }
      bool found = false;
      for (std::size_t i = 0; i < report.parts.size(); ++i) {
        const engine::ImportedPart& p = report.parts[i];
        if (nodes.count(p.node) != 0 ||
            std::find(p.groups.begin(), p.groups.end(), name) != p.groups.end()) {
          listed[i] = 1;
          found = true;
        }
      }
      if (!found) {
        std::set<std::string> known;
        for (const engine::ImportedPart& p : report.parts) {
          known.insert(p.name);
          known.insert(p.groups.begin(), p.groups.end());
        }
        const std::vector<std::string> candidates(known.begin(), known.end());
        fail(where, what + ": " + path.filename().string() + " has no node '" + name + "'" +
                        did_you_mean(name, candidates));
      }
    }
    std::vector<Vec3> vertices;
    std::vector<collision::TriangleIndices> triangles;
    taken.assign(report.parts.size(), 0);
    for (std::size_t i = 0; i < report.parts.size(); ++i) {
      const engine::ImportedPart& p = report.parts[i];
      if ((listed[i] != 0) != keep) continue;
      taken[i] = 1;
      const auto base = static_cast<std::uint32_t>(vertices.size());
      vertices.insert(vertices.end(), p.mesh.vertices.begin(), p.mesh.vertices.end());
      for (collision::TriangleIndices tri : p.mesh.triangles) {
        for (auto& index : tri) index += base;
        triangles.push_back(tri);
      }
    }
    if (triangles.empty())
      fail(where, what + ": no triangles are left of " + path.filename().string());
    return collision::make_mesh(std::move(vertices), std::move(triangles), path.string());
  }

  /// The sorted names of a table of named declarations, such as
  /// `parts = { peg = part { ... } }`; `noun` is "part", `example` its example.
  std::vector<std::string> declaration_names(int map, const SourceLocation& where,
                                             const std::string& field, const std::string& noun,
                                             const std::string& example) {
    if (lua_type(L_, map) != LUA_TTABLE || !word_of(map).empty()) {
      fail(where, "scenario: " + field + " must be a table of named " + noun + "s: " + example);
    }
    std::vector<std::string> names;
    std::vector<lua_Integer> positions;
    keys_of(map, names, positions, where, field);
    if (!positions.empty()) fail(where, field + ": every " + noun + " needs a name: " + example);
    for (const std::string& name : names) {
      if (name.empty()) fail(where, field + ": a " + noun + "'s name may not be empty: " + example);
    }
    return names;
  }

  void read_scenario_fields(int table, const SourceLocation& where);
  void read_parts(int map, const SourceLocation& where);
  /// Reads the part `part.name` of the parts table at `map` into `part`.
  void read_part(int map, PartSpec& part);
  std::shared_ptr<const collision::Mesh> read_shape(int index, const SourceLocation& where,
                                                    const std::string& what);
  void read_mates(int map, const SourceLocation& where);
  void read_regions(int map, const SourceLocation& where);
  void read_glove(int index, const SourceLocation& where);
  void read_steps(int list, const SourceLocation& where);
  void read_rules(int list, const SourceLocation& where);
  void read_expectations(int list, const SourceLocation& where);
  /// Every name a clause may refer to, by kind.
  struct Names {
    std::vector<std::string> parts, mates, steps, regions;
    /// The parts, and "hand" when the scenario has one: what a misspelt
    /// name where the hand may stand is nearest ("hnad": 'hand').
    std::vector<std::string> parts_or_hand;
  };
  void resolve();
  void resolve_clause(const Clause& clause, const Names& names);

  LuaHost& host_;
  lua_State* L_;
  /// The registry's reference to the lists of where each named declaration
  /// was made (the prelude's `made`).
  int made_ = LUA_NOREF;
  std::optional<std::vector<std::string>> source_lines_;
  std::string file_;
  /// A file the scenario names, into *files_read_ (kept when loading fails).
  void note_file(const std::filesystem::path& path) {
    if (files_read_ != nullptr) files_read_->push_back(path);
  }

  std::filesystem::path folder_;
  Scenario scenario_;
  mutable std::vector<Problem> noted_;  ///< see note(), and fail() in an optional field
  /// Set while an optional field's value is read (field()): see fail().
  mutable bool reading_optional_field_ = false;
  struct OptionalFieldProblem {};
  /// Set while a part is read (read_parts): see fail().
  mutable bool reading_part_ = false;
  struct PartProblem {};
  std::vector<std::filesystem::path>* files_read_ = nullptr;
  bool hand_given_ = false;  ///< a replayed trace gives the hand the scenario lacks
  /// The text of the files read, and the lines found, for field_line.
  std::map<std::string, std::string> source_text_;
  std::map<std::string, int> field_lines_;
  std::map<std::string, engine::ImportReport> imports_;  ///< mesh files read by node
  /// A part made of nodes of a file: which it took, and where it stands.
  struct NodesTaken {
    std::string part, file;  ///< file: the key of imports_
    std::vector<char> taken;
  };
  std::vector<NodesTaken> nodes_taken_;
  /// Parts declared `open_surface = true`: no warning about their surface.
  std::set<std::string> open_surfaces_;
  /// Mesh files read whole, once however many parts name them (each read is
  /// a process of its own).
  std::map<std::string, engine::ImportReport> whole_imports_;
  /// The mesh of every file and node selection read so far, and for a
  /// selection which of the file's imported parts it took.
  struct ReadMesh {
    std::shared_ptr<const collision::Mesh> mesh;
    std::vector<char> taken;
  };
  std::map<std::string, ReadMesh> meshes_;
};

Scenario Loader::load() {
  scenario_.file = file_;
  note_file(file_);
  // Define the vocabulary's constructors in the sandbox.
  host_.run_string("return function(...) " + std::string(kPrelude) + " end", kPreludeName, 1);
  lua_createtable(L_, static_cast<int>(vocabulary().size()), 0);
  int i = 1;
  for (const Word& word : vocabulary()) {
    lua_pushlstring(L_, word.name.data(), word.name.size());
    lua_rawseti(L_, -2, i++);
  }
  lua_pushcfunction(L_, where_function);
  lua_createtable(L_, 0, static_cast<int>(kNamedDeclarations.size()));
  for (const char* word : kNamedDeclarations) {
    lua_newtable(L_);
    lua_setfield(L_, -2, word);
  }
  lua_pushvalue(L_, -1);
  made_ = luaL_ref(L_, LUA_REGISTRYINDEX);
  host_.call(3, 0);

  // Unknown names are errors while the file runs, and nil again after.
  const auto set_unknown_global = [&](lua_CFunction handler) {
    host_.push_env();
    lua_getmetatable(L_, -1);
    if (handler) {
      lua_pushcfunction(L_, handler);
    } else {
      lua_pushnil(L_);
    }
    lua_setfield(L_, -2, "__index");
    lua_pop(L_, 2);
  };
  const int base = lua_gettop(L_);
  set_unknown_global(unknown_global);
  try {
    host_.run_file(file_, 1);
  } catch (const ScriptError& e) {
    set_unknown_global(nullptr);
    throw with_comma_hint(e);
  } catch (...) {
    set_unknown_global(nullptr);
    throw;
  }
  set_unknown_global(nullptr);
  const int top = base + 1;
  const SourceLocation file_only{file_, 0};
  if (word_of(top) != "scenario") {
    fail(file_only,
         "the file must end with `return scenario { ... }`; it returned " + describe(top));
  }
  SourceLocation where = open_declaration(top, "scenario", file_only, "the file's result");
  if (where.line == 0) where.line = return_line(file_);
  read_scenario_fields(lua_gettop(L_), where);
  lua_settop(L_, base);
  resolve();
  throw_noted();
  return std::move(scenario_);
}

void Loader::read_scenario_fields(int table, const SourceLocation& where) {
  const Word& word = *find_word("scenario");
  check_fields(table, word, where, "scenario");
  scenario_.name = field(table, word, "name", where, "scenario").text;
  // Units first: every length depends on them.
  // A value out of its range is noted at the field's line and its default
  // stands, so that one check names every such mistake.
  const auto at = [&](std::string_view key) { return field_line(where, "scenario", key); };
  const Arg units = field(table, word, "units", where, "scenario");
  if (units.given) {
    if (const std::optional<double> metres = engine::metres_per_unit(units.text)) {
      scenario_.units = units.text;
      scenario_.metres_per_unit = *metres;
    } else {
      note(at("units"),
           "scenario: units must be \"mm\", \"cm\" or \"m\", not \"" + units.text + "\"");
    }
  }
  if (const Arg a = field(table, word, "seed", where, "scenario"); a.given) {
    scenario_.seed = static_cast<std::uint64_t>(a.number);
  }
  if (const Arg a = field(table, word, "duration", where, "scenario"); a.given) {
    if (a.number > kMaxRunSeconds) {
      note(at("duration"),
           "scenario: duration must be at most " + format_number(kMaxRunSeconds) + " s");
    } else {
      scenario_.duration = a.number;
    }
  }
  if (const Arg a = field(table, word, "time_step", where, "scenario"); a.given) {
    if (!(a.number >= 1e-4 && a.number <= 1)) {
      note(at("time_step"),
           "scenario: time_step must be in [0.0001, 1] s, not " + format_number(a.number));
    } else {
      scenario_.time_step = a.number;
    }
  }
  // "exact" or a length: not one of the argument types, so read here.
  raw_getfield(table, "accuracy");
  if (lua_type(L_, -1) == LUA_TNUMBER) {
    const double tolerance = lua_tonumber(L_, -1);
    if (!(tolerance > 0) || !std::isfinite(tolerance)) {
      note(at("accuracy"),
           "scenario: accuracy must be \"exact\" or a length > 0 (a tolerance), not " +
               format_number(tolerance));
    } else {
      scenario_.tolerance_m = tolerance * scenario_.metres_per_unit;
    }
  } else if (lua_type(L_, -1) != LUA_TNIL &&
             !(lua_type(L_, -1) == LUA_TSTRING && string_at(-1) == "exact")) {
    note(at("accuracy"),
         std::string("scenario: accuracy must be \"exact\" or a length > 0 (a tolerance), "
                     "not a ") +
             luaL_typename(L_, -1) +
             (lua_type(L_, -1) == LUA_TSTRING ? " \"" + string_at(-1) + "\"" : std::string()));
  }
  lua_pop(L_, 1);
  auto with_field = [&](const char* name, auto read) {
    raw_getfield(table, name);
    if (lua_type(L_, -1) != LUA_TNIL) read(lua_gettop(L_));
    lua_pop(L_, 1);
  };
  raw_getfield(table, "parts");
  if (lua_type(L_, -1) == LUA_TNIL) fail(where, "scenario: missing field 'parts'");
  lua_pop(L_, 1);
  with_field("parts", [&](int i) { read_parts(i, where); });
  with_field("mates", [&](int i) { read_mates(i, where); });
  with_field("regions", [&](int i) { read_regions(i, where); });
  with_field("hand", [&](int i) { read_glove(i, where); });
  with_field("steps", [&](int i) { read_steps(i, where); });
  with_field("rules", [&](int i) { read_rules(i, where); });
  with_field("expect", [&](int i) { read_expectations(i, where); });
  with_field("camera", [&](int i) {
    const SourceLocation camera_at = at("camera");
    if (lua_type(L_, i) != LUA_TTABLE)
      fail(camera_at, "scenario: camera must be { from = {x, y, z}, to = {x, y, z} }");
    std::vector<std::string> keys;
    std::vector<lua_Integer> positions;
    keys_of(i, keys, positions, camera_at, "camera");
    for (const std::string& key : keys) {
      if (key != "from" && key != "to") {
        const std::vector<std::string> known = {"from", "to"};
        fail(camera_at, "scenario: camera has no field '" + key + "'" + did_you_mean(key, known) +
                            ": it is { from = {x, y, z}, to = {x, y, z} }");
      }
    }
    if (keys != std::vector<std::string>{"from", "to"} || !positions.empty()) {
      fail(camera_at, "scenario: camera must be { from = {x, y, z}, to = {x, y, z} }");
    }
    engine::Camera camera;
    raw_getfield(i, "from");
    camera.eye = vector_at(lua_gettop(L_), camera_at, "camera 'from'") * scenario_.metres_per_unit;
    lua_pop(L_, 1);
    raw_getfield(i, "to");
    camera.target = vector_at(lua_gettop(L_), camera_at, "camera 'to'") * scenario_.metres_per_unit;
    lua_pop(L_, 1);
    if (!((camera.eye - camera.target).norm() > 0))
      fail(camera_at, "scenario: camera 'from' and 'to' are the same point");
    // Straight down (or up) the y axis, up on the picture is -z, as for
    // `render --camera top`: y, the usual up, is along the view.
    const Vec3 view = (camera.target - camera.eye).normalized();
    if (view.cross(camera.up).norm() <= 1e-9) camera.up = -Vec3::UnitZ();
    scenario_.camera = camera;
  });
}

void Loader::read_parts(int map, const SourceLocation& where) {
  const std::vector<std::string> names =
      declaration_names(map, where, "parts", "part", "parts = { peg = part { ... } }");
  if (names.empty()) fail(where, "scenario: parts is empty");
  for (const std::string& name : names) {
    const int top = lua_gettop(L_);
    PartSpec part;
    part.name = name;
    part.where = where;
    try {
      const Flag reading(reading_part_);
      read_part(map, part);
    } catch (const PartProblem&) {
      // Noted: the part stands by its name alone, without a mesh.
      lua_settop(L_, top);
      part.mesh = nullptr;
      part.file.clear();
      part.attached_to.clear();
    }
    scenario_.parts.push_back(std::move(part));
  }
}

void Loader::read_part(int map, PartSpec& part) {
  const Word& word = *find_word("part");
  const std::string& name = part.name;
  {
    const SourceLocation& where = part.where;
    raw_getfield(map, name);
    const int declaration = lua_gettop(L_);
    const std::string what = "part '" + name + "'";
    part.where = open_declaration(declaration, "part", where, what);
    const int t = lua_gettop(L_);
    check_fields(t, word, part.where, what);
    if (name == "hand" || name.rfind("hand.", 0) == 0) {
      fail(part.where, what + ": the names 'hand' and 'hand.*' belong to the hand");
    }
    raw_getfield(t, "shape");
    const bool has_shape = lua_type(L_, -1) != LUA_TNIL;
    if (has_shape) part.mesh = read_shape(lua_gettop(L_), part.where, what);
    lua_pop(L_, 1);
    const Arg mesh = field(t, word, "mesh", part.where, what);
    if (has_shape == mesh.given)
      fail(part.where, what + ": give either shape = ... or mesh = \"file\"");
    const Arg nodes = field(t, word, "nodes", part.where, what);
    const Arg without = field(t, word, "without", part.where, what);
    if ((nodes.given || without.given) && !mesh.given) {
      fail(part.where, what + ": nodes and without select from a mesh file");
    }
    if (nodes.given && without.given) fail(part.where, what + ": give either nodes or without");
    double file_metres_per_unit = scenario_.metres_per_unit;
    if (const Arg units = field(t, word, "units", part.where, what); units.given) {
      if (!mesh.given) {
        fail(field_line(part.where, "part", "units"),
             what + ": units are a mesh file's; a shape's lengths are in the scenario's units");
      }
      if (const std::optional<double> metres = engine::metres_per_unit(units.text)) {
        part.file_units = units.text;
        file_metres_per_unit = *metres;
      } else {
        fail(field_line(part.where, "part", "units"),
             what + ": units must be \"mm\", \"cm\" or \"m\", not \"" + units.text + "\"");
      }
    }
    if (mesh.given) {
      const std::filesystem::path path = folder_ / mesh.text;
      note_file(path);  // named by the scenario, read or not: never to be overwritten
      part.file = mesh.text;
      // Parts that name the same file and the same nodes share one mesh, so
      // that its hull, hierarchies and distance models are built once.
      std::error_code ec;
      const std::filesystem::path where_on_disk = std::filesystem::weakly_canonical(path, ec);
      std::string key = (ec ? path.lexically_normal() : where_on_disk).string();
      key += '\0' + std::to_string(file_metres_per_unit);
      for (const auto& [which, arg] :
           {std::pair{"nodes", &nodes}, std::pair{"without", &without}}) {
        if (!arg->given) continue;
        std::vector<std::string> names = arg->names;  // in any order: the same selection
        std::sort(names.begin(), names.end());
        key += '\0';
        key += which;
        for (const std::string& node : names) (key += '\0') += node;
      }
      auto known = meshes_.find(key);
      if (known == meshes_.end()) {
        ReadMesh read;
        read.mesh = read_mesh_file(path, nodes, without, file_metres_per_unit, part.where, what,
                                   read.taken);
        known = meshes_.emplace(key, std::move(read)).first;
      }
      part.mesh = known->second.mesh;  // a known one's files were noted when it was read
      if (nodes.given || without.given) {
        nodes_taken_.push_back({name, path.string(), known->second.taken});
      }
    }
    if (const Arg at = field(t, word, "at", part.where, what); at.given) part.X_WP.t = at.vector;
    if (const Arg turn = field(t, word, "turn", part.where, what); turn.given) {
      const Vec3 rad = turn.vector * (std::numbers::pi / 180);
      part.X_WP.R =
          (Eigen::AngleAxisd(rad.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rad.y(), Vec3::UnitY()) *
           Eigen::AngleAxisd(rad.x(), Vec3::UnitX()))
              .toRotationMatrix();
    }
    part.fixed = field(t, word, "fixed", part.where, what).number != 0;
    if (field(t, word, "open_surface", part.where, what).number != 0) {
      open_surfaces_.insert(part.name);
    }
    part.attached_to = field(t, word, "attached_to", part.where, what).text;
    if (const Arg c = field(t, word, "color", part.where, what); c.given) part.color = c.color;
    part.tags = field(t, word, "tags", part.where, what).names;
    lua_pop(L_, 2);
  }
}

std::shared_ptr<const collision::Mesh> Loader::read_shape(int index, const SourceLocation& outer,
                                                          const std::string& what) {
  const std::string word_name = word_of(index);
  const Word* word = word_name.empty() ? nullptr : find_word(word_name);
  if (word == nullptr || word->kind != WordKind::kShape) {
    fail(outer, what +
                    ": shape must be box, cylinder, block_with_hole, tube or sphere { ... }, not " +
                    describe(index));
  }
  const SourceLocation where = open_declaration(index, word_name.c_str(), outer, what);
  const int t = lua_gettop(L_);
  check_fields(t, *word, where, word_name);
  auto get = [&](std::string_view name) { return field(t, *word, name, where, word_name); };
  auto sides = [&](int fallback) {
    const Arg a = get("sides");
    if (!a.given) return fallback;
    if (a.number < 3 || a.number > 4096) fail(where, word_name + ": sides must be in [3, 4096]");
    return static_cast<int>(a.number);
  };
  auto positive = [&](const Arg& a, const char* name) {
    if (!(a.number > 0)) fail(where, word_name + ": " + name + " must be positive");
    return a.number;
  };
  collision::Mesh mesh;
  try {
    if (word_name == "box") {
      const Vec3 size = get("size").vector;
      if (!(size.minCoeff() > 0)) fail(where, "box: every edge of size must be positive");
      mesh = collision::make_box(size / 2);
    } else if (word_name == "cylinder") {
      mesh = collision::make_cylinder(positive(get("diameter"), "diameter") / 2,
                                      positive(get("length"), "length"), sides(64));
    } else if (word_name == "block_with_hole") {
      const Vec3 size = get("size").vector;
      if (!(size.minCoeff() > 0))
        fail(where, "block_with_hole: every edge of size must be positive");
      mesh = collision::make_block_with_hole(size / 2, positive(get("hole"), "hole") / 2,
                                             positive(get("depth"), "depth"), sides(64));
    } else if (word_name == "tube") {
      const double outside = positive(get("outer"), "outer");
      const double inside = positive(get("inner"), "inner");
      if (!(inside < outside)) fail(where, "tube: inner must be less than outer");
      mesh = collision::make_tube(outside / 2, inside / 2, positive(get("length"), "length"),
                                  sides(64));
    } else {
      mesh = collision::make_sphere(positive(get("diameter"), "diameter") / 2, 3);
    }
  } catch (const ScenarioError&) {
    throw;
  } catch (const std::exception& e) {
    // The mesh maker's message (or the mesh check's), without its own name.
    std::string message = e.what();
    for (const char* own : {"make_", "generated "}) {
      if (message.rfind(own, 0) == 0 && message.find(": ") != std::string::npos) {
        message.erase(0, message.find(": ") + 2);
      }
    }
    fail(where, word_name + ": " + message);
  }
  lua_pop(L_, 1);
  return std::make_shared<const collision::Mesh>(std::move(mesh));
}

void Loader::read_mates(int map, const SourceLocation& where) {
  const std::vector<std::string> names =
      declaration_names(map, where, "mates", "mate", "mates = { fit = mate { ... } }");
  const Word& word = *find_word("mate");
  for (const std::string& name : names) {
    raw_getfield(map, name);
    const std::string what = "mate '" + name + "'";
    MateSpec spec;
    spec.where = open_declaration(lua_gettop(L_), "mate", where, what);
    const int t = lua_gettop(L_);
    check_fields(t, word, spec.where, what);
    interaction::Mate& m = spec.mate;
    m.name = name;
    m.part = field(t, word, "part", spec.where, what).text;
    m.p_PF = field(t, word, "point", spec.where, what).vector;
    m.axis_P = field(t, word, "axis", spec.where, what).vector;
    m.other = field(t, word, "into", spec.where, what).text;
    m.p_OF = field(t, word, "at", spec.where, what).vector;
    m.axis_O = field(t, word, "along", spec.where, what).vector;
    if (const Arg a = field(t, word, "tolerance", spec.where, what); a.given)
      m.position_tolerance = a.number;
    if (const Arg a = field(t, word, "angle", spec.where, what); a.given) {
      if (!(a.number > 0 && a.number <= 180))
        fail(spec.where, what + ": angle must be above 0 and at most 180 degrees, not " +
                             format_number(a.number));
      m.angle_tolerance_deg = a.number;
    }
    if (const Arg a = field(t, word, "guide", spec.where, what); a.given) m.guide = a.number != 0;
    if (m.part == m.other) fail(spec.where, what + ": a part cannot mate with itself");
    lua_pop(L_, 2);
    scenario_.mates.push_back(std::move(spec));
  }
}

void Loader::read_regions(int map, const SourceLocation& where) {
  const std::vector<std::string> names =
      declaration_names(map, where, "regions", "region", "regions = { tray = region { ... } }");
  const Word& word = *find_word("region");
  for (const std::string& name : names) {
    raw_getfield(map, name);
    const std::string what = "region '" + name + "'";
    RegionSpec spec;
    spec.where = open_declaration(lua_gettop(L_), "region", where, what);
    const int t = lua_gettop(L_);
    check_fields(t, word, spec.where, what);
    spec.region.name = name;
    spec.region.box.min = field(t, word, "min", spec.where, what).vector;
    spec.region.box.max = field(t, word, "max", spec.where, what).vector;
    const Arg parts = field(t, word, "parts", spec.where, what);
    if (parts.given && parts.names.empty()) {
      fail(field_line(spec.where, "region", "parts"),
           what + ": parts is empty; leave it out to watch every part and the hand");
    }
    spec.region.parts = parts.names;
    if ((spec.region.box.max - spec.region.box.min).minCoeff() < 0) {
      fail(spec.where, what + ": max must not be below min on any axis");
    }
    lua_pop(L_, 2);
    scenario_.regions.push_back(std::move(spec));
  }
}

void Loader::read_glove(int index, const SourceLocation& outer) {
  const Word& word = *find_word("glove");
  GloveSpec glove;
  glove.where = open_declaration(index, "glove", outer, "hand");
  const int t = lua_gettop(L_);
  check_fields(t, word, glove.where, "glove");
  const Arg plan = field(t, word, "plan", glove.where, "glove");
  const Arg trace = field(t, word, "trace", glove.where, "glove");
  if (plan.given == trace.given)
    fail(glove.where, "glove: give either plan = \"file\" or trace = \"file\"");
  if (plan.given) glove.plan = folder_ / plan.text;
  if (trace.given) glove.trace = folder_ / trace.text;
  // Read by the run unless it replays another trace; never to be overwritten.
  note_file(plan.given ? glove.plan : glove.trace);
  glove.holding = field(t, word, "holding", glove.where, "glove").text;
  if (const Arg a = field(t, word, "grasp", glove.where, "glove"); a.given) {
    glove.grasp = a.text == "precision" ? interaction::GraspType::kPrecision
                  : a.text == "tripod"  ? interaction::GraspType::kTripod
                                        : interaction::GraspType::kPower;
  }
  if (const Arg a = field(t, word, "hand_length", glove.where, "glove"); a.given) {
    if (a.number < 0.12 || a.number > 0.26) {
      // In the scenario's units, as the number was given.
      const double per_unit = scenario_.metres_per_unit;
      fail(field_line(glove.where, "glove", "hand_length"),
           "glove: hand_length must be " + brief(0.12 / per_unit) + " to " +
               brief(0.26 / per_unit) + " " + scenario_.units +
               (scenario_.units == "mm" ? "" : " (120 to 260 mm)") + ", not " +
               brief(a.number / per_unit) + " " + scenario_.units);
    }
    glove.hand_length = a.number;
  }
  raw_getfield(t, "noise");
  if (lua_type(L_, -1) != LUA_TNIL) {
    const int n = lua_gettop(L_);
    if (lua_type(L_, n) != LUA_TTABLE) fail(glove.where, "glove: noise must be a table");
    std::vector<std::string> keys;
    std::vector<lua_Integer> positions;
    keys_of(n, keys, positions, glove.where, "glove noise");
    interaction::GloveNoise noise;
    noise.donning_sigma_deg = 0;
    for (const std::string& key : keys) {
      raw_getfield(n, key);
      const double x = number_at(lua_gettop(L_), glove.where, "glove noise " + key);
      lua_pop(L_, 1);
      if (x < 0) fail(glove.where, "glove noise " + key + " must not be negative");
      if (key == "position") {
        noise.position_sigma_m = x * scenario_.metres_per_unit;
      } else if (key == "angle") {
        noise.orientation_sigma_deg = x;
      } else if (key == "joints") {
        noise.joint_sigma_deg = x;
      } else if (key == "seed") {
        noise.seed = static_cast<std::uint64_t>(x);
      } else {
        const std::vector<std::string> known = {"position", "angle", "joints", "seed"};
        fail(glove.where, "glove noise: unknown field '" + key + "'" + did_you_mean(key, known));
      }
    }
    glove.noise = noise;
  }
  lua_pop(L_, 2);
  scenario_.glove = std::move(glove);
}

void Loader::read_steps(int list, const SourceLocation& where) {
  if (lua_type(L_, list) != LUA_TTABLE || !word_of(list).empty()) {
    fail(where, "scenario: steps must be a list: steps = { step { ... }, ... }");
  }
  const Word& word = *find_word("step");
  const lua_Integer n = static_cast<lua_Integer>(lua_rawlen(L_, list));
  for (lua_Integer i = 1; i <= n; ++i) {
    lua_rawgeti(L_, list, i);
    const std::string what = "step " + std::to_string(i);
    StepSpec step;
    step.where = open_declaration(lua_gettop(L_), "step", where, what);
    const int t = lua_gettop(L_);
    check_fields(t, word, step.where, what, 2);
    auto text_at = [&](lua_Integer position, const char* key) {
      lua_rawgeti(L_, t, position);
      raw_getfield(t, key);
      std::string out;
      if (lua_type(L_, -2) != LUA_TNIL && lua_type(L_, -1) != LUA_TNIL) {
        fail(step.where, what + ": its " + key + " is given twice");
      }
      const int v = lua_type(L_, -2) != LUA_TNIL ? -2 : -1;
      if (lua_type(L_, v) != LUA_TNIL) {
        if (lua_type(L_, v) != LUA_TSTRING)
          fail(step.where, what + ": its " + key + " must be text");
        out = string_at(v);
      }
      lua_pop(L_, 2);
      return out;
    };
    step.name = text_at(1, "name");
    step.text = text_at(2, "text");
    if (step.name.empty())
      fail(step.where, what + ": a step needs a name: step { \"insert\", ... }");
    for (const StepSpec& other : scenario_.steps) {
      if (other.name == step.name) fail(step.where, "step '" + step.name + "' is declared twice");
    }
    raw_getfield(t, "done");
    if (lua_type(L_, -1) != LUA_TNIL) {
      step.done = clause_at(lua_gettop(L_), {WordKind::kEvent}, step.where,
                            "step '" + step.name + "': done");
    }
    lua_pop(L_, 3);
    scenario_.steps.push_back(std::move(step));
  }
}

void Loader::read_rules(int list, const SourceLocation& where) {
  if (lua_type(L_, list) != LUA_TTABLE || !word_of(list).empty()) {
    fail(where, "scenario: rules must be a list: rules = { rule { ... }, ... }");
  }
  const Word& word = *find_word("rule");
  const lua_Integer n = static_cast<lua_Integer>(lua_rawlen(L_, list));
  for (lua_Integer i = 1; i <= n; ++i) {
    lua_rawgeti(L_, list, i);
    const std::string what = "rule " + std::to_string(i);
    RuleSpec rule;
    rule.where = open_declaration(lua_gettop(L_), "rule", where, what);
    const int t = lua_gettop(L_);
    check_fields(t, word, rule.where, what);
    raw_getfield(t, "when");
    if (lua_type(L_, -1) == LUA_TNIL) fail(rule.where, what + ": missing field 'when'");
    rule.when = clause_at(lua_gettop(L_), {WordKind::kEvent}, rule.where, what + ": when");
    lua_pop(L_, 1);
    for (const char* key : {"unless", "only_if"}) {
      raw_getfield(t, key);
      if (lua_type(L_, -1) != LUA_TNIL) {
        Clause c = clause_at(lua_gettop(L_), {WordKind::kState}, rule.where, what + ": " + key);
        (std::strcmp(key, "unless") == 0 ? rule.unless : rule.only_if) = std::move(c);
      }
      lua_pop(L_, 1);
    }
    raw_getfield(t, "act");
    const int act = lua_gettop(L_);
    if (lua_type(L_, act) == LUA_TTABLE && word_of(act).empty()) {
      const lua_Integer m = static_cast<lua_Integer>(lua_rawlen(L_, act));
      for (lua_Integer k = 1; k <= m; ++k) {
        lua_rawgeti(L_, act, k);
        rule.act.push_back(
            clause_at(lua_gettop(L_), {WordKind::kAction}, rule.where, what + ": act"));
        lua_pop(L_, 1);
      }
    } else if (lua_type(L_, act) == LUA_TTABLE) {
      rule.act.push_back(clause_at(act, {WordKind::kAction}, rule.where, what + ": act"));
    } else {
      fail(rule.where, what + ": act must be a list of actions: act = { highlight \"block\" }");
    }
    if (rule.act.empty()) fail(rule.where, what + ": act lists no action");
    lua_pop(L_, 1);
    // The cooldown keeps a flickering contact from firing a rule frame after
    // frame; a timer's ticks are exact, and are kept from one another only
    // by a cooldown given.
    if (const Arg a = field(t, word, "cooldown", rule.where, what); a.given) {
      rule.cooldown = a.number;
    } else if (rule.when.word->name == "every" || rule.when.word->name == "after") {
      rule.cooldown = 0;
    }
    rule.once = field(t, word, "once", rule.where, what).number != 0;
    lua_pop(L_, 2);
    scenario_.rules.push_back(std::move(rule));
  }
}

void Loader::read_expectations(int list, const SourceLocation& where) {
  if (lua_type(L_, list) != LUA_TTABLE || !word_of(list).empty()) {
    fail(where, "scenario: expect must be a list: expect = { max_penetration(0.01), ... }");
  }
  const lua_Integer n = static_cast<lua_Integer>(lua_rawlen(L_, list));
  for (lua_Integer i = 1; i <= n; ++i) {
    lua_rawgeti(L_, list, i);
    scenario_.expectations.push_back(clause_at(lua_gettop(L_), {WordKind::kExpectation}, where,
                                               "expect item " + std::to_string(i)));
    lua_pop(L_, 1);
  }
}

void Loader::resolve_clause(const Clause& clause, const Names& names) {
  const auto& [parts, mates, steps, regions, parts_or_hand] = names;
  auto check = [&](const std::string& name, const std::vector<std::string>& known,
                   const char* kind) {
    if (std::find(known.begin(), known.end(), name) == known.end()) {
      // A name of another kind (a part where a mate belongs) is said so.
      std::string other;
      for (const auto& [list, what] :
           {std::pair{&names.parts, "part"}, std::pair{&names.mates, "mate"},
            std::pair{&names.steps, "step"}, std::pair{&names.regions, "region"}}) {
        if (what != std::string_view(kind) &&
            std::find(list->begin(), list->end(), name) != list->end()) {
          other = " ('" + name + "' is a " + what + "; " + kind + "s: " +
                  (known.empty() ? std::string("none") : [&] {
                    std::string all;
                    for (const std::string& k : known) all += (all.empty() ? "" : ", ") + k;
                    return all;
                  }()) +
                  ")";
        }
      }
      note(clause.where, std::string(clause.word->name) + ": no " + kind + " '" + name + "'" +
                             (other.empty() ? did_you_mean(name, known) : other));
    }
  };
  for (std::size_t i = 0; i < clause.args.size(); ++i) {
    const Arg& arg = clause.args[i];
    if (!arg.given) continue;
    switch (clause.word->params[i].type) {
      case ArgType::kPartOrHand:
        if (arg.text == "hand") {
          if (!scenario_.glove && !hand_given_)
            note(clause.where, std::string(clause.word->name) + ": the scenario has no hand");
          break;
        }
        check(arg.text, parts_or_hand, "part");
        break;
      case ArgType::kPart:
        if (arg.text == "hand" && !clause.word->params.empty() &&
            clause.word->params[0].type == ArgType::kPartOrHand) {
          // touches("peg", "hand"): the hand may be named, but first.
          note(clause.where, std::string(clause.word->name) +
                                 ": the hand is named first: " + std::string(clause.word->name) +
                                 "(\"hand\", \"" + clause.args[0].text + "\")");
          break;
        }
        if (arg.text == "hand") {
          std::string words;
          for (const Word& w : vocabulary()) {
            if (!w.params.empty() && w.params[0].type == ArgType::kPartOrHand)
              words += (words.empty() ? "" : ", ") + std::string(w.name);
          }
          note(clause.where, std::string(clause.word->name) +
                                 ": 'hand' is no part (the hand is named first in " + words + ")");
          break;
        }
        check(arg.text, parts, "part");
        break;
      case ArgType::kMate:
        check(arg.text, mates, "mate");
        break;
      case ArgType::kStep:
        check(arg.text, steps, "step");
        break;
      case ArgType::kRegion:
        check(arg.text, regions, "region");
        break;
      case ArgType::kNames:
        if (clause.word->name == "steps_in_order") {
          if (arg.names.empty()) note(clause.where, "steps_in_order: name at least one step");
          for (std::size_t k = 0; k < arg.names.size(); ++k) {
            check(arg.names[k], steps, "step");
            // A step is done once: named twice, the order can never hold.
            if (std::find(arg.names.begin(), arg.names.begin() + static_cast<std::ptrdiff_t>(k),
                          arg.names[k]) != arg.names.begin() + static_cast<std::ptrdiff_t>(k)) {
              note(clause.where, "steps_in_order: step '" + arg.names[k] +
                                     "' is named twice; a step is completed once");
            }
          }
        }
        break;
      default:
        break;
    }
  }
}

/// A part, mate or region made but in no table of the scenario: most often
/// one of two of the same name in one table (`peg = part { ... }` twice),
/// of which Lua keeps the later without a word. A declaration made by a
/// function for many (one line for all) is not told apart from its others.
void Loader::warn_about_dropped_declarations() {
  std::map<std::string, std::set<std::string>> read;  // word -> "file:line" of those read
  for (const PartSpec& p : scenario_.parts) read["part"].insert(p.where.str());
  for (const MateSpec& m : scenario_.mates) read["mate"].insert(m.where.str());
  for (const RegionSpec& r : scenario_.regions) read["region"].insert(r.where.str());
  std::vector<std::pair<std::string, SourceLocation>> dropped;  // (word, where)
  lua_rawgeti(L_, LUA_REGISTRYINDEX, made_);
  for (const char* word : kNamedDeclarations) {
    lua_getfield(L_, -1, word);
    const lua_Integer n = luaL_len(L_, -1);
    for (lua_Integer i = 1; i <= n; ++i) {
      lua_rawgeti(L_, -1, i);
      const std::string text = string_at(-1);
      lua_pop(L_, 1);
      const SourceLocation where = parse_where(text, file_);
      if (where.line > 0 && read[word].count(where.str()) == 0) dropped.emplace_back(word, where);
    }
    lua_pop(L_, 1);
  }
  lua_pop(L_, 1);
  if (dropped.empty()) return;
  const std::vector<std::string>& lines = source_lines();
  for (const auto& [word, where] : dropped) {
    // The name it was given, from its line: `name = part {` or `["name"] = part {`.
    std::string name;
    if (where.file == file_ && where.line <= static_cast<int>(lines.size())) {
      name = declared_name(lines[where.line - 1], word);
    }
    const SourceLocation* kept = nullptr;
    for (const PartSpec& p : scenario_.parts)
      if (word == "part" && p.name == name) kept = &p.where;
    for (const MateSpec& m : scenario_.mates)
      if (word == "mate" && m.mate.name == name) kept = &m.where;
    for (const RegionSpec& r : scenario_.regions)
      if (word == "region" && r.region.name == name) kept = &r.where;
    if (kept) {
      scenario_.warnings.push_back(where.str() + ": " + word + " '" + name +
                                   "' is declared again at line " + std::to_string(kept->line) +
                                   ", which replaces this one: give each " + word +
                                   " a name of its own");
    } else {
      scenario_.warnings.push_back(where.str() + ": this " + word +
                                   " { ... } is in none of the "
                                   "scenario's " +
                                   word + "s (is its name given twice?)");
    }
  }
}

/// A custom function's part names, where its text spells them out
/// (`dt.part("peg")`), checked as the vocabulary's are: a misspelt one would
/// stop the run when the function runs, perhaps minutes in. A name the
/// function computes is not seen.
void Loader::warn_about_parts_named_in_custom(const Clause& custom,
                                              const std::vector<std::string>& parts) {
  const Arg& function = custom.args[0];
  if (!function.given || function.function_ref == LUA_NOREF) return;
  lua_rawgeti(L_, LUA_REGISTRYINDEX, function.function_ref);
  lua_Debug ar;
  const bool known = lua_getinfo(L_, ">S", &ar) != 0 && ar.source != nullptr &&
                     ar.source[0] == '@' && std::string(ar.source + 1) == file_;
  if (!known || ar.linedefined <= 0) return;
  const std::vector<std::string>& lines = source_lines();
  const auto last =
      std::min<std::size_t>(static_cast<std::size_t>(ar.lastlinedefined), lines.size());
  for (std::size_t row = static_cast<std::size_t>(ar.linedefined); row <= last; ++row) {
    const std::string& line = lines[row - 1];
    for (std::size_t at = line.find("part"); at != std::string::npos;
         at = line.find("part", at + 4)) {
      if (at == 0 || (line[at - 1] != '.' && line[at - 1] != ':')) continue;
      std::size_t i = at + 4;
      while (i < line.size() && line[i] == ' ') ++i;
      const bool paren = i < line.size() && line[i] == '(';
      if (paren) ++i;
      while (i < line.size() && line[i] == ' ') ++i;
      if (i >= line.size() || (line[i] != '"' && line[i] != '\'')) continue;
      const std::size_t close = line.find(line[i], i + 1);
      if (close == std::string::npos) continue;
      // The whole argument, not the start of a concatenation ("l" .. "id").
      std::size_t after = close + 1;
      while (after < line.size() && line[after] == ' ') ++after;
      if (paren ? after >= line.size() || line[after] != ')'
                : after < line.size() && line[after] == '.') {
        continue;
      }
      const std::string name = line.substr(i + 1, close - i - 1);
      if (std::find(parts.begin(), parts.end(), name) != parts.end()) continue;
      scenario_.warnings.push_back(file_ + ":" + std::to_string(row) + ": custom: no part '" +
                                   name + "'" + did_you_mean(name, parts) +
                                   ": the run stops with an error if the function asks for it");
    }
  }
}

/// Two parts of one file's nodes that share a node, standing where each
/// other stands: its triangles are in both, one over the other. The overlap
/// warning misses it between parts attached to each other (a pin taken
/// with its piston's group, and again as a part attached to the piston).
/// Parts placed apart are copies, as a file's brick is used for three.
void Loader::warn_about_nodes_taken_twice() {
  for (std::size_t a = 0; a < nodes_taken_.size(); ++a) {
    for (std::size_t b = a + 1; b < nodes_taken_.size(); ++b) {
      const NodesTaken &x = nodes_taken_[a], &y = nodes_taken_[b];
      const PartSpec *px = part_named(x.part), *py = part_named(y.part);
      if (x.file != y.file || !px || !py || !(px->X_WP.R == py->X_WP.R) ||
          !(px->X_WP.t == py->X_WP.t)) {
        continue;
      }
      const auto import = imports_.find(x.file);
      if (import == imports_.end()) continue;
      for (std::size_t i = 0; i < x.taken.size() && i < y.taken.size(); ++i) {
        if (!x.taken[i] || !y.taken[i]) continue;
        const SourceLocation& later = px->where.line <= py->where.line ? py->where : px->where;
        scenario_.warnings.push_back(
            later.str() + ": parts '" + x.part + "' and '" + y.part + "' both take node '" +
            import->second.parts[i].name + "' of " +
            std::filesystem::path(x.file).filename().string() +
            ", where each stands: its triangles are in both, one over the other (a group's "
            "name takes every node below it)");
        break;
      }
    }
  }
}

/// A glTF file is in metres by its specification: read without `units` in
/// a scenario in millimetres or centimetres, its numbers are taken as the
/// scenario's, a thousandth or a hundredth of the size meant (a 1 m table
/// becomes 1 mm), which the size warnings miss among parts of any size.
/// Some exporters write millimetres; `units` says which.
void Loader::warn_about_gltf_units() {
  if (scenario_.metres_per_unit == 1) return;
  for (const PartSpec& p : scenario_.parts) {
    if (p.file.empty() || !p.file_units.empty() || !p.mesh) continue;
    std::string extension = std::filesystem::path(p.file).extension().string();
    for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (extension != ".gltf" && extension != ".glb") continue;
    const double numbers = across(*p.mesh) / scenario_.metres_per_unit;  // as the file has them
    scenario_.warnings.push_back(
        p.where.str() + ": part '" + p.name + "' (" + p.file +
        "): a glTF file is in metres by its specification, but its numbers are read in " +
        scenario_.units + ", as the scenario's: " + brief(numbers) + " " + scenario_.units +
        " across, where in metres it is " + brief(numbers) +
        " m; give the part units = \"m\", or units = \"" + scenario_.units +
        "\" if the file is in " + scenario_.units);
  }
}

/// A part from a mesh file hundreds of times smaller or larger than the
/// scenario's other parts, and under 2 mm or over 20 m across (or under
/// 0.05 mm or over 200 m whatever the others): most likely a file in other
/// units (a plate in metres in a scenario in millimetres is 80 micrometres
/// across, and any part passes through it in a frame). A 4 mm screw in a
/// 3 m frame is no such part.
void Loader::warn_about_mesh_sizes() {
  // Each part's size in the scenario's units, once.
  const std::vector<PartSpec>& parts = scenario_.parts;
  std::vector<double> sizes(parts.size(), 0);
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (parts[i].mesh) sizes[i] = across(*parts[i].mesh) / scenario_.metres_per_unit;
  }
  constexpr double kRatio = 500;  // units differ by 1000 (m and mm)
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const PartSpec& p = parts[i];
    if (p.file.empty() || !p.mesh) continue;
    std::vector<double> others;
    for (std::size_t j = 0; j < parts.size(); ++j) {
      if (j != i && parts[j].mesh) others.push_back(sizes[j]);
    }
    if (others.empty()) continue;
    std::nth_element(others.begin(), others.begin() + others.size() / 2, others.end());
    const double median = others[others.size() / 2], size = sizes[i];
    if (!(size > 0) || !(median > 0)) continue;
    const double ratio = median / size;
    // Far from the others and of a size few parts have; or of a size no part has.
    const double metres = size * scenario_.metres_per_unit;
    const bool far = ratio >= kRatio || ratio <= 1 / kRatio;
    const bool rare = metres < 2e-3 || metres > 20;
    const bool never = metres < 5e-5 || metres > 200;
    if (!(far && rare) && !never) continue;
    const std::string& units = scenario_.units;
    const std::string& file_units = p.file_units.empty() ? units : p.file_units;
    scenario_.warnings.push_back(
        p.where.str() + ": part '" + p.name + "' (" + p.file + ") is " + brief(size) + " " + units +
        " across, " +
        (ratio > 1 ? "1/" + brief(std::round(ratio)) + " of"
                   : brief(std::round(1 / ratio)) + " times") +
        " the other parts (a median of " + brief(median) + " " + units +
        "): is the file in other units? " +
        units_hint("Its", file_units,
                   likely_units(metres, file_units, median * scenario_.metres_per_unit),
                   "the part"));
  }
}

/// Parts from mesh files that agree with each other but not with the hand:
/// a median of under 1/200 or over 200 times the hand's length, where a
/// hand grasps parts of millimetres to a metre. A whole product exported in
/// metres into a scenario in millimetres (or the other way round) is such a
/// set; warn_about_mesh_sizes, which compares parts with each other, misses it.
void Loader::warn_about_parts_beside_the_hand() {
  if (!scenario_.glove) return;
  // What a hand assembles is mostly of a few centimetres: the units to offer
  // are those that bring the parts nearest that, not the hand's length.
  constexpr double kTypicalPart_m = 0.05;
  std::vector<double> sizes;
  std::set<std::string> file_units;
  for (const PartSpec& p : scenario_.parts) {
    if (p.file.empty() || !p.mesh) continue;
    file_units.insert(p.file_units.empty() ? scenario_.units : p.file_units);
    sizes.push_back(across(*p.mesh));  // metres (the vertices are scaled)
  }
  if (sizes.empty()) return;
  std::nth_element(sizes.begin(), sizes.begin() + sizes.size() / 2, sizes.end());
  const double median = sizes[sizes.size() / 2];
  double hand = scenario_.glove->hand_length;
  for (const interaction::HandSize& size : interaction::hand_sizes()) {
    if (hand == 0 && size.name == interaction::HandDef{}.size) hand = size.hand_length;
  }
  constexpr double kRatio = 200;
  if (!(median > 0) || (median >= hand / kRatio && median <= hand * kRatio)) return;
  const double per_unit = scenario_.metres_per_unit;
  const auto whole = [](double x) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.0f", x);
    return std::string(buffer);
  };
  const std::string& units = scenario_.units;
  const double ratio = hand / median;
  scenario_.warnings.push_back(
      scenario_.glove->where.str() + ": the parts from mesh files are a median of " +
      brief(median / per_unit) + " " + units + " across, " +
      (ratio > 1 ? "1/" + whole(ratio) + " of" : whole(1 / ratio) + " times") + " the hand (" +
      brief(hand / per_unit) + " " + units + "): are the files in other units?" +
      (file_units.size() == 1
           ? " " + units_hint("Their", *file_units.begin(),
                              likely_units(median, *file_units.begin(), kTypicalPart_m),
                              "the parts")
           : std::string()));
}

/// A part from a mesh file whose surface is open or inconsistently wound:
/// its overlaps are measured wrong or not at all (interaction::surface_flaw),
/// and nothing else would say so. Generated shapes are closed by construction.
void Loader::warn_about_open_surfaces() {
  for (const PartSpec& p : scenario_.parts) {
    if (p.file.empty() || !p.mesh || open_surfaces_.count(p.name) != 0) continue;
    if (const std::optional<std::string> flaw = interaction::surface_flaw(*p.mesh)) {
      scenario_.warnings.push_back(p.where.str() + ": part '" + p.name + "' (" + p.file +
                                   ") is not a closed surface: " + *flaw + "; " +
                                   interaction::kSurfaceFlawEffect);
    }
  }
}

/// Parts that overlap where the scenario places them: a shaft started
/// through a housing's wall goes unnoticed otherwise (nothing moves it, and
/// only a max_penetration expectation would measure it). Parts attached to
/// each other, directly or through others, are put together so (a press
/// fit) and are left out. Measured as max_penetration measures
/// (interaction::OverlapGauge), only for parts whose boxes overlap.
void Loader::warn_about_overlapping_parts() {
  const auto root = [&](const PartSpec& p) {
    const PartSpec* at = &p;
    for (std::size_t k = 0; k < scenario_.parts.size() && !at->attached_to.empty(); ++k) {
      const PartSpec* up = part_named(at->attached_to);
      if (!up) break;
      at = up;
    }
    return at;
  };
  const std::vector<PartSpec>& parts = scenario_.parts;
  // Each part's box in the world, once: the box of its local box's corners.
  std::vector<Eigen::AlignedBox<double, 3>> boxes(parts.size());
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (!parts[i].mesh) continue;
    const collision::Bounds b =
        collision::transformed_bounds(collision::mesh_bounds(*parts[i].mesh), parts[i].X_WP);
    boxes[i] = Eigen::AlignedBox<double, 3>(b.min, b.max);
  }
  constexpr double kDeepest = 1e-6;  // metres: touching parts read 0, or rounding
  interaction::OverlapGauge gauge;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (!parts[i].mesh) continue;
    for (std::size_t j = i + 1; j < parts.size(); ++j) {
      if (!parts[j].mesh || root(parts[i]) == root(parts[j])) continue;
      if (!boxes[i].intersects(boxes[j])) continue;
      const double depth = gauge.depth(parts[i].mesh, parts[i].X_WP, parts[j].mesh, parts[j].X_WP);
      if (!(depth > kDeepest)) continue;
      // Named at the later declaration (the part more likely placed last),
      // with the other's line.
      const bool j_later = parts[i].where.line <= parts[j].where.line;
      const PartSpec& later = j_later ? parts[j] : parts[i];
      const PartSpec& earlier = j_later ? parts[i] : parts[j];
      scenario_.warnings.push_back(
          later.where.str() + ": parts '" + later.name + "' and '" + earlier.name + "' (line " +
          std::to_string(earlier.where.line) + ") overlap by " +
          brief(depth / scenario_.metres_per_unit) + " " + scenario_.units +
          " where the scenario places them: one starts inside the other (attach them with "
          "attached_to if they are pressed together)");
    }
  }
}

void Loader::resolve() {
  Names names;
  for (const PartSpec& p : scenario_.parts) names.parts.push_back(p.name);
  for (const MateSpec& m : scenario_.mates) names.mates.push_back(m.mate.name);
  for (const StepSpec& s : scenario_.steps) names.steps.push_back(s.name);
  for (const RegionSpec& r : scenario_.regions) names.regions.push_back(r.region.name);
  names.parts_or_hand = names.parts;
  if (scenario_.glove || hand_given_) names.parts_or_hand.emplace_back("hand");
  const std::vector<std::string>& parts = names.parts;
  auto fixed = [&](const std::string& name) {
    for (const PartSpec& p : scenario_.parts) {
      if (p.name == name) return p.fixed;
    }
    return false;
  };
  // With or_hand, "hand" is among the names suggested ("hnad": did you mean 'hand'?).
  auto check_part = [&](const std::string& name, const SourceLocation& where,
                        const std::string& what, bool or_hand = false) {
    if (std::find(parts.begin(), parts.end(), name) != parts.end()) return;
    note(where, what + ": no part '" + name + "'" +
                    did_you_mean(name, or_hand ? names.parts_or_hand : parts));
  };
  for (const MateSpec& m : scenario_.mates) {
    check_part(m.mate.part, field_line(m.where, "mate", "part"), "mate '" + m.mate.name + "'");
    check_part(m.mate.other, field_line(m.where, "mate", "into"), "mate '" + m.mate.name + "'");
    if (fixed(m.mate.part))
      note(m.where, "mate '" + m.mate.name + "': its part '" + m.mate.part + "' is fixed");
  }
  for (const RegionSpec& r : scenario_.regions) {
    for (const std::string& p : r.region.parts) {
      if (p != "hand") {
        check_part(p, r.where, "region '" + r.region.name + "'", true);
      } else if (!scenario_.glove && !hand_given_) {
        note(r.where, "region '" + r.region.name + "': the scenario has no hand");
      }
    }
  }
  // Parts attached from the start: to another part, not fixed themselves, without a cycle.
  for (const PartSpec& p : scenario_.parts) {
    if (p.attached_to.empty()) continue;
    const std::string what = "part '" + p.name + "': attached_to";
    check_part(p.attached_to, field_line(p.where, "part", "attached_to"), what);
    if (p.attached_to == p.name) {
      note(p.where, what + ": a part cannot be attached to itself");
      continue;
    }
    if (p.fixed)
      note(p.where, what + ": the part is fixed, so it cannot move with '" + p.attached_to + "'");
    // Up the chain; back at the part within as many steps as there are parts: a cycle.
    std::string chain = "'" + p.name + "'";
    const PartSpec* q = &p;
    for (std::size_t k = 0; k < scenario_.parts.size() && q && !q->attached_to.empty(); ++k) {
      chain += " to '" + q->attached_to + "'";
      q = part_named(q->attached_to);
      if (q == &p) {
        note(p.where, what + " makes a cycle: " + chain);
        break;
      }
    }
  }
  warn_about_mesh_sizes();
  warn_about_parts_beside_the_hand();
  warn_about_open_surfaces();
  if (noted_.empty()) warn_about_overlapping_parts();
  warn_about_dropped_declarations();
  warn_about_gltf_units();
  warn_about_nodes_taken_twice();
  if (scenario_.glove && !scenario_.glove->holding.empty()) {
    check_part(scenario_.glove->holding, scenario_.glove->where, "glove: holding");
    if (fixed(scenario_.glove->holding)) {
      note(scenario_.glove->where,
           "glove: the hand cannot hold the fixed part '" + scenario_.glove->holding + "'");
    } else {
      // Holding a part carries its sub-assembly: one attached to a fixed part
      // cannot move. (The chain has no cycle: those are refused above.)
      const PartSpec* q = part_named(scenario_.glove->holding);
      for (std::size_t k = 0; q && !q->attached_to.empty() && k < scenario_.parts.size(); ++k) {
        q = part_named(q->attached_to);
      }
      if (q && q->fixed) {
        note(scenario_.glove->where, "glove: the hand cannot hold '" + scenario_.glove->holding +
                                         "': it is attached to '" + q->name + "', which is fixed");
      }
    }
  }
  auto can_never = [&](const Clause& c, const std::string& context) {
    const std::string_view w = c.word->name;
    // An event never happens; a state never holds.
    const std::string never =
        c.text + (c.word->kind == WordKind::kState ? " can never hold: " : " can never happen: ");
    if ((w == "touches" || w == "separates" || w == "touching" || w == "no_contact") &&
        c.args[0].text != "hand" && fixed(c.args[0].text) && fixed(c.args[1].text)) {
      scenario_.warnings.push_back(c.where.str() + ": " + context + never + "'" + c.args[0].text +
                                   "' and '" + c.args[1].text + "' are both fixed");
    }
    if ((w == "touches" || w == "separates" || w == "touching") &&
        c.args[0].text == c.args[1].text) {
      scenario_.warnings.push_back(c.where.str() + ": " + context + never +
                                   "a part does not touch itself");
    }
    if ((w == "grasped" || w == "released" || w == "holding" || w == "slides" ||
         w == "grasped_as") &&
        (fixed(c.args[0].text) || !(scenario_.glove || hand_given_))) {
      scenario_.warnings.push_back(c.where.str() + ": " + context + never +
                                   (fixed(c.args[0].text)
                                        ? "'" + c.args[0].text + "' is fixed"
                                        : std::string("the scenario has no hand")));
    }
    if (w == "enters" || w == "leaves" || w == "inside") {
      for (const RegionSpec& r : scenario_.regions) {
        const std::vector<std::string>& watched = r.region.parts;
        if (r.region.name != c.args[1].text || watched.empty() ||
            std::find(watched.begin(), watched.end(), c.args[0].text) != watched.end()) {
          continue;
        }
        std::string list;
        for (const std::string& p : watched) list += (list.empty() ? "'" : ", '") + p + "'";
        scenario_.warnings.push_back(c.where.str() + ": " + context + never + "region '" +
                                     r.region.name + "' watches only " + list);
      }
    }
  };
  for (const StepSpec& s : scenario_.steps) {
    if (s.done) {
      resolve_clause(*s.done, names);
      can_never(*s.done, "step '" + s.name + "': ");
    }
  }
  for (const RuleSpec& r : scenario_.rules) {
    resolve_clause(r.when, names);
    can_never(r.when, "rule: ");
    if (r.when.word->name == "every" && r.when.args[0].number < r.cooldown - 1e-9) {
      scenario_.warnings.push_back(r.when.where.str() + ": rule: " + r.when.text +
                                   " fires at most once every " + format_number(r.cooldown) +
                                   " s, the rule's cooldown: not at every tick");
    }
    if (r.unless) resolve_clause(*r.unless, names);
    if (r.only_if) {
      resolve_clause(*r.only_if, names);
      can_never(*r.only_if, "rule: ");
    }
    for (const Clause& c : r.act) {
      resolve_clause(c, names);
      if (c.word->name == "custom") warn_about_parts_named_in_custom(c, names.parts);
      if (c.word->name != "attach") continue;
      const std::string &part = c.args[0].text, &to = c.args[1].text;
      if (part == to) {
        note(c.where, "attach: '" + part + "' cannot be attached to itself");
      } else if (fixed(part)) {
        note(c.where, "attach: '" + part + "' is fixed, so it cannot move with '" + to +
                          "' (attach '" + to + "' to it instead)");
      }
    }
  }
  for (const Clause& c : scenario_.expectations) {
    resolve_clause(c, names);
    can_never(c, "expectation: ");
  }
}

}  // namespace

Scenario load_scenario(LuaHost& host, const std::filesystem::path& file,
                       std::vector<std::filesystem::path>* files_read, bool hand_given) {
  Loader loader(host, file, files_read, hand_given);
  return loader.load();
}

}  // namespace dovetail::scripting
