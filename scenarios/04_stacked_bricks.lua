-- Stacked bricks: three 2x4 bricks go one on another onto a studded base
-- plate, each one's studs fitting inside the cavity of the brick above with
-- 0.3 mm to spare; the middle brick is shifted by one stud, the top one back.
--
-- Done by the hand: the middle brick. The hand carries it in from the side
-- over the lower brick, tilted 1 degree and 0.4 mm off; the mate's guidance
-- draws it onto the studs' axis, it goes down over the studs until it sits on
-- the lower brick (the hand goes on 3 mm; the rubber band stretches) and snaps
-- into place when the hand opens. The hand then moves aside before the top
-- brick comes down past it (no_contact checks that they never touch).
--
-- Scripted, not done by the hand: the lower and the top brick. Each is moved
-- straight down onto the stack by a rule (`move` does not look for
-- collisions: they come down exactly on the studs' axis, which no_contact and
-- max_penetration check) and snapped into place as soon as it touches the
-- brick or plate below (`snap`).
--
-- The bricks and the plate are meshes written by assets/parts/make_parts.py.
return scenario {
  name = "Three bricks stacked",
  units = "mm",

  parts = {
    baseplate = part {
      mesh = "../assets/parts/baseplate.obj",  -- 6 x 4 studs, top at y = 3.2
      fixed = true, color = "green",
    },
    brick1 = part {
      mesh = "../assets/parts/brick_2x4.obj",  -- origin at the middle of its bottom, y up
      at = { 0, 33.2, 0 }, color = "red",      -- 30 mm over its place
    },
    brick2 = part {
      mesh = "../assets/parts/brick_2x4.obj",
      at = { 8.4, 40, 50 }, turn = { x = 1 },  -- in the hand, to the side
      color = "blue",
    },
    brick3 = part {
      mesh = "../assets/parts/brick_2x4.obj",
      at = { 0, 182.4, 0 }, color = "yellow",  -- 160 mm over its place
    },
  },

  mates = {
    brick1_on_plate = mate {
      part = "brick1", point = { 0, 0, 0 }, axis = "-y",
      into = "baseplate", at = { 0, 3.2, 0 }, along = "-y",
    },
    brick2_on_brick1 = mate {                  -- one stud (8 mm) along x
      part = "brick2", point = { 0, 0, 0 }, axis = "-y",
      into = "brick1", at = { 8, 9.6, 0 }, along = "-y",
    },
    brick3_on_brick2 = mate {                  -- and back
      part = "brick3", point = { 0, 0, 0 }, axis = "-y",
      into = "brick2", at = { -8, 9.6, 0 }, along = "-y",
    },
  },

  hand = glove { plan = "../assets/glove/stack_bricks.plan", holding = "brick2", grasp = "tripod" },

  steps = {
    step { "first", "Press the red brick onto the plate", done = mated "brick1_on_plate" },
    step { "second", "Press the blue brick onto the red one, one stud to the right",
           done = mated "brick2_on_brick1" },
    step { "third", "Press the yellow brick onto the blue one, in line with the red",
           done = mated "brick3_on_brick2" },
  },

  rules = {
    rule { when = after(0.1), act = { move("brick1", { 0, 3.2, 0 }, 0.5) } },
    rule { when = touches("brick1", "baseplate"), act = { snap "brick1_on_plate" }, once = true },
    rule { when = mated "brick1_on_plate", act = { log "red brick on the plate" } },

    rule { when = slides("brick2", "brick1"), act = { highlight "brick1" }, once = true },
    rule { when = released "brick2", unless = near "brick2_on_brick1",
           act = { warn "the blue brick was let go off the studs" } },
    rule { when = mated "brick2_on_brick1",
           act = { unhighlight "brick1", log "blue brick on the red one",
                   move("brick3", { 0, 22.4, 0 }, 1.2) } },

    rule { when = touches("brick3", "brick2"), act = { snap "brick3_on_brick2" }, once = true },
    rule { when = mated "brick3_on_brick2", act = { log "yellow brick on top" } },
  },

  expect = {
    steps_in_order { "first", "second", "third" },
    finished_within(4),
    no_contact("hand", "brick3"),
    mate_made "brick1_on_plate",
    mate_made "brick2_on_brick1",
    mate_made "brick3_on_brick2",
    max_penetration(0.01),
    warnings_at_most(0),
  },
}
