-- Engine piston: a piston and its connecting rod are pulled out of a cylinder
-- and put back, beside the two-cylinder engine of assimp's test models
-- (2CylinderEngine.glb from Debian's assimp-testmodels, in millimetres).
--
-- What is a stand-in: the engine is one fixed part, and its own pistons, pins
-- and rods are merged into it, inside its cylinders. The piston and rod the
-- hand moves are not the file's: a part could take single nodes of the file
-- (`nodes = { ... }`), but the file's own pistons fill the engine's bores, so
-- no bore would be free for a piston taken out of it.
-- So the piston and rod are one stand-in part (a 93 mm piston, the size of the
-- file's, and a rod with a big-end eye: assets/parts/make_parts.py), and they
-- work in a spare cylinder, a fixed block with a 93.6 mm blind bore, standing
-- on the bench in front of the engine.
--
-- Done by the hand, nothing scripted: the hand pulls piston and rod straight
-- up out of the bore, holds them, brings them back 1 mm off the bore's axis
-- and tilted 1.5 degrees; the mate's guidance draws them onto the axis, the
-- piston slides down the bore until its crown meets the bottom (the hand goes
-- on 3 mm; the rubber band stretches) and snaps into place when the hand
-- opens. Neither the piston and rod nor the hand ever touch the engine.
return scenario {
  name = "Piston and rod out and back in, beside the engine",
  units = "mm",

  parts = {
    engine = part {
      mesh = "/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb",
      units = "mm",  -- its numbers are millimetres, though glTF's are metres by its specification
      fixed = true, color = { 0.45, 0.6, 0.3 },  -- 743 x 273 x 268 mm, its base at y = -181
      open_surface = true,  -- its tessellation has cracks (13,308 open edges); nothing touches it
    },
    bench = part {
      shape = box { size = { 1000, 40, 800 } }, at = { 0, -201, 150 },
      fixed = true, color = "grey",
    },
    cylinder = part {
      shape = block_with_hole { size = { 140, 130, 140 }, hole = 93.6, depth = 100, sides = 96 },
      at = { 0, -116, 320 },                      -- on the bench; the bore's bottom at y = -151
      fixed = true, color = "steel",
    },
    piston_rod = part {
      mesh = "../assets/parts/piston_rod.obj",   -- crown at its origin, rod along its z
      at = { 0, -150.5, 320 }, turn = { x = -90 },  -- crown down, 0.5 mm over the bottom
      color = "brass",
    },
  },

  mates = {
    piston_in_cylinder = mate {
      part = "piston_rod", point = { 0, 0, 0 }, axis = "-z",   -- the crown, facing down
      into = "cylinder", at = { 0, -35, 0 }, along = "-y",      -- the bore's bottom
    },
  },

  -- The bore: the piston and rod are out once no part of them is in it.
  regions = {
    bore = region { min = { -46, -150, 274 }, max = { 46, -52, 366 }, parts = { "piston_rod" } },
  },

  hand = glove { plan = "../assets/glove/piston_out_and_in.plan", holding = "piston_rod" },

  steps = {
    step { "take_out", "Pull the piston and rod out of the cylinder", done = leaves("piston_rod", "bore") },
    step { "put_back", "Put them back until the crown sits on the bottom",
           done = mated "piston_in_cylinder" },
  },

  rules = {
    rule { when = leaves("piston_rod", "bore"), act = { log "the piston is out" } },
    rule { when = enters("piston_rod", "bore"), only_if = done "take_out",
           act = { log "the piston is going back in" } },
    rule { when = slides("piston_rod", "cylinder"), act = { highlight "cylinder" }, once = true },
    rule { when = mated "piston_in_cylinder",
           act = { unhighlight "cylinder", log "the piston is back in place" } },
    rule { when = touches("piston_rod", "engine"), act = { warn "the piston hit the engine" } },
    rule { when = grasped "piston_rod", act = { warn "the hand took hold of the piston again" } },
    rule { when = released "piston_rod", unless = near "piston_in_cylinder",
           act = { warn "the piston was let go outside the cylinder" } },
  },

  expect = {
    steps_in_order { "take_out", "put_back" },
    finished_within(5),
    mate_made "piston_in_cylinder",
    max_penetration(0.01),
    no_contact("piston_rod", "engine"),
    no_contact("hand", "engine"),
    warnings_at_most(0),
  },
}
