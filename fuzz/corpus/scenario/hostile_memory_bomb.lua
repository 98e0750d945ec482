-- Memory that grows without end: stopped by the memory cap.
local t = {}
while true do t[#t + 1] = ("x"):rep(1000) .. #t end
return scenario { name = "hostile", parts = { a = part { shape = box { size = { 1, 1, 1 } } } }, duration = 0.1 }
