-- A well-behaved scenario among the hostile ones: it still runs and passes.
return scenario {
  name = "well behaved", duration = 0.5,
  parts = { a = part { shape = box { size = { 10, 10, 10 } } } },
  steps = { step { "wait", done = after(0.2) } },
  expect = { steps_in_order { "wait" }, finished_within(0.3) },
}
