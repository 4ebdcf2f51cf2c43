-- The study runner (scripts/study.lua) killed with SIGKILL while a run is part-way, then started
-- again with the same command: the runs finished before are skipped (their files untouched), the
-- killed run starts again, every run ends finished, and no folder named as a result is ever
-- without a complete summary. Tiny joints (8 mm), one job at a time.
local json = require("json")
local out = assert(params.out, "give out=DIRECTORY")
local dir = out .. "/study"
os.execute("rm -rf '" .. out .. "'")
asperity.mkdir(out)
local sh = require("shell")
local exe = sh.program()
local study = asperity.scripts_dir .. "/study.lua"
local cmd = ("'%s' run '%s' surfaces=S1 stresses=14 directions=x,y models=rigid,elastic jobs=1 threads=1 " ..
             "report=false size=0.008 out='%s' joint='thickness=0.003 shear=1 pack_steps=50000 velocity=5e-6'")
            :format(exe, study, dir)
local names = {"S1_14_x_rigid_s1", "S1_14_x_elastic_s1", "S1_14_y_rigid_s1", "S1_14_y_elastic_s1"}

local exists, read = sh.exists, sh.read
local function sleep(s) io.popen(("sleep %g"):format(s)):close() end
-- Every folder named as a result holds a summary that parses (the runner renames only complete ones).
local function check_results()
  local finished = {}
  for _, name in ipairs(names) do
    if exists(dir .. "/" .. name) then
      local ok, s = pcall(json.read, dir .. "/" .. name .. "/summary.json")
      assert(ok and type(s.peak_shear_stress_mpa) == "number", "half-written result: " .. name .. ": " .. tostring(s))
      finished[#finished + 1] = name
    end
  end
  return finished
end

-- 1. Start the runner, wait until one run has finished and the next is part-way, kill it.
local pid = tonumber(io.popen(cmd .. " > '" .. out .. "/first.log' 2>&1 & echo $!"):read("l"))
local part
for _ = 1, 1200 do
  local finished = check_results()
  if #finished >= 1 then
    for _, name in ipairs(names) do
      if exists(dir .. "/" .. name .. ".part/log.txt") and (read(dir .. "/" .. name .. ".part/log.txt") or ""):find("halves in contact") then
        part = name
      end
    end
  end
  if part then break end
  sleep(0.05)
end
assert(part, "no run was seen part-way after the first one finished; first.log:\n" .. (read(out .. "/first.log") or ""))
os.execute("kill -KILL " .. pid)
sleep(1.5)   -- the run's wrapper notices that its runner is gone and stops the run
assert(not exists("/proc/" .. pid .. "/cmdline") or not read("/proc/" .. pid .. "/cmdline"):find("study.lua"), "the runner still runs")
for entry in io.popen("ls /proc"):lines() do
  local line = entry:match("^%d+$") and read("/proc/" .. entry .. "/cmdline")
  assert(not (line and line:find(dir .. "/", 1, true)), "a process of the killed study still runs: " .. tostring(line and line:gsub("%z", " ")))
end
local before = check_results()
assert(#before >= 1 and #before < #names, ("%d runs finished at the kill"):format(#before))
assert(exists(dir .. "/" .. part .. ".part") and not exists(dir .. "/" .. part),
       part .. " was killed part-way: it must be left as .part, not as a result")
local kept = {}
for _, name in ipairs(before) do kept[name] = read(dir .. "/" .. name .. "/summary.json") end
print(("killed the runner with %d of %d runs finished, %s part-way"):format(#before, #names, part))

-- 2. The same command again: it resumes.
local log_path = out .. "/second.log"
local ok, how, status = os.execute(cmd .. " > '" .. log_path .. "' 2>&1")
local log = read(log_path)
assert(ok and status == 0, ("the resumed study exited with %s %s:\n%s"):format(how, status, log))
assert(log:find(("%d finished before"):format(#before), 1, true), "the resumed runner counts the finished runs:\n" .. log)
for _, name in ipairs(before) do
  assert(not log:find("started " .. name, 1, true), name .. " was finished and must not run again:\n" .. log)
  assert(read(dir .. "/" .. name .. "/summary.json") == kept[name], name .. "'s result was rewritten")
end
assert(log:find("started " .. part .. " (again: it was interrupted)", 1, true), part .. " must start again:\n" .. log)
-- A model with a run finished before has an estimate from the start (that run's wall time).
local model_before = {}
for _, name in ipairs(before) do model_before[name:match("_(%a+)_s1$")] = true end
for line in log:gmatch("[^\n]+") do
  local model = line:match("%] started S1_14_%a_(%a+)_s1")
  if model and model_before[model] then
    assert(line:find("expected to end at", 1, true), "a " .. model .. " run finished before: an estimate at once:\n" .. log)
  end
end
local after = check_results()
assert(#after == #names, ("%d of %d runs finished after the resume"):format(#after, #names))
for _, name in ipairs(names) do assert(not exists(dir .. "/" .. name .. ".part"), name .. ".part left behind") end
local t = json.read(dir .. "/study.json")
assert(#t.runs == #names, ("study.json has %d rows"):format(#t.runs))
for _, row in ipairs(t.runs) do assert(row.status == "finished", row.name .. " is " .. row.status) end
print("PASS")
