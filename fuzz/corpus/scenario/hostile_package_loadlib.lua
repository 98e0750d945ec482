-- The package library is absent.
local f = package.loadlib("libc.so.6", "system")
return scenario { name = "hostile", parts = { a = part { shape = box { size = { 1, 1, 1 } } } }, duration = 0.1 }
