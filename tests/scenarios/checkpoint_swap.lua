-- A joint run's save (joint/checkpoint.lua, M.swap) killed at any moment leaves a whole state
-- where the next run looks for one: the kill is simulated before each file operation of the swap
-- (a rename or a removal), from each state a folder can be in when a save starts (the last save
-- whole; a run resumed from .resume.old after a kill between the renames, with or without a cut
-- .resume), and the state found afterwards must be the current one or the new one, never none.
-- (Once, a run resumed from .old removed it before renaming the new one in: a kill there lost
-- the run's progress.) The run's end (M.clear) too: killed at any moment, it leaves no state
-- whose world is gone.
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

-- The end of a run (M.clear) killed at any moment, before a file operation or half-way through a
-- folder's removal (its world.h5 gone, its state.lua not yet): the next run finds no state, or a
-- whole one (state.lua beside world.h5), never a state.lua whose world is gone.
local function write_whole(path, step)
  write_state(path, step)
  local f = assert(io.open(path .. "/world.h5", "wb"))
  assert(f:write("world"))
  assert(f:close())
end
local clear_starts = {
  ["the last save whole"] = function() write_whole(out .. "/.resume", 1) end,
  ["a save's swap cut between its renames"] = function()
    write_whole(out .. "/.resume.old", 1)
    write_whole(out .. "/.resume.new", 2)
  end,
  ["a save cut short"] = function()
    write_whole(out .. "/.resume", 1)
    asperity.mkdir(out .. "/.resume.new")
  end,
}
local clear_cases = 0
for name, start in pairs(clear_starts) do
  for _, halfway in ipairs{false, true} do
    for kill = 1, 10 do
      asperity.remove_all(out)
      asperity.mkdir(out)
      start()
      assert(found_step() == 1, name .. ": the state is found before the run ends")
      -- The kill: the file operations the clear calls (asperity.remove_all, os.remove), wrapped.
      local remove_all, remove = asperity.remove_all, os.remove
      local ops = 0
      local function op(f, cut)
        return function(path)
          ops = ops + 1
          if ops == kill then
            if cut then cut(path) end
            error("killed", 0)
          end
          return f(path)
        end
      end
      local cut_removal = halfway and function(path) remove(path .. "/world.h5") end or nil
      asperity.remove_all, os.remove = op(remove_all, cut_removal), op(remove)
      local ok, err = pcall(checkpoint.clear, {P = P})
      asperity.remove_all, os.remove = remove_all, remove
      assert(ok or err == "killed", err)
      local state = checkpoint.find({P = P, log = function() end})
      assert(not state or read(state.path .. "/world.h5"),
             ("%s, killed %s operation %d of the clear: %s holds a state without its world"):format(
               name, halfway and "half-way through" or "before", kill, state and state.path))
      if ok then
        assert(not state and not read(out .. "/.resume.new/state.lua"), name .. ": a whole clear leaves no state")
        break
      end
      clear_cases = clear_cases + 1
    end
  end
end
print(("PASS checkpoint swap: %d kills, a whole state found after each; the run's end: %d kills, no state "
       .. "without its world"):format(cases, clear_cases))
