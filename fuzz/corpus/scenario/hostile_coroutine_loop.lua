-- Two coroutines handing over to each other for ever.
local a = coroutine.wrap(function() while true do coroutine.yield() end end)
while true do a() end
return scenario { name = "hostile", parts = { a = part { shape = box { size = { 1, 1, 1 } } } }, duration = 0.1 }
