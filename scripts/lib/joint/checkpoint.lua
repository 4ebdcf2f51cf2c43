-- A joint run that survives a kill (scripts/joint.lua checkpoint_every=): while it closes and
-- shears the joint, the run saves its whole state every `checkpoint_every` minutes of wall time
-- and when a SIGTERM arrives (a batch job's time limit, a study runner stopping it); the same
-- command with the same `out=` then resumes from the last save and writes the files an
-- uninterrupted run writes, byte for byte.
--
--   local checkpoint = require("joint.checkpoint")
--   local saved = checkpoint.find(run)          -- the state to resume from, or nil
--   ... the genesis, assembly.prepare, model.apply: deterministic, done again on resume
--   if saved then checkpoint.restore(run, saved) end   -- the world and the run's fields
--   run.checkpoint:poll(function() return {phase = "shear", ...} end)   -- in a phase's callback
--   checkpoint.clear(run)                       -- the run ended: the state is removed
--
-- On disk: OUT/.resume/world.h5 (the world, asperity's checkpoint) and OUT/.resume/state.lua (the
-- run's fields, the phase's own state and series, persist.lua), written into OUT/.resume.new and
-- then swapped in, so a kill at any moment leaves one whole state. What is not saved is done
-- again on resume: the genesis comes from the specimen cache, and the assembly and the model
-- from it are deterministic. A kill before the closure starts therefore starts the run again.
local persist = require("persist")
local read = require("shell").read

local M = {}

local VERSION = 1
-- Parameters that change how a run is carried out but not what it computes (the results do not
-- depend on the thread count), and where it is (a run folder may be moved): a resumed run may give
-- others.
local FREE = {threads = true, genesis_threads = true, progress = true, checkpoint_every = true, cache = true,
              save = true, out = true}
-- Parameters joint.lua gained after states were saved: a state saved without one was made with
-- this value (the behaviour before it existed), so it resumes where that value is given.
local MADE_WITHOUT = {mass_floor = 0, genesis_mass_floor = 0, genesis_damping = 0.7, rotation_lock_beams = false}
-- The run's fields (joint/context.lua) that the closure and the shear change and the report reads.
local RUN_FIELDS = {"ramp_steps", "moved_steps", "overlap_max", "overlap_at", "overlap_turning_max",
                    "overlap_turning_at", "escaped_count", "escape_box",
                    "z_contact", "normal_stiffness", "applied_z", "axis", "c0", "e0", "dynamic_ratio",
                    "dynamic_at", "shear_impulse", "peak_points", "speedup_max", "speedup_from",
                    "specimen_packed", "specimen_seconds"}
local SERIES = {"closure", "shear"}

local function dir(P) return P.out .. "/.resume" end


-- A state's folder, whole (a save cut short may have left a temporary file in it).
local function remove_state(path) asperity.remove_all(path) end

-- The parameters that shape the results, as text, for the comparison on resume.
local function signature(P)
  local t = {}
  for k, v in pairs(P) do if not FREE[k] then t[k] = v end end
  return t
end

local Checkpoint = {}
Checkpoint.__index = Checkpoint

-- run.checkpoint: saves every checkpoint_every minutes and on SIGTERM; 0 turns both off.
local function new(run)
  local P = run.P
  return setmetatable({run = run, every = P.checkpoint_every * 60, last = asperity.wall_time(),
                       saves = 0, resumes = 0}, Checkpoint)
end

function Checkpoint:enabled() return self.every > 0 end

-- Catches SIGTERM from here on: a signal is then served at the next poll (a save, and the end).
function Checkpoint:catch_terminate()
  if self:enabled() and not self.catching then
    asperity.catch_terminate(true)
    self.catching = true
  end
end

function Checkpoint:release_terminate()
  if self.catching then
    self.catching = false
    asperity.catch_terminate(false)   -- a SIGTERM not served ends the process here
  end
end

-- Saves the state `state_fn()` returns (the phase's own part: phase, steps_done, series, snaps,
-- locals) when the wall-time interval has passed or a SIGTERM arrived; after a SIGTERM the
-- process then ends as the signal would have ended it (exit status 143).
function Checkpoint:poll(state_fn)
  if not self:enabled() then return end
  local terminate = asperity.terminate_requested()
  if not terminate and asperity.wall_time() - self.last < self.every then return end
  self:save(state_fn())
  if terminate then
    self.run:log("SIGTERM: state saved at step %d; the same command resumes from it", self.run.world:step())
    asperity.terminate()
  end
end

function Checkpoint:save(part)
  local run, P = self.run, self.run.P
  local t0 = asperity.wall_time()
  local state = {version = VERSION, parameters = signature(P), step = run.world:step(), phase = part.phase,
                 steps_done = part.steps_done, snaps = part.snaps or {}, locals = part.locals or {},
                 series = {}, run = {}, wall_seconds = t0 - run.t_start, saves = self.saves + 1,
                 resumes = self.resumes}
  for _, k in ipairs(RUN_FIELDS) do state.run[k] = run[k] end
  for _, k in ipairs(SERIES) do
    if run[k] then state.series[k] = persist.series_state(run[k]) end
  end
  for k, s in pairs(part.series or {}) do state.series[k] = persist.series_state(s) end
  local text = persist.encode(state)
  local new_dir = dir(P) .. ".new"
  remove_state(new_dir)
  asperity.mkdir(new_dir)
  run.world:save(new_dir .. "/world.h5")
  local f = assert(io.open(new_dir .. "/state.lua", "wb"))
  assert(f:write(text))
  assert(f:close())
  M.swap(P)
  self.saves = self.saves + 1
  self.last = asperity.wall_time()
  run:log("checkpoint %d at step %d (%s): %.1f s", self.saves, state.step, part.phase, self.last - t0)
end

-- The whole new state in OUT/.resume.new put in place of the current one, so that a kill at any
-- moment leaves a whole state where find looks: OUT/.resume, or OUT/.resume.old while .resume is
-- not whole. The current state is .resume if it holds a state, else .old (a run resumed from
-- .old after a kill between the renames): .old goes only once .resume holds a state, or the
-- current one would be lost until the new one is renamed in. `given` (tests) replaces some of the
-- file operations: rename(from, to), remove(path), has_state(path).
function M.swap(P, given)
  local fs = {rename = function(a, b) assert(os.rename(a, b)) end, remove = remove_state,
              has_state = function(path) return read(path .. "/state.lua") ~= nil end}
  for k, f in pairs(given or {}) do fs[k] = f end
  local final, new_dir, old_dir = dir(P), dir(P) .. ".new", dir(P) .. ".old"
  if fs.has_state(final) then
    fs.remove(old_dir)
    fs.rename(final, old_dir)
  else
    fs.remove(final)  -- what a save cut short left, if anything
  end
  fs.rename(new_dir, final)
  fs.remove(old_dir)
end

-- The saved state in OUT (nil if none), checked against the run's parameters. Also makes
-- run.checkpoint.
function M.find(run)
  local P = run.P
  run.checkpoint = new(run)
  if P.checkpoint_every <= 0 then return nil end
  -- A kill between the two renames of a save leaves the previous state as .resume.old.
  for _, path in ipairs{dir(P), dir(P) .. ".old"} do
    local text = read(path .. "/state.lua")
    if text then
      local state = persist.decode(text, path .. "/state.lua")
      if type(state) ~= "table" or state.version ~= VERSION then
        error(("%s holds a saved state this version of joint.lua cannot resume (version %s); remove it "
               .. "or give another out="):format(path, tostring(type(state) == "table" and state.version)), 0)
      end
      local now = signature(P)
      local names = {}
      for k in pairs(now) do names[#names + 1] = k end
      for k in pairs(state.parameters) do if now[k] == nil and not FREE[k] then names[#names + 1] = k end end
      table.sort(names)
      for _, k in ipairs(names) do
        local was = state.parameters[k]
        if was == nil then was = MADE_WITHOUT[k] end
        if now[k] ~= was then
          error(("out=%s holds a run saved with %s=%s, not %s: give the same parameters to resume it, or "
                 .. "remove %s (or give another out=) to start afresh"):format(P.out, k,
                 tostring(was), tostring(now[k]), path), 0)
        end
      end
      state.path = path
      return state
    end
  end
  return nil
end

-- Puts the saved world and the run's saved fields in place (after the deterministic preparation,
-- whose world the saved one replaces).
function M.restore(run, state)
  local P = run.P
  run.world = asperity.load(state.path .. "/world.h5", {threads = P.threads, simd = P.simd})
  if run.world:step() ~= state.step then
    error(("%s: the world is at step %d, the state at %d: remove it to start afresh"):format(
      state.path, run.world:step(), state.step), 0)
  end
  for _, k in ipairs(RUN_FIELDS) do run[k] = state.run[k] end
  -- A state saved before the turning particles' overlap was tracked: the deepest of any contact
  -- bounds it.
  if run.overlap_turning_max == nil then
    run.overlap_turning_max, run.overlap_turning_at = run.overlap_max, run.overlap_at
  end
  for _, k in ipairs(SERIES) do
    if state.series[k] then run[k] = persist.series_from(state.series[k]) end
  end
  run.t_start = asperity.wall_time() - state.wall_seconds
  run.checkpoint.saves, run.checkpoint.resumes = state.saves, state.resumes + 1
  run.resumes = run.checkpoint.resumes
  run:log("resumed from %s: step %d, %s phase (resume %d)", state.path, state.step, state.phase,
          run.checkpoint.resumes)
end

-- The run ended: its saved state goes. The states' markers (state.lua, what find looks for) go
-- first, each in one unlink, and the folders after them: a folder removal cut short by a kill
-- could otherwise leave a state.lua whose world.h5 was already removed, which the next run would
-- find and fail to load.
function M.clear(run)
  local P = run.P
  for _, path in ipairs{dir(P), dir(P) .. ".old"} do os.remove(path .. "/state.lua") end
  for _, path in ipairs{dir(P), dir(P) .. ".new", dir(P) .. ".old"} do remove_state(path) end
end

return M
