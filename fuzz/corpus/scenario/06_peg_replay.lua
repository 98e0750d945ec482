-- Peg in hole, replayed: the scene of 01_peg_in_hole.lua, but the hand is
-- driven by a recorded glove trace instead of a plan. The 20 mm peg goes into
-- the 20.5 mm hole as in 01: the mate's guidance draws it onto the hole's
-- axis, it slides down to the bottom and snaps into place when the hand opens.
--
-- Where the trace comes from: it is not a person's glove. It is 01's plan run
-- through the simulated glove's noise model (tracker 1 mm and 0.5 degrees,
-- joints 0.5 degrees, readings at 120 Hz held between readings, 5 ms latency,
-- seed 3) and recorded frame by frame:
--
--   01_peg_in_hole.lua with, in its glove,
--     noise = { position = 1, angle = 0.5, joints = 0.5, seed = 3 }
--   dovetail run that_copy.lua --record assets/traces/peg_in_hole.csv
--
-- So the hand shakes by about a millimetre as it carries the peg down; that
-- the peg still goes in, without overlapping the block, is what this checks.
-- (Replay is exact: the noisy run the trace was recorded from ends with the
-- same state hash as this one.) Nothing is scripted.
return scenario {
  name = "Peg in hole, from a recorded noisy trace",
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

  -- The run ends with the trace's last sample (3.6 s).
  hand = glove { trace = "../assets/traces/peg_in_hole.csv", holding = "peg" },

  steps = {
    step { "insert", "Slide the peg into the hole until it seats", done = mated "peg_in_hole" },
  },

  rules = {
    rule { when = slides("peg", "block"), act = { highlight "block" }, once = true },
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
