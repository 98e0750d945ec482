-- A syntax error.
return scenario { name = "broken" parts = {} }
