-- pcall cannot swallow the budget error.
pcall(function() while true do end end)
return scenario { name = "hostile", parts = { a = part { shape = box { size = { 1, 1, 1 } } } }, duration = 0.1 }
