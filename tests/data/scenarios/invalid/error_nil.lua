-- An error object that is not a string still names the file and line.
local reason = nil
error(reason)
