#include "dovetail/scripting/scenario.h"

namespace dovetail::scripting {

std::string starting_scenario(const std::string& name, const std::string& file) {
  std::string text = R"lua(-- A Dovetail scenario. It describes an assembly: the parts, how they fit
-- (mates), the hand and its glove, the steps, what should happen when (rules)
-- and what must hold for the scenario to pass (expect). Run it with
--   dovetail check FILE    (loads it and checks every name)
--   dovetail run FILE --render out   (simulates it; out/final.png)
-- Every word is explained in docs/authoring.md.
return scenario {
  name = "NAME",
  units = "mm",                 -- every length below is in millimetres

  parts = {
    -- A fixed block with a 20.5 mm hole, 40 mm deep, its top face at y = 30.
    block = part {
      shape = block_with_hole { size = { 80, 60, 80 }, hole = 20.5, depth = 40 },
      fixed = true,
    },
    -- A 20 mm peg, 60 mm long, standing 10 mm above the hole (its z axis down).
    peg = part {
      shape = cylinder { diameter = 20, length = 60 },
      at = { 0, 100, 0 }, turn = { x = 90 },
    },
    -- A part may come from a mesh file instead, read in the file's own units
    -- when they are not the scenario's (glTF is in metres):
    -- bracket = part { mesh = "bracket.glb", units = "m", at = { 150, 0, 0 } },
  },

  mates = {
    -- The peg's lower end (0, 0, 60 in its frame) seats at the hole's bottom.
    peg_in_hole = mate {
      part = "peg", point = { 0, 0, 60 }, axis = "z",
      into = "block", at = { 0, -10, 0 }, along = "-y",
    },
  },

  -- Uncomment to let a simulated hand carry the peg (a plan file, in metres,
  -- as described in docs/interaction.md), or use trace = "recorded.csv".
  -- hand = glove { plan = "my.plan", holding = "peg" },

  steps = {
    step { "insert", "Put the peg into the hole", done = mated "peg_in_hole" },
  },

  rules = {
    -- Without a hand, a rule puts the peg in after one second.
    rule { when = after(1), act = { snap "peg_in_hole" } },
    rule { when = mated "peg_in_hole", act = { log "the peg is in" } },
  },

  expect = {
    steps_in_order { "insert" },
    finished_within(2),
    max_penetration(0.01),
  },
  duration = 2,
}
)lua";
  // The name goes into a Lua string: quotes, backslashes and control
  // characters escaped. The file goes into comments: a line each.
  std::string quoted;
  for (const char c : name) {
    if (c == '"' || c == '\\') {
      quoted += '\\';
      quoted += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      quoted += '\\';
      quoted += std::to_string(static_cast<int>(c));
    } else {
      quoted += c;
    }
  }
  std::string shown = file;
  for (char& c : shown) {
    if (static_cast<unsigned char>(c) < 0x20) c = '?';
  }
  // One pass, so that neither value is read again as a placeholder.
  std::string out;
  std::size_t from = 0;
  while (true) {
    const std::size_t at_name = text.find("NAME", from), at_file = text.find("FILE", from);
    const std::size_t at = std::min(at_name, at_file);
    if (at == std::string::npos) break;
    out.append(text, from, at - from);
    out += at == at_name ? quoted : shown;
    from = at + 4;
  }
  out.append(text, from, std::string::npos);
  text = std::move(out);
  return text;
}

}  // namespace dovetail::scripting
