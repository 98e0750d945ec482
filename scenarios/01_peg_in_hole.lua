-- Peg in hole: a 20 mm peg, held 1.5 mm off the hole's axis and tilted by
-- 2 degrees, is carried down to a 20.5 mm hole 40 mm deep. As its tip comes
-- within 2 mm of the block the mate draws it onto the hole's axis, as a
-- chamfer would; it goes down without touching the wall, lands on the bottom
-- and slides there instead of passing through, and snaps into place when the
-- hand opens.
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
      into = "block", at = { 0, -10, 0 }, along = "-y",   -- the hole's bottom
    },
  },

  hand = glove { plan = "../assets/glove/peg_in_hole.plan", holding = "peg" },

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

  camera = { from = { 160, 170, 260 }, to = { 0, 20, 0 } },
}
