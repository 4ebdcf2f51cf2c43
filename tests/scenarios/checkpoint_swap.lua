-- A joint run's save (joint/checkpoint.lua, M.swap) killed at any moment leaves a whole state
-- where the next run looks for one: the kill is simulated before each file operation of the swap
-- (a rename or a removal), from each state a folder can be in when a save starts (the last save
-- whole; a run resumed from .resume.old after a kill between the renames, with or without a cut
-- .resume), and the state found afterwards must be the current one or the new one, never none.
-- (Once, a run resumed from .old removed it before renaming the new one in: a kill there lost
-- the run's progress.)
local checkpoint = require("joint.checkpoint")
local persist = require("persist")
local read = require("shell").read
local out = assert(params.out, "give out=DIRECTORY")

local P = {checkpoint_every = 5, out = out, model = "elastic", surface = "S1", stress = 14}
local function write_state(path, step)
  asperity.mkdir(path)
  local f = assert(io.open(path .. "/state.lua", "wb"))
  assert(f:write(persist.encode({version = 1, phase = "shear", step = step,
                                 parameters = {model = "elastic", surface = "S1", stress = 14}})))
  assert(f:close())
end
local function found_step()
  local state = checkpoint.find({P = P, log = function() end})
  return state and state.step
end

-- Where the current state (step 1) is when a save starts; the new one (step 2) is whole in .new.
local starts = {
  ["the last save whole"] = function() write_state(out .. "/.resume", 1) end,
  ["resumed from .old"] = function() write_state(out .. "/.resume.old", 1) end,
  ["resumed from .old, .resume cut"] = function()
    write_state(out .. "/.resume.old", 1)
    asperity.mkdir(out .. "/.resume")   -- a folder without its state
  end,
}
local cases = 0
for name, start in pairs(starts) do
  for kill = 1, 10 do
    asperity.remove_all(out)
    asperity.mkdir(out)
    start()
    write_state(out .. "/.resume.new", 2)
    assert(found_step() == 1, name .. ": the current state is found before the save")
    local ops = 0
    local function op(f)
      return function(...)
        ops = ops + 1
        if ops == kill then error("killed", 0) end
        return f(...)
      end
    end
    local fs = {rename = op(function(a, b) assert(os.rename(a, b)) end), remove = op(asperity.remove_all)}
    local ok, err = pcall(checkpoint.swap, P, fs)
    assert(ok or err == "killed", err)
    local step = found_step()
    assert(step == 1 or step == 2, ("%s, killed before operation %d: no whole state found"):format(name, kill))
    if ok then
      assert(step == 2, name .. ": a whole swap leaves the new state")
      assert(not read(out .. "/.resume.old/state.lua") and not read(out .. "/.resume.new/state.lua"),
             name .. ": a whole swap leaves only .resume")
      break
    end
    cases = cases + 1
  end
end
print(("PASS checkpoint swap: %d kills, a whole state found after each"):format(cases))
