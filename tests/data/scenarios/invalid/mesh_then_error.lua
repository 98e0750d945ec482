-- Names a mesh beside it, then fails to load (an unknown part in a rule):
-- the run writes no report over the mesh.
return scenario {
  name = "mesh then error", duration = 0.2,
  parts = { cube = part { mesh = "cube.obj" } },
  rules = { rule { when = touches("cube", "nope"), act = { log "x" } } },
}
