-- The glove's plan does not exist: `check` says so, as `run` would.
return scenario {
  name = "missing plan", duration = 0.5,
  parts = { base = part { shape = box { size = { 100, 20, 100 } }, fixed = true } },
  hand = glove { plan = "no_such.plan" },
}
