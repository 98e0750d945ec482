-- A scenario of many simulated hours: stopped by regress --timeout.
return scenario {
  name = "slow", duration = 3600, time_step = 0.001,
  parts = { a = part { shape = box { size = { 10, 10, 10 } } } },
}
