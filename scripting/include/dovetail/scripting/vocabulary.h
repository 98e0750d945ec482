#pragma once
/// \file vocabulary.h
/// Every word a scenario can use: declarations, events, states, actions and
/// expectations, with their arguments and a line of documentation each.
///
/// Why: one registry drives three things that must agree. The Lua prelude
/// defines one constructor per word from it, the loader checks each use's
/// arguments against it, and `dovetail reference` prints it as the reference
/// section of docs/authoring.md (a test compares the two), so the vocabulary,
/// its checks and its documentation cannot drift apart.

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace dovetail::scripting {

/// What a word is for.
enum class WordKind {
  kDeclaration,  ///< builds the scenario: scenario, part, mate, glove, step, rule, region
  kShape,        ///< a generated part shape: box, cylinder, ...
  kEvent,        ///< something that happens in one frame (an edge): `when =`
  kState,        ///< something that holds or not right now: `unless =`, `only_if =`
  kAction,       ///< what a rule does: `act =`
  kExpectation,  ///< what must hold for the scenario to pass: `expect =`
};
/// "declaration", "shape", "event", ... as in the reference.
std::string_view word_kind_name(WordKind kind);

/// The type of an argument or a field.
enum class ArgType {
  kPart,        ///< a part's name
  kPartOrHand,  ///< a part's name or "hand" (any segment of the hand)
  kMate,        ///< a mate's name
  kStep,        ///< a step's name
  kRegion,      ///< a region's name
  kSeconds,     ///< simulation time in seconds, >= 0
  kLength,      ///< a length in the scenario's units, >= 0
  kNumber,      ///< any finite number
  kCount,       ///< a whole number >= 0
  kText,        ///< free text
  kGraspType,   ///< "precision", "tripod" or "power"
  kVector,      ///< three numbers {x, y, z} in the scenario's units
  kDirection,   ///< "x", "-y", ... or three numbers (normalised)
  kTurn,        ///< {x = deg, y = deg, z = deg}: about x, then y, then z (fixed axes)
  kColor,       ///< {r, g, b} in [0, 1] or a colour name
  kFunction,    ///< a Lua function (custom actions only)
  kFlag,        ///< true or false
  kFile,        ///< a path, relative to the scenario's folder
  kTable,       ///< a table of named fields (see the word's fields)
  kList,        ///< a list of words of the kinds named in the field's documentation
  kMap,         ///< names mapped to words: { peg = part{...}, ... }
  kWord,        ///< one word of the kind named in the documentation
  kNames,       ///< a list of names
};
std::string_view arg_type_name(ArgType type);

/// One argument (events, actions, ...) or field (declarations).
struct Param {
  std::string_view name;
  ArgType type;
  bool optional;
  std::string_view doc;
};

/// A word of the vocabulary.
struct Word {
  std::string_view name;
  WordKind kind;
  /// Positional arguments for events, states, actions and expectations;
  /// named fields for declarations and shapes (called with one table).
  std::vector<Param> params;
  std::string_view doc;
  std::string_view example;
};

/// The vocabulary, in reference order (by kind, then as documented).
const std::vector<Word>& vocabulary();
/// The word called `name`, or nullptr.
const Word* find_word(std::string_view name);

/// The reference section of docs/authoring.md, in Markdown.
std::string reference_markdown();

/// Edit distance (insertions, deletions, substitutions) between two names.
std::size_t edit_distance(std::string_view a, std::string_view b);
/// The closest of `candidates` within a third of the name's length (at
/// least 2 edits), if one is that close.
std::optional<std::string> nearest_name(std::string_view name,
                                        std::span<const std::string> candidates);
/// " (did you mean 'x'?)" for nearest_name, or "" when none is close.
std::string did_you_mean(std::string_view name, std::span<const std::string> candidates);

}  // namespace dovetail::scripting
