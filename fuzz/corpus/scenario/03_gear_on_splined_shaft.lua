-- Gear on a splined shaft: the hand carries a 24-tooth gear whose bore has six
-- keyways down onto a shaft with six straight-sided splines (0.25 mm play on
-- every side), until the gear sits on the shaft's collar.
--
-- Done by the hand: the gear starts turned 10 degrees, with its keyways over
-- the splines' ends rather than between them, and the hand turns it into line
-- before lowering it (a mate draws a part onto its axis but never turns it
-- about that axis, so lining up the splines is the hand's job). Near the
-- shaft the mate's guidance draws the gear onto the shaft's axis; it slides
-- down over the splines and stops on the collar (the hand goes on 3 mm; the
-- rubber band stretches), and snaps into place when the hand opens. Lowered
-- without being turned, the gear would rest on the splines' ends instead: a
-- rule warns, and warnings_at_most(0) fails.
--
-- Nothing is scripted. The shaft and the gear are meshes written by
-- assets/parts/make_parts.py.
return scenario {
  name = "Gear onto a splined shaft",
  units = "mm",

  parts = {
    base = part { shape = box { size = { 90, 8, 90 } }, at = { 0, -4, 0 }, fixed = true, color = "grey" },
    shaft = part {
      mesh = "../assets/parts/splined_shaft.obj",  -- collar z = 0..10, splines to z = 50
      turn = { x = -90 },                           -- standing up: its z axis is the world's y
      fixed = true, color = "steel",
    },
    gear = part {
      mesh = "../assets/parts/splined_gear.obj",   -- 12 thick along its z, bore on its z axis
      at = { 0.4, 75, 0 }, turn = { x = -90, y = 10 },  -- flat, turned 10 degrees off the splines
      color = "brass",
    },
  },

  mates = {
    gear_on_shaft = mate {
      part = "gear", point = { 0, 0, 0 }, axis = "z",     -- the centre of the gear's lower face
      into = "shaft", at = { 0, 0, 10 }, along = "z",    -- the centre of the collar's top
    },
  },

  -- Around the splines below their ends: the gear is in it once it is on the splines.
  regions = {
    on_splines = region { min = { -12, 10, -12 }, max = { 12, 46, 12 }, parts = { "gear" } },
  },

  hand = glove { plan = "../assets/glove/gear_on_shaft.plan", holding = "gear", grasp = "tripod" },

  steps = {
    step { "engage", "Line the keyways up with the splines and start the gear onto the shaft",
           done = enters("gear", "on_splines") },
    step { "seat", "Slide the gear down until it sits on the collar", done = mated "gear_on_shaft" },
  },

  rules = {
    rule { when = enters("gear", "on_splines"), act = { log "the gear is on the splines" } },
    rule { when = slides("gear", "shaft"), act = { highlight "shaft" }, once = true },
    rule { when = slides("gear", "shaft"), unless = near "gear_on_shaft",
           act = { warn "the gear caught on the shaft before reaching the collar" } },
    rule { when = mated "gear_on_shaft", act = { unhighlight "shaft", log "the gear is seated" } },
    rule { when = released "gear", unless = near "gear_on_shaft",
           act = { warn "the gear was let go off the shaft" } },
  },

  expect = {
    steps_in_order { "engage", "seat" },
    finished_within(3.5),
    mate_made "gear_on_shaft",
    max_penetration(0.01),
    warnings_at_most(0),
  },
}
