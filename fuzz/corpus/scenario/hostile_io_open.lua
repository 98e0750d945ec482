-- So are files.
local f = io.open("/etc/passwd")
return scenario { name = "hostile", parts = { a = part { shape = box { size = { 1, 1, 1 } } } }, duration = 0.1 }
