-- A hand over a box, from a plan beside the scenario (tests write copies of
-- both and try to record over the plan).
return scenario {
  name = "plan alias", duration = 0.2,
  parts = { base = part { shape = box { size = { 100, 20, 100 } }, fixed = true } },
  hand = glove { plan = "hand.plan" },
}
