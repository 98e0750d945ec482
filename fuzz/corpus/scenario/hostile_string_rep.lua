-- A string of 2^40 bytes: refused before it is built.
local s = string.rep("x", 2^40)
return scenario { name = "hostile", parts = { a = part { shape = box { size = { 1, 1, 1 } } } }, duration = 0.1 }
