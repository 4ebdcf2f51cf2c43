-- A joint run that is killed resumes (scripts/joint.lua checkpoint_every, lib/joint/checkpoint.lua)
-- and writes what an unbroken run writes, byte for byte. The tiny fracture joint (8 mm, chaotic:
-- any difference in a resumed state would show in its breaks) with its energies sampled:
--   1. an unbroken run that never saves: the reference;
--   2. the same run, saving every 0.12 s: stopped by SIGTERM in its closure (it saves and ends with
--      status 143), refused when resumed with another parameter, resumed, killed with SIGKILL in
--      its shear, then killed with SIGKILL at random moments until it finishes;
--   3. its series, breaks, snapshot indexes and summary (timings aside) equal the reference's,
--      and nothing of its saved state is left.
local json = require("json")
local sh = require("shell")
local out = assert(params.out, "give out=DIRECTORY")
os.execute("rm -rf " .. sh.quote(out))
asperity.mkdir(out)
local exe = sh.program()
local exists, read = sh.exists, sh.read
local function sleep(s) io.popen(("sleep %g"):format(s)):close() end
-- A failed check shows the end of the runs' log.
local function log_tail()
  local text = read(out .. "/broken.log") or ""
  return "\n--- the last lines of " .. out .. "/broken.log:\n" .. text:sub(-3000)
end
assert = function(ok, message, ...)
  if not ok then error(tostring(message or "assertion failed") .. log_tail(), 2) end
  return ok, message, ...
end

-- The closure at a tenth of its default velocity: it then lasts several of the 0.12 s between
-- saves, so step 2 catches it in a save however fast the machine (at the default it took ~0.05 s).
local function command(dir, extra)
  return ("%s run %s size=0.008 thickness=0.003 shear=1 pack_steps=50000 progress=false cache=%s "
          .. "snapshots=0,0.5,0.75,1 model=fracture velocity=5e-6 closure_velocity=6e-6 events_every=50 threads=1 "
          .. "out=%s %s"):format(
          sh.quote(exe), sh.quote(asperity.scripts_dir .. "/joint.lua"), sh.quote(out .. "/cache"),
          sh.quote(dir), extra or "")
end

-- Starts a run in the background: its pid, and a function that tells its exit status once it ended
-- (nil while it runs).
local attempt = 0
local function start(dir, extra)
  attempt = attempt + 1
  local status_file = ("%s/status_%d"):format(out, attempt)
  local pid_file = ("%s/pid_%d"):format(out, attempt)
  local script = ("%s >> %s 2>&1 & pid=$!; echo $pid > %s; wait $pid; echo $? > %s"):format(
    command(dir, extra), sh.quote(out .. "/broken.log"), sh.quote(pid_file), sh.quote(status_file))
  os.execute(("bash -c %s &"):format(sh.quote(script)))
  local pid
  for _ = 1, 200 do
    pid = tonumber(read(pid_file) or "")
    if pid then break end
    sleep(0.02)
  end
  assert(pid, "the run did not start")
  return pid, function() return tonumber(read(status_file) or "") end
end
local function wait_for(status, seconds)
  for _ = 1, seconds / 0.05 do
    local s = status()
    if s then return s end
    sleep(0.05)
  end
  error("the run did not end within " .. seconds .. " s")
end
local function log_text() return read(out .. "/broken.log") or "" end
local function count(text, pattern) local n = 0; for _ in text:gmatch(pattern) do n = n + 1 end; return n end
-- Waits until the log holds `n` matches of `pattern`.
local function wait_log(pattern, n, status)
  for _ = 1, 1200 do
    if count(log_text(), pattern) >= n then return end
    assert(not status(), "the run ended before its log showed " .. pattern .. ":\n" .. log_text())
    sleep(0.02)
  end
  error("the log never showed " .. pattern .. ":\n" .. log_text())
end

-- 1. The reference (this also packs the specimen into the cache the others load).
local ref = out .. "/ref"
local _, ref_status = start(ref, "checkpoint_every=0")
assert(wait_for(ref_status, 600) == 0, "the reference run failed:\n" .. log_text())
assert(not exists(ref .. "/.resume"), "checkpoint_every=0 saves nothing")

-- 2. The broken run.
local dir = out .. "/broken"
local every = "checkpoint_every=0.002"   -- minutes: a save every 0.12 s
local pid, status = start(dir, every)
wait_log("%(closure%)", 1, status)
os.execute("kill -TERM " .. pid)
assert(wait_for(status, 60) == 143, "SIGTERM: the run saves its state and ends as the signal would (143)")
assert(log_text():find("SIGTERM: state saved"), "the run says it saved its state")
local state = read(dir .. "/.resume/state.lua")
assert(state and state:find('%["phase"%]="closure"'), "the state saved in the closure")

-- Another parameter than the saved run's is refused, by name, and the state is kept.
local _, other = start(dir, every .. " stress=21")
assert(wait_for(other, 120) ~= 0, "a resume with other parameters must fail")
assert(log_text():find("holds a run saved with stress=14, not 21", 1, true), "the refusal names the parameter:\n" .. log_text())
assert(read(dir .. "/.resume/state.lua") == state, "the refused run leaves the state as it was")

-- What a save cut short leaves (a temporary file of the world's in the new folder, one in the
-- current folder from an earlier cut) does not stop the next saves.
for _, junk in ipairs{dir .. "/.resume.new/world.h5.tmp", dir .. "/.resume/world.h5.tmp"} do
  asperity.mkdir(junk:match("^(.*)/"))
  local f = io.open(junk, "w"); f:write("cut short"); f:close()
end
pid, status = start(dir, every)
wait_log("resumed from [^\n]*closure phase", 1, status)
local shear_saves = count(log_text(), "%(shear%)")
wait_log("%(shear%)", shear_saves + 3, status)
os.execute("kill -KILL " .. pid)
assert(wait_for(status, 60) == 137, "SIGKILL ends the run at once (137)")

-- The run has finished once its summary is written and no saved state is left to resume: a kill
-- that lands in the milliseconds after it cleared its state (or while it clears it) ends a run
-- that is done, and the same command would then run it again from the start.
local function finished()
  return exists(dir .. "/summary.json") and not exists(dir .. "/.resume/state.lua")
         and not exists(dir .. "/.resume.old/state.lua")
end
math.randomseed(os.time())
local kills = 0
for _ = 1, 40 do
  pid, status = start(dir, every)
  sleep(0.4 + 1.2 * math.random())
  if status() then break end
  os.execute("kill -KILL " .. pid)
  local s = wait_for(status, 60)
  if s == 0 or finished() then break end
  assert(s == 137, "a killed run ends with 137, got " .. s)
  kills = kills + 1
end
if not finished() then
  pid, status = start(dir, every)
  assert(wait_for(status, 600) == 0, "the last attempt must finish:\n" .. log_text())
end
local resumed_in_shear = count(log_text(), "resumed from [^\n]*shear phase")
assert(resumed_in_shear >= 1, "a resume in the shear")
assert(finished() and not exists(dir .. "/.resume.new/state.lua"), "a finished run leaves no saved state")
if status() == 0 then  -- ended by itself, not by a kill in its clearing: nothing left at all
  assert(not exists(dir .. "/.resume") and not exists(dir .. "/.resume.old") and not exists(dir .. "/.resume.new"),
         "a finished run leaves no saved state's folder")
end

-- 3. The same files.
for _, name in ipairs{"closure.csv", "shear.csv", "breaks.csv", "events.csv", "joint.xdmf", "joint_closure.xdmf",
                      "joint_bonds.xdmf"} do
  local a, b = read(ref .. "/" .. name), read(dir .. "/" .. name)
  assert(a and #a > 0, "the reference wrote " .. name)
  assert(a == b, name .. ": the resumed run's file differs from the unbroken run's")
end
-- The summary: every result equal; what depends on the attempts (wall times, rebuilds after a
-- load, the cadence of saves, the resumes) and the output folder aside.
local ASIDE = {wall_seconds = true, shear_seconds = true, shear_microseconds_per_step = true, specimen_seconds = true,
               specimen_packed = true, shear_rebuilds = true, resumes = true, checkpoint_every = true, out = true,
               peak_memory_bytes = true, memory_bytes_per_particle = true}
local function compare(a, b, path)
  if type(a) ~= "table" or type(b) ~= "table" then
    assert(a == b or (a ~= a and b ~= b), ("summary %s: %s resumed, %s unbroken"):format(path, tostring(b), tostring(a)))
    return
  end
  for k, v in pairs(a) do if not ASIDE[k] then compare(v, b[k], path .. "." .. tostring(k)) end end
  for k in pairs(b) do assert(ASIDE[k] or a[k] ~= nil, "summary " .. path .. "." .. tostring(k) .. " only when resumed") end
end
local s_ref, s_dir = json.read(ref .. "/summary.json"), json.read(dir .. "/summary.json")
compare(s_ref, s_dir, "")
assert(s_ref.broken_bonds > 0, "the fracture run breaks bonds")
assert(s_dir.resumes >= 2 and s_ref.resumes == 0, ("resumes %s, reference %s"):format(s_dir.resumes, s_ref.resumes))
print(("PASS joint resume: SIGTERM in the closure, SIGKILL in the shear, %d random kills (%d resumes in the "
       .. "shear); files and results as the unbroken run's (%d broken bonds)"):format(kills, resumed_in_shear,
       s_ref.broken_bonds))
