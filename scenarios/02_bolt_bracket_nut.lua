-- Bolt, bracket and nut: the hand carries an M10 bolt down through the 10.5 mm
-- hole of an angle bracket. Held 0.5 mm off the hole's axis and tilted 1.5
-- degrees, the bolt is drawn onto the axis by the mate's guidance, goes
-- through without touching the hole's wall, and its head comes down on the
-- flange, where it stops (the hand goes on 4 mm further; the rubber band
-- stretches). When the hand opens, the bolt snaps into place.
--
-- Scripted, not done by the hand: the nut. It waits on the base under the
-- hole, and once the bolt is in, a rule moves it straight up the bolt's axis
-- onto the shank (`move` does not look for collisions: the nut goes where it
-- is sent), and when it touches the flange's underside a rule snaps it into
-- place (`snap`). Nothing turns it: threads are not modelled, and its
-- 10.5 mm bore clears the 10 mm shank (no_contact checks that the nut never
-- touches the bolt).
--
-- The bolt, nut and bracket are meshes written by assets/parts/make_parts.py.
return scenario {
  name = "Bolt through a bracket, then a nut",
  units = "mm",

  parts = {
    bracket = part {
      mesh = "../assets/parts/bracket.obj",   -- flange top at y = 6, hole on the y axis
      fixed = true, color = "steel",
    },
    base = part {
      shape = box { size = { 70, 6, 40 } }, at = { -15, -53, 0 },
      fixed = true, color = "grey",
    },
    bolt = part {
      mesh = "../assets/parts/bolt.obj",      -- head top at its origin, shank along its z
      at = { 0.5, 70, 0 }, turn = { x = 90, z = -1.5 },  -- its z axis points down
      color = "blue",
    },
    nut = part {
      mesh = "../assets/parts/nut.obj",       -- 8 thick along its z
      at = { 0, -50, 0 }, turn = { x = -90 },  -- lying on the base, its z axis up
      color = "brass",
    },
  },

  mates = {
    bolt_through = mate {
      part = "bolt", point = { 0, 0, 7 }, axis = "z",      -- under the head
      into = "bracket", at = { 0, 6, 0 }, along = "-y",   -- the flange's top, on the hole
    },
    nut_on_bolt = mate {
      part = "nut", point = { 0, 0, 8 }, axis = "z",       -- the nut's upper face
      into = "bolt", at = { 0, 0, 13 }, along = "-z",     -- the flange's underside on the shank
    },
  },

  hand = glove { plan = "../assets/glove/bolt_bracket.plan", holding = "bolt", grasp = "tripod" },

  steps = {
    step { "insert_bolt", "Push the bolt through the bracket until its head sits on the flange",
           done = mated "bolt_through" },
    step { "fit_nut", "Run the nut up the bolt against the flange", done = mated "nut_on_bolt" },
  },

  rules = {
    rule { when = slides("bolt", "bracket"), act = { highlight "bracket" }, once = true },
    rule { when = mated "bolt_through",
           act = { unhighlight "bracket", log "the bolt is through the bracket",
                   move("nut", { 0, -8, 0 }, 0.8) } },
    rule { when = touches("nut", "bracket"), act = { snap "nut_on_bolt" }, once = true },
    rule { when = mated "nut_on_bolt", act = { highlight("nut", "green"), log "the nut is on" } },
    rule { when = released "bolt", unless = near "bolt_through",
           act = { warn "the bolt was let go away from the hole" } },
  },

  expect = {
    steps_in_order { "insert_bolt", "fit_nut" },
    finished_within(3.5),
    mate_made "bolt_through",
    mate_made "nut_on_bolt",
    max_penetration(0.01),
    no_contact("nut", "bolt"),
    warnings_at_most(0),
  },
}
