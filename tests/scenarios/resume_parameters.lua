-- A saved joint run (joint/checkpoint.lua) is resumed only with the parameters it was made with;
-- a parameter joint.lua gained after the save counts at the value that reproduces the run before
-- it existed (mass_floor = 0: true masses), so such a run resumes where that value is given and is
-- refused, by name, where another is.
local checkpoint = require("joint.checkpoint")
local persist = require("persist")
local out = assert(params.out, "give out=DIRECTORY")
asperity.remove_all(out)
asperity.mkdir(out .. "/.resume")
local saved = {version = 1, phase = "shear", step = 1000,
               parameters = {model = "elastic", surface = "S1", stress = 14}}   -- saved before mass_floor existed
local f = assert(io.open(out .. "/.resume/state.lua", "wb"))
assert(f:write(persist.encode(saved)))
assert(f:close())

local function find(extra)
  local P = {checkpoint_every = 5, out = out, model = "elastic", surface = "S1", stress = 14}
  for k, v in pairs(extra) do P[k] = v end
  return pcall(checkpoint.find, {P = P, log = function() end})
end
local ok, state = find{mass_floor = 0}
assert(ok and state and state.step == 1000, "a state saved without mass_floor resumes with mass_floor=0: " .. tostring(state))
local refused, why = find{mass_floor = 0.75}
assert(not refused and tostring(why):find("mass_floor=0, not 0.75", 1, true), "refused by name: " .. tostring(why))
local other, why2 = find{mass_floor = 0, stress = 21}
assert(not other and tostring(why2):find("stress=14, not 21", 1, true), "a parameter it was saved with: " .. tostring(why2))
print("PASS")
