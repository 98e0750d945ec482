-- An endless loop: stopped by the instruction budget.
while true do end
return scenario { name = "hostile", parts = { a = part { shape = box { size = { 1, 1, 1 } } } }, duration = 0.1 }
