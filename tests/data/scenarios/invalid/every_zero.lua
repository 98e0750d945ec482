-- every(0) would never fire: a load error, not a silent rule.
return scenario {
  name = "every zero", duration = 1,
  parts = { a = part { shape = box { size = { 1, 1, 1 } } } },
  rules = { rule { when = every(0), act = { log "tick" } } },
}
