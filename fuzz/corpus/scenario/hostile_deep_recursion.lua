-- Recursion without end: a stack overflow, not a crash.
local function f(n) return 1 + f(n + 1) end
f(1)
return scenario { name = "hostile", parts = { a = part { shape = box { size = { 1, 1, 1 } } } }, duration = 0.1 }
