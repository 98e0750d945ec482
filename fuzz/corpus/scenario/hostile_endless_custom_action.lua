-- A custom action that never returns, called during the run.
return scenario {
  name = "endless custom action", duration = 1,
  parts = { a = part { shape = box { size = { 10, 10, 10 } } } },
  rules = { rule { when = after(0.5), act = { custom(function(dt) while true do end end) } } },
}
