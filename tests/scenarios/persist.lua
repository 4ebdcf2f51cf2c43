-- scripts/lib/persist.lua: plain values and series written as text come back exactly (the state a
-- resumed joint run continues from), and what cannot come back is refused when written.
local persist = require("persist")

local v = {1, 2.5, -0.0, 0.1, 1 / 3, math.huge, -math.huge, 0 / 0, math.maxinteger, math.mininteger, 2 ^ 53,
           5e-324, "a \"quoted\"\nline", true, false,
           nested = {c0 = asperity.vec(0.1, -0.2, 1e-300), list = {{1, 2}, {3.0, 4}}, [7] = "seven", [2.5] = "x"}}
local text = persist.encode(v)
local back = persist.decode(text, "test")
for i = 1, 15 do
  local a, b = v[i], back[i]
  if a ~= a then assert(b ~= b, "NaN")
  else
    assert(a == b and math.type(a) == math.type(b), ("item %d: %s (%s) came back as %s (%s)"):format(
      i, tostring(a), math.type(a), tostring(b), math.type(b)))
  end
end
assert(1 / back[3] == -math.huge, "-0.0 keeps its sign")
assert(getmetatable(back.nested.c0) == getmetatable(asperity.vec(0, 0, 0)), "a vec comes back a vec")
assert(back.nested.c0[3] == 1e-300 and back.nested.c0.y == -0.2)
assert(back.nested.list[2][1] == 3.0 and math.type(back.nested.list[2][1]) == "float")
assert(back.nested[7] == "seven" and back.nested[2.5] == "x")
assert(persist.encode(back) == text, "the same state gives the same text")

local function refused(value, words)
  local ok, err = pcall(persist.encode, value)
  assert(not ok and err:find(words, 1, true), tostring(err))
end
refused({f = print}, "state.f is a function")
refused({w = {asperity.series{"a"}}}, "state.w[1] is a userdata")
local loop = {}
loop.self = loop
refused(loop, "state.self refers to a table that contains it")
refused({obj = setmetatable({}, {})}, "state.obj is a table with a metatable")
local ok, err = pcall(persist.decode, "return {", "broken.lua")
assert(not ok and err:find("broken.lua: not a saved state", 1, true), err)

local s = asperity.series{"x [m]", "n [1]", "label"}
s:record(0.1, 3, 1 / 3)
s:record(-2.5e-17, 4, 0 / 0)
local t = persist.series_from(persist.decode(persist.encode(persist.series_state(s)), "series"))
local names, units = t:names()
assert(table.concat(names, ",") == "x,n,label" and table.concat(units, ",") == "m,1,", "names and units")
assert(t:rows() == 2 and t:column("x")[2] == -2.5e-17 and t:column("label")[1] == 1 / 3)
assert(t:column("label")[2] ~= t:column("label")[2], "NaN in a series")
print("PASS persist")
