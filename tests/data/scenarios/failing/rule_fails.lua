return scenario {
  name = "a rule fails", units = "mm", duration = 2,
  parts = { a = part { shape = box { size = { 10, 10, 10 } } } },
  rules = { rule { when = after(0.5), act = { fail "stop here" } } },
}
