-- An hour simulated in 36 million frames (about 10 s of wall time here, ten
-- times the timeout): stopped by regress --timeout.
return scenario {
  name = "slow", duration = 3600, time_step = 0.0001,
  parts = { a = part { shape = box { size = { 10, 10, 10 } } } },
}
