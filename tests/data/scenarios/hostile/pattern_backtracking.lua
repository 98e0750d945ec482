-- A pattern that would backtrack for hours inside the string library, where
-- no guard can stop it: refused by its bound before it runs.
local s = string.rep("a", 3000)
s:find(".-.-.-b")
return scenario { name = "hostile", parts = { a = part { shape = box { size = { 1, 1, 1 } } } }, duration = 0.1 }
