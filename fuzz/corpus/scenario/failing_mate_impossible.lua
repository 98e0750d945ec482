-- Peg in hole with the mate's seat 20 mm below the hole's bottom: the mate can never be made.
-- Peg in hole: a 20 mm peg, held a little off the hole's axis and tilted by
-- 2 degrees, is carried down into a 20.5 mm hole 40 mm deep. It slides along
-- the hole's rim and wall instead of passing through, and snaps into place at
-- the bottom when the hand opens.
return scenario {
  name = "Peg in hole",
  units = "mm",

  parts = {
    block = part {
      shape = block_with_hole { size = { 80, 60, 80 }, hole = 20.5, depth = 40 },
      fixed = true, color = "steel",
    },
    peg = part {
      shape = cylinder { diameter = 20, length = 60 },
      at = { 1.5, 100, 0 }, turn = { x = 90, z = -2 },  -- its z axis points down
      color = "brass",
    },
  },

  mates = {
    peg_in_hole = mate {
      part = "peg", point = { 0, 0, 60 }, axis = "z",      -- the peg's lower end
      into = "block", at = { 0, -30, 0 }, along = "-y",   -- the hole's bottom
    },
  },

  hand = glove { plan = "../../../../assets/glove/peg_in_hole.plan", holding = "peg" },

  steps = {
    step { "insert", "Slide the peg into the hole until it seats", done = mated "peg_in_hole" },
  },

  rules = {
    rule { when = touches("peg", "block"), act = { highlight "block" }, once = true },
    rule { when = mated "peg_in_hole", act = { unhighlight "block", log "the peg is seated" } },
    rule { when = released "peg", unless = near "peg_in_hole",
           act = { warn "the peg was let go away from the hole" } },
  },

  expect = {
    steps_in_order { "insert" },
    finished_within(3.5),
    mate_made "peg_in_hole",
    max_penetration(0.01),
    warnings_at_most(0),
  },
}
