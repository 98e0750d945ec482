-- Binary chunks are refused.
local f = assert(load("\27Lua\84\0\25\147\13\10\26\10"))
return scenario { name = "hostile", parts = { a = part { shape = box { size = { 1, 1, 1 } } } }, duration = 0.1 }
