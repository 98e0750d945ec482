#include "dovetail/scripting/vocabulary.h"

#include <algorithm>
#include <numeric>

namespace dovetail::scripting {

namespace {

using enum ArgType;
constexpr bool kOptional = true;
constexpr bool kRequired = false;

std::vector<Word> make_vocabulary() {
  std::vector<Word> w;
  // ---- declarations
  w.push_back(
      {"scenario",
       WordKind::kDeclaration,
       {{"name", kText, kRequired, "what the scenario is called in reports"},
        {"units", kText, kOptional, "\"mm\" (default), \"cm\" or \"m\": the unit of every length"},
        {"seed", kCount, kOptional, "seeds math.random in custom actions (default 1)"},
        {"duration", kSeconds, kOptional,
         "simulated seconds to run, at most 3600 (default: the glove's plan plus 1 s, or its "
         "trace's length)"},
        {"time_step", kSeconds, kOptional, "seconds per frame, 0.0001 to 1 (default 1/90)"},
        {"accuracy", kText, kOptional,
         "\"exact\" (default): parts touch exactly when their triangles meet; or a length, a "
         "tolerance: parts that far apart may count as touching, and the pipeline picks "
         "cheaper levels where they keep it (never a missed contact)"},
        {"parts", kMap, kRequired, "the parts by name: `peg = part { ... }`"},
        {"mates", kMap, kOptional, "the mates by name: `peg_in_hole = mate { ... }`"},
        {"regions", kMap, kOptional, "named boxes in the world: `tray = region { ... }`"},
        {"hand", kWord, kOptional, "the hand and its glove: `glove { ... }`"},
        {"steps", kList, kOptional, "the assembly steps, in the order they should be done"},
        {"rules", kList, kOptional,
         "what should happen when: `rule { ... }`, checked in file order"},
        {"expect", kList, kOptional, "expectations; the scenario passes when all hold"},
        {"camera", kTable, kOptional,
         "where pictures are taken from: { from = {x, y, z}, to = {x, y, z} } (default: "
         "the whole scene, obliquely from above)"}},
       "The whole scenario; the file returns it.",
       "return scenario { name = \"Peg into block\", units = \"mm\", parts = { ... } }"});
  w.push_back(
      {"part",
       WordKind::kDeclaration,
       {{"shape", kWord, kOptional, "a generated shape: `cylinder { ... }`, `box { ... }`, ..."},
        {"mesh", kFile, kOptional,
         "or a mesh file (OBJ, STL, PLY, glTF, ...; its numbers in the scenario's units "
         "unless `units` says otherwise)"},
        {"units", kText, kOptional,
         "the unit of the mesh file's numbers, \"mm\", \"cm\" or \"m\" (default: the "
         "scenario's); `at` and the mates' points stay in the scenario's"},
        {"nodes", kNames, kOptional,
         "only these nodes of the mesh file, as `dovetail inspect --parts` names them; "
         "the part's frame stays the file's"},
        {"without", kNames, kOptional, "or every node of the mesh file but these"},
        {"at", kVector, kOptional, "position of the part's origin (default {0, 0, 0})"},
        {"turn", kTurn, kOptional, "orientation: degrees about x, then y, then z"},
        {"fixed", kFlag, kOptional, "true: the part never moves (default false)"},
        {"open_surface", kFlag, kOptional,
         "true: the mesh is known not to be a closed, consistently wound surface (a model "
         "shown beside the assembly), so loading does not warn of it; overlaps with it are "
         "still measured unreliably (default false)"},
        {"attached_to", kPart, kOptional,
         "another part it is attached to from the start, where it is placed (as `attach`)"},
        {"color", kColor, kOptional,
         "display colour: black, blue, brass, green, grey (or gray), orange, purple, red, "
         "steel, white, yellow, or {r, g, b} in [0, 1]"},
        {"tags", kNames, kOptional, "free labels"}},
       "A part of the assembly: a generated shape or a mesh file, placed in the world.",
       "peg = part { shape = cylinder { diameter = 20, length = 60 }, at = { 0, 100, 0 } }"});
  w.push_back(
      {"mate",
       WordKind::kDeclaration,
       {{"part", kPart, kRequired, "the part that is carried and snaps"},
        {"point", kVector, kOptional, "its feature point, in its own frame (default origin)"},
        {"axis", kDirection, kRequired, "its feature axis, in its own frame"},
        {"into", kPart, kRequired, "the part it fits onto"},
        {"at", kVector, kOptional, "that part's feature point, in its frame (default origin)"},
        {"along", kDirection, kRequired, "that part's feature axis, in its frame"},
        {"tolerance", kLength, kOptional, "position tolerance (default 2 mm)"},
        {"angle", kNumber, kOptional,
         "angle tolerance in degrees, above 0 and at most 180 (default 5)"},
        {"guide", kFlag, kOptional,
         "false: the carried part is not drawn onto the axis, so a misalignment stays as "
         "it would without a chamfer (default true)"}},
       "A fit: released within the tolerances, the part snaps so its point and axis meet "
       "the other's, and `mated` fires, unless in place it would overlap another part (then a "
       "warning names it). Carried near the axis, the part is drawn onto it as it reaches the "
       "other part, as a chamfer draws a peg (unless guide = false).",
       "peg_in_hole = mate { part = \"peg\", point = { 0, 0, 60 }, axis = \"z\", into = "
       "\"block\", at = { 0, -10, 0 }, along = \"-y\" }"});
  w.push_back({"glove",
               WordKind::kDeclaration,
               {{"plan", kFile, kOptional,
                 "a simulated-glove plan (docs/interaction.md, \"Sources\"; in metres)"},
                {"trace", kFile, kOptional, "or a recorded glove trace (CSV)"},
                {"holding", kPart, kOptional,
                 "a part the hand holds from the start (no grasp event: it was never grasped)"},
                {"grasp", kGraspType, kOptional, "the grasp it is held with (default \"power\")"},
                {"noise", kTable, kOptional,
                 "glove noise: { position = length, angle = deg, joints = deg, seed = n }"},
                {"hand_length", kLength, kOptional,
                 "wrist to middle fingertip, 120 to 260 mm (default 190 mm)"}},
               "The hand, driven by a simulated glove (a plan) or a recorded trace.",
               "hand = glove { plan = \"../assets/glove/peg_in_hole.plan\", holding = \"peg\" }"});
  w.push_back(
      {"step",
       WordKind::kDeclaration,
       {{"name", kText, kRequired, "the step's name (or the first item)"},
        {"text", kText, kOptional, "what to do, for people (or the second item)"},
        {"done", kWord, kOptional, "the event that completes it"}},
       "An assembly step. Steps are done in order; completing one before the step "
       "before it is recorded as out of order.",
       "step { \"insert\", \"Push the peg into the block\", done = mated \"peg_in_hole\" }"});
  w.push_back({"rule",
               WordKind::kDeclaration,
               {{"when", kWord, kRequired, "the event"},
                {"unless", kWord, kOptional, "a state that stops the rule"},
                {"only_if", kWord, kOptional, "a state that must hold"},
                {"act", kList, kRequired, "actions, done at the start of the next frame"},
                {"cooldown", kSeconds, kOptional,
                 "seconds before the rule can fire again (default 0.1, or 0 for a rule on after or "
                 "every)"},
                {"once", kFlag, kOptional, "true: fire at most once"}},
               "When the event happens (and the states allow), do the actions.",
               "rule { when = touches(\"peg\", \"block\"), act = { highlight \"block\" } }"});
  w.push_back({"region",
               WordKind::kDeclaration,
               {{"min", kVector, kRequired, "lowest corner"},
                {"max", kVector, kRequired, "highest corner"},
                {"parts", kNames, kOptional,
                 "only these parts, and \"hand\" for the hand (default: every part and the "
                 "hand)"}},
               "A box in the world; a part whose bounding box overlaps it is inside, and the "
               "hand is while one of its segments' boxes does.",
               "tray = region { min = { -50, 0, -50 }, max = { 50, 20, 50 } }"});
  // ---- shapes
  w.push_back({"box",
               WordKind::kShape,
               {{"size", kVector, kRequired, "edge lengths along x, y, z, centred on the origin"}},
               "A box.",
               "box { size = { 40, 10, 40 } }"});
  w.push_back({"cylinder",
               WordKind::kShape,
               {{"diameter", kLength, kRequired,
                 "diameter through the corners of its facets (with 64 sides the flats are "
                 "0.12 % nearer)"},
                {"length", kLength, kRequired, "length along z, from z = 0"},
                {"sides", kCount, kOptional, "facets around, 3 to 4096 (default 64)"}},
               "A closed cylinder along z from 0 to its length.",
               "cylinder { diameter = 20, length = 60 }"});
  w.push_back({"block_with_hole",
               WordKind::kShape,
               {{"size", kVector, kRequired, "edge lengths; the top face is at y = size.y / 2"},
                {"hole", kLength, kRequired,
                 "the hole's diameter across the flats (a pin of this diameter fits), down along "
                 "-y from the top"},
                {"depth", kLength, kRequired, "the hole's depth (less than size.y)"},
                {"sides", kCount, kOptional, "facets of the hole's wall, 3 to 4096 (default 64)"}},
               "A block centred on the origin with a blind round hole down from its top.",
               "block_with_hole { size = { 80, 60, 80 }, hole = 20.5, depth = 40 }"});
  w.push_back({"tube",
               WordKind::kShape,
               {{"outer", kLength, kRequired, "outer diameter, through the corners"},
                {"inner", kLength, kRequired,
                 "inner diameter (the bore), across the flats: a shaft of this diameter fits"},
                {"length", kLength, kRequired, "length along z, from z = 0"},
                {"sides", kCount, kOptional,
                 "facets around, inside and out, 3 to 4096 (default 64; 6 gives a hexagon)"}},
               "A tube, ring or nut: a prism around z with a bore.",
               "tube { outer = 24, inner = 10.5, length = 3 }"});
  w.push_back({"sphere",
               WordKind::kShape,
               {{"diameter", kLength, kRequired, "diameter, centred on the origin"}},
               "A sphere.",
               "sphere { diameter = 30 }"});
  // ---- events
  w.push_back({"touches",
               WordKind::kEvent,
               {{"a", kPartOrHand, kRequired, "a part, or \"hand\""},
                {"b", kPart, kRequired, "another part"}},
               "a and b begin to touch: their surfaces meet, or a held part begins to slide "
               "along the other (\"hand\": any segment of the hand).",
               "touches(\"peg\", \"block\")"});
  w.push_back({"separates",
               WordKind::kEvent,
               {{"a", kPartOrHand, kRequired, "a part, or \"hand\""},
                {"b", kPart, kRequired, "another part"}},
               "a and b stop touching (the last contact or slide between them ends).",
               "separates(\"peg\", \"block\")"});
  w.push_back({"grasped",
               WordKind::kEvent,
               {{"part", kPart, kRequired, "the part"},
                {"type", kGraspType, kOptional, "only this grasp type"}},
               "The hand grasps the part.",
               "grasped \"peg\""});
  w.push_back({"released",
               WordKind::kEvent,
               {{"part", kPart, kRequired, "the part"}},
               "The hand lets go of the part (opened, the band overstretched, or attached to a "
               "fixed part while held).",
               "released \"peg\""});
  w.push_back({"mated",
               WordKind::kEvent,
               {{"mate", kMate, kRequired, "the mate"}},
               "The mate's part snaps into place.",
               "mated \"peg_in_hole\""});
  w.push_back(
      {"slides",
       WordKind::kEvent,
       {{"part", kPart, kRequired, "a carried part: the held one, or one of its sub-assembly"},
        {"on", kPart, kOptional, "only on this part"}},
       "A carried part (the held part, or a part of its sub-assembly) comes into contact "
       "with another part and slides along it: once for each pair, named as it touches.",
       "slides(\"peg\", \"block\")"});
  w.push_back({"enters",
               WordKind::kEvent,
               {{"part", kPartOrHand, kRequired, "a part, or \"hand\""},
                {"region", kRegion, kRequired, "the region"}},
               "The part enters the region (\"hand\": as its first segment does).",
               "enters(\"peg\", \"tray\")"});
  w.push_back({"leaves",
               WordKind::kEvent,
               {{"part", kPartOrHand, kRequired, "a part, or \"hand\""},
                {"region", kRegion, kRequired, "the region"}},
               "The part leaves the region (\"hand\": as its last segment does).",
               "leaves(\"peg\", \"tray\")"});
  w.push_back({"after",
               WordKind::kEvent,
               {{"seconds", kSeconds, kRequired, "simulated seconds from the start"}},
               "Once, in the first frame at or after the time.",
               "after(30)"});
  w.push_back(
      {"every",
       WordKind::kEvent,
       {{"seconds", kSeconds, kRequired, "the period, > 0"}},
       "In the first frame at or after each multiple of the period, t = p, 2p, ... (not at 0): "
       "once a frame for a period shorter than the time step. A rule on it fires at every "
       "tick, unless it is given a cooldown longer than the period.",
       "every(1)"});
  w.push_back({"arrives",
               WordKind::kEvent,
               {{"part", kPart, kRequired, "the part"}},
               "A move action has brought the part where it was sent (in the frame it gets "
               "there; at once for a move without `over`).",
               "arrives \"cap\""});
  w.push_back({"completed",
               WordKind::kEvent,
               {{"step", kStep, kRequired, "the step"}},
               "The step is completed.",
               "completed \"insert\""});
  // ---- states
  w.push_back({"holding",
               WordKind::kState,
               {{"part", kPart, kRequired, "the part"}},
               "The hand holds the part.",
               "holding \"peg\""});
  w.push_back({"touching",
               WordKind::kState,
               {{"a", kPartOrHand, kRequired, "a part, or \"hand\""},
                {"b", kPart, kRequired, "another part"}},
               "a and b touch now.",
               "touching(\"peg\", \"block\")"});
  w.push_back({"near",
               WordKind::kState,
               {{"mate", kMate, kRequired, "the mate"}},
               "The mate's part is within its tolerances: released now, it would snap, unless "
               "in place it would overlap another part (then the snap is refused, with a "
               "warning).",
               "near \"peg_in_hole\""});
  w.push_back({"done",
               WordKind::kState,
               {{"step", kStep, kRequired, "the step"}},
               "The step has been completed.",
               "done \"insert\""});
  w.push_back({"inside",
               WordKind::kState,
               {{"part", kPartOrHand, kRequired, "a part, or \"hand\""},
                {"region", kRegion, kRequired, "the region"}},
               "The part is inside the region.",
               "inside(\"peg\", \"tray\")"});
  // ---- actions
  w.push_back({"highlight",
               WordKind::kAction,
               {{"part", kPart, kRequired, "the part"},
                {"color", kColor, kOptional, "the colour (default \"orange\")"}},
               "Draws the part in a highlight colour.",
               "highlight \"block\""});
  w.push_back({"unhighlight",
               WordKind::kAction,
               {{"part", kPart, kRequired, "the part"}},
               "Draws the part in its own colour again.",
               "unhighlight \"block\""});
  w.push_back({"show",
               WordKind::kAction,
               {{"part", kPart, kRequired, "the part"}},
               "Draws the part (parts are shown at the start).",
               "show \"cover\""});
  w.push_back({"hide",
               WordKind::kAction,
               {{"part", kPart, kRequired, "the part"}},
               "Stops drawing the part; it still collides.",
               "hide \"cover\""});
  w.push_back({"move",
               WordKind::kAction,
               {{"part", kPart, kRequired, "the part"},
                {"to", kVector, kRequired, "the new position of its origin"},
                {"over", kSeconds, kOptional, "seconds to get there (default 0: at once)"}},
               "Moves the part in a straight line, keeping its orientation. It goes where it is "
               "sent: nothing stops it on the way (max_penetration and no_contact see what it "
               "passes through). Act when it gets there with arrives. A move replaces the part's "
               "move under way; of two in one frame the one written later wins, with a warning.",
               "move(\"cover\", { 0, 200, 0 }, 0.5)"});
  w.push_back({"attach",
               WordKind::kAction,
               {{"part", kPart, kRequired, "the part"},
                {"to", kPart, kRequired, "the part it moves with from now on"}},
               "Fixes the part to another; it keeps its place and moves with it. While the "
               "hand carries that part, the attached part is kept out of the others as the "
               "carried part is: it slides on them or holds the carried part back. A fixed "
               "part cannot be attached (attach what moves to it); an attach that would make a "
               "cycle is a warning and changes nothing. Parts attached to each other are not "
               "counted by max_penetration while attached (a press fit overlaps on purpose).",
               "attach(\"nut\", \"bolt\")"});
  w.push_back({"detach",
               WordKind::kAction,
               {{"part", kPart, kRequired, "the part"}},
               "Undoes attach; the part stays where it is.",
               "detach \"nut\""});
  w.push_back({"snap",
               WordKind::kAction,
               {{"mate", kMate, kRequired, "the mate"}},
               "Puts the mate's part in place at once, wherever it is, and fires `mated`; a part "
               "in place already stays, and fires nothing.",
               "snap \"peg_in_hole\""});
  w.push_back({"log",
               WordKind::kAction,
               {{"text", kText, kRequired, "the message"}},
               "Writes a line to the report's messages.",
               "log \"peg is in\""});
  w.push_back({"warn",
               WordKind::kAction,
               {{"text", kText, kRequired, "the message"}},
               "Writes a warning; `warnings_at_most` counts them.",
               "warn \"peg hits the block outside the hole\""});
  w.push_back({"fail",
               WordKind::kAction,
               {{"text", kText, kRequired, "the reason"}},
               "Ends the run; the scenario fails with the reason.",
               "fail \"peg not inserted within 30 s\""});
  w.push_back({"complete",
               WordKind::kAction,
               {{"step", kStep, kRequired, "the step"}},
               "Completes the step (as its `done` event would).",
               "complete \"insert\""});
  w.push_back({"custom",
               WordKind::kAction,
               {{"fn", kFunction, kRequired, "function(dt) ... end, with the low-level API"}},
               "Runs a Lua function with the low-level API (`dt.part`, `dt.time`, `dt.log`); "
               "poses it sets apply at the start of the next frame.",
               "custom(function(dt) dt.part(\"peg\"):set_translation(0, 90, 0) end)"});
  // ---- expectations
  w.push_back({"steps_in_order",
               WordKind::kExpectation,
               {{"steps", kNames, kRequired, "step names"}},
               "Each of these steps is completed, in this order, and none out of order.",
               "steps_in_order { \"insert\", \"fasten\" }"});
  w.push_back({"finished_within",
               WordKind::kExpectation,
               {{"seconds", kSeconds, kRequired, "simulated seconds"}},
               "Every step is completed by this time.",
               "finished_within(20)"});
  w.push_back({"max_penetration",
               WordKind::kExpectation,
               {{"depth", kLength, kRequired, "the deepest allowed, in the scenario's units"}},
               "No two parts ever overlap deeper than this, measured every frame: for two "
               "convex parts the exact penetration depth (the shortest move that parts them), "
               "otherwise the deepest point of one's edges inside the other, which misses an "
               "overlap deepest in the middle of a face (check touching with no_contact). The "
               "hand's segments are not counted, nor parts attached to each other while they "
               "are. Against a part whose surface is open or wrongly wound the depth may read 0 "
               "or far too deep, and a failure says so.",
               "max_penetration(0.01)"});
  w.push_back({"no_contact",
               WordKind::kExpectation,
               {{"a", kPartOrHand, kRequired, "a part, or \"hand\""},
                {"b", kPart, kRequired, "another part"}},
               "a and b never touch.",
               "no_contact(\"piston\", \"crankcase\")"});
  w.push_back({"warnings_at_most",
               WordKind::kExpectation,
               {{"count", kCount, kRequired,
                 "how many warnings may be written (`warn` actions and the run's own: a move of "
                 "a fixed part, a refused snap, a glove far from every part, a rule that can "
                 "never fire)"}},
               "At most this many warnings.",
               "warnings_at_most(0)"});
  w.push_back({"mate_made",
               WordKind::kExpectation,
               {{"mate", kMate, kRequired, "the mate"}},
               "The mate has snapped by the end (and not been undone by a move).",
               "mate_made \"peg_in_hole\""});
  w.push_back(
      {"grasped_as",
       WordKind::kExpectation,
       {{"part", kPart, kRequired, "the part"}, {"type", kGraspType, kRequired, "the grasp type"}},
       "The hand grasps the part with this grasp type at some time. Failed, it says the "
       "hand's closest try: the moment most of the hand touched the part (while the hand "
       "closed, if it touched it then), what touched it, what the grasp lacked (the palm "
       "within 2 mm, a finger opposing it, the hand closing) and the other parts the hand "
       "touched then, which stop the fingers they meet (a table under a bar).",
       "grasped_as(\"pin\", \"precision\")"});
  return w;
}

}  // namespace

std::string_view word_kind_name(WordKind kind) {
  switch (kind) {
    case WordKind::kDeclaration:
      return "declaration";
    case WordKind::kShape:
      return "shape";
    case WordKind::kEvent:
      return "event";
    case WordKind::kState:
      return "state";
    case WordKind::kAction:
      return "action";
    case WordKind::kExpectation:
      return "expectation";
  }
  return "?";
}

std::string_view arg_type_name(ArgType type) {
  switch (type) {
    case kPart:
      return "part";
    case kPartOrHand:
      return "part or \"hand\"";
    case kMate:
      return "mate";
    case kStep:
      return "step";
    case kRegion:
      return "region";
    case kSeconds:
      return "seconds";
    case kLength:
      return "length";
    case kNumber:
      return "number";
    case kCount:
      return "count";
    case kText:
      return "text";
    case kGraspType:
      return "grasp type";
    case kVector:
      return "{x, y, z}";
    case kDirection:
      return "direction";
    case kTurn:
      return "{x = deg, y = deg, z = deg}";
    case kColor:
      return "colour";
    case kFunction:
      return "function";
    case kFlag:
      return "true/false";
    case kFile:
      return "file";
    case kTable:
      return "table";
    case kList:
      return "list";
    case kMap:
      return "names = ...";
    case kWord:
      return "word";
    case kNames:
      return "{names}";
  }
  return "?";
}

const std::vector<Word>& vocabulary() {
  static const std::vector<Word> words = make_vocabulary();
  return words;
}

const Word* find_word(std::string_view name) {
  for (const Word& word : vocabulary()) {
    if (word.name == name) return &word;
  }
  return nullptr;
}

std::string reference_markdown() {
  static constexpr std::pair<WordKind, std::string_view> kSections[] = {
      {WordKind::kDeclaration, "Declarations"},
      {WordKind::kShape, "Shapes"},
      {WordKind::kEvent, "Events (`when =`)"},
      {WordKind::kState, "States (`unless =`, `only_if =`)"},
      {WordKind::kAction, "Actions (`act =`)"},
      {WordKind::kExpectation, "Expectations (`expect =`)"},
  };
  std::string out;
  for (const auto& [kind, title] : kSections) {
    out += "### " + std::string(title) + "\n\n";
    for (const Word& word : vocabulary()) {
      if (word.kind != kind) continue;
      const bool fields = kind == WordKind::kDeclaration || kind == WordKind::kShape;
      out += "#### `" + std::string(word.name);
      if (!fields) {
        out += "(";
        for (std::size_t i = 0; i < word.params.size(); ++i) {
          out += (i ? ", " : "") + std::string(word.params[i].name);
          if (word.params[i].optional) out += "?";
        }
        out += ")";
      }
      out += "`\n\n" + std::string(word.doc) + "\n\n";
      out +=
          fields ? "| field | type | |\n|---|---|---|\n" : "| argument | type | |\n|---|---|---|\n";
      for (const Param& p : word.params) {
        out += "| `" + std::string(p.name) + "` | " + std::string(arg_type_name(p.type)) + " | " +
               (p.optional ? "optional: " : "") + std::string(p.doc) + " |\n";
      }
      out += "\n```lua\n" + std::string(word.example) + "\n```\n\n";
    }
  }
  return out;
}

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  std::iota(row.begin(), row.end(), std::size_t{0});
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

std::optional<std::string> nearest_name(std::string_view name,
                                        std::span<const std::string> candidates) {
  const std::size_t limit = std::max<std::size_t>(2, name.size() / 3);
  // Of equally near names, the one that shares the longest start: for
  // "nodes[5]_3", "nodes[5]_2" rather than "nodes[25]_3".
  const auto common_start = [&](const std::string& candidate) {
    std::size_t n = 0;
    while (n < name.size() && n < candidate.size() && name[n] == candidate[n]) ++n;
    return n;
  };
  const std::string* best = nullptr;
  std::size_t best_distance = limit + 1, best_start = 0;
  for (const std::string& candidate : candidates) {
    const std::size_t d = edit_distance(name, candidate);
    if (d > limit || d > best_distance) continue;
    const std::size_t start = common_start(candidate);
    if (d < best_distance || start > best_start) {
      best_distance = d;
      best_start = start;
      best = &candidate;
    }
  }
  if (best == nullptr) return std::nullopt;
  return *best;
}

std::string did_you_mean(std::string_view name, std::span<const std::string> candidates) {
  const std::optional<std::string> best = nearest_name(name, candidates);
  return best ? " (did you mean '" + *best + "'?)" : "";
}

}  // namespace dovetail::scripting
