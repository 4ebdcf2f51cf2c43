-- A reduced study through the real runner (scripts/study.lua) on tiny joints (8 mm, ~200
-- particles): S1 and S5 (they differ in H only), 14 MPa, -x, rigid and elastic, two jobs. Checks
-- the table rows, the cases, the plots and the trend report; a fracture run of S1 (bonds
-- installed stress-free, so the fracture model runs) for the event statistics;
-- a study whose runs all fail (a bad joint parameter): recorded with their message, exit status =
-- their number; the Slurm script of the first study: valid bash, every run named once, each
-- command the one the runner used, and its submission (with a stand-in sbatch) chains the run
-- array after the packing one.
local json = require("json")
local out = assert(params.out, "give out=DIRECTORY")
os.execute("rm -rf '" .. out .. "'")
asperity.mkdir(out)
local sh = require("shell")
local exe = sh.program()
local study = asperity.scripts_dir .. "/study.lua"
local read = sh.read
local exists = sh.exists
local function run(args, log) return sh.run(("%s run %s %s"):format(sh.quote(exe), sh.quote(study), args), log) end

-- 1. The reduced study.
local dir = out .. "/study"
local args = ("surfaces=S1,S5 stresses=14 directions=x models=rigid,elastic jobs=2 threads=1 size=0.008 " ..
              "out='%s' joint='thickness=0.003 shear=1 pack_steps=50000'"):format(dir)
local t0 = asperity.wall_time()
local status, log = run(args, out .. "/study.log")
print(("reduced study: exit %d in %.1f s"):format(status, asperity.wall_time() - t0))
assert(status == 0, "the reduced study failed:\n" .. log)
assert(select(2, log:gsub("packs the specimen", "")) == 2, "one packing per surface:\n" .. log)
for _, m in ipairs{"finished S1_14_x_rigid_s1", "finished S5_14_x_elastic_s1", "left"} do
  assert(log:find(m, 1, true), "progress line '" .. m .. "' missing:\n" .. log)
end
local t = json.read(dir .. "/study.json")
assert(#t.runs == 4, ("study.json: %d rows, want 4"):format(#t.runs))
local csv = read(dir .. "/study.csv")
local lines = {}
for line in csv:gmatch("[^\n]+") do lines[#lines + 1] = line end
assert(#lines == 5, ("study.csv: %d lines, want a header and 4 rows"):format(#lines))
assert(lines[1]:find("^name,surface,H,Lc_mm,s2_mm2,stress_mpa,direction,model,seed,"), "study.csv header: " .. lines[1])
for _, row in ipairs(t.runs) do
  assert(row.status == "finished", row.name .. ": " .. row.status .. " " .. row.message)
  local s = json.read(dir .. "/" .. row.name .. "/summary.json")
  assert(row.peak_shear_stress_mpa == s.peak_shear_stress_mpa, row.name .. ": the row holds the run's summary")
  assert(row.energy_shares_friction == s.energy_shares.friction, row.name .. ": nested scalars flattened")
  assert(row.H == (row.surface == "S1" and 0.75 or 0.52) and row.Lc_mm == 16 and row.s2_mm2 == 0.547,
         row.name .. ": surface statistics")
  assert(s.parameters.threads == 1 and s.parameters.thickness == 0.003 and s.parameters.size == 0.008,
         row.name .. ": the runner's parameters reach joint.lua")
end
assert(read(dir .. "/study_cases.csv"):find("\nS5,14,x,elastic,1,"), "study_cases.csv has the S5 elastic case")
for _, png in ipairs{"shear_rigid_14_x", "dilatancy_elastic_14_x", "contacts_elastic_14_x",
                     "models_S1_14", "models_dilatancy_S5_14", "strength_vs_H_14", "strength_vs_Lc_14", "strength_vs_s2_14",
                     "shear_stiffness_vs_stress", "energy_shares_elastic"} do
  local data = read(dir .. "/plots/" .. png .. ".png")
  assert(data and data:sub(2, 4) == "PNG", "plot " .. png .. ".png missing or not a PNG")
end
-- The trend report: the H pair (S5/S1) is compared once per model; the stress, direction and
-- s2/Lc trends are untestable on this subset and say why.
local trends = {}
for _, tr in ipairs(json.read(dir .. "/trends.json").trends) do trends[tr.id] = tr end
local h = assert(trends.peak_grows_as_hurst_falls, "trends.json lacks peak_grows_as_hurst_falls")
assert(h.comparisons == 2 and h.verdict ~= "untestable", ("H trend: %d comparisons (%s)"):format(h.comparisons, h.verdict))
assert(#h.pairs == 2 and h.pairs[1].low:find("^S5") and h.pairs[1].high:find("^S1"), "the H pairs go from S5 to S1")
for _, id in ipairs{"stress_peak", "directions_alike", "peak_grows_with_variance", "peak_falls_with_correlation_length"} do
  assert(trends[id] and trends[id].verdict == "untestable" and trends[id].reason, id .. " must be untestable, with a reason")
end
assert(trends.elastic_above_rigid_peak.comparisons == 2, "elastic against rigid: one comparison per surface")
assert(trends.fracture_between.verdict == "untestable", "no fracture run: untestable")
local md = read(dir .. "/trends.md")
assert(md:find("| peak shear stress grows as H falls | ", 1, true) and md:find("untestable", 1, true), "trends.md")
-- The runner's time is recorded, and the report gives it with the runs' times per model.
local elapsed = json.read(dir .. "/.study/elapsed.json")
assert(elapsed.invocations == 1 and elapsed.seconds > 0 and elapsed.jobs >= 1 and elapsed.threads == 1,
       "elapsed.json: " .. asperity.json(elapsed))
assert(md:find("## Run time", 1, true) and md:find("The runner ran for **", 1, true)
       and md:find("\n| rigid | 2 | ", 1, true) and md:find("\n| elastic | 2 | ", 1, true)
       and md:find("2 specimens were packed", 1, true), "the run time section:\n" .. md)
-- The fracture study, for the event statistics (events_every=100 by default for fracture runs).
local fdir = out .. "/fracture"
status, log = run(("surfaces=S1 stresses=14 directions=x models=fracture jobs=1 threads=1 size=0.008 " ..
                   "out='%s' joint='thickness=0.003 shear=1 pack_steps=50000'"):format(fdir),
                  out .. "/fracture.log")
assert(status == 0, "the fracture study failed:\n" .. log)
local evs = json.read(fdir .. "/events/events.json")
assert(evs.runs == 1 and evs.sampled_runs == 1, ("events: %s runs, %s sampled"):format(evs.runs, evs.sampled_runs))
assert(evs.pooled_events > 0 and evs.magnitude:find("log10 S"), "pooled events and the magnitude definition")
for _, f in ipairs{"summary.csv", "sizes.png", "xcorr.png", "xcorr.csv", "fluctuations.png", "fluctuations.csv",
                   "S1_14_x_fracture_s1_breaks.csv", "S1_14_x_fracture_s1_xcorr.csv"} do
  assert(exists(fdir .. "/events/" .. f), "events/" .. f .. " missing")
end
assert(exists(fdir .. "/plots/broken_bonds_fracture_14_x.png"), "broken bonds of the fracture runs")
local xc = read(fdir .. "/events/xcorr.csv")
assert(select(2, xc:gsub("\n", "")) == 22, "cross-correlations at lags 0..20")

-- One surface on two jobs: its packer packs on both cores (the other run waits for the specimen),
-- then shears on one; the run that waited gets no genesis threads.
local one = out .. "/one"
status, log = run(("surfaces=S1 stresses=14 directions=x models=rigid,elastic jobs=2 threads=1 size=0.008 " ..
                   "out='%s' report=false joint='thickness=0.003 shear=1 pack_steps=50000'"):format(one), out .. "/one.log")
assert(status == 0, "the one-surface study failed:\n" .. log)
if (tonumber(sh.capture("nproc")) or 1) >= 2 then
  assert(read(one .. "/S1_14_x_rigid_s1/command.txt"):find(" genesis_threads=2 ", 1, true)
         and log:find("packs the specimen on 2 threads", 1, true), "the packer packs on both cores:\n" .. log)
end
assert(not read(one .. "/S1_14_x_elastic_s1/command.txt"):find("genesis_threads", 1, true), "the waiting run packs nothing")
assert(json.read(one .. "/S1_14_x_rigid_s1/summary.json").parameters.threads == 1, "the packer shears on one thread")
-- A rerun does nothing (everything finished) and collect=true rebuilds the same rows.
status, log = run(args, out .. "/again.log")
assert(status == 0 and log:find("4 finished before", 1, true) and not log:find("started", 1, true), "rerun:\n" .. log)
assert(json.read(dir .. "/.study/elapsed.json").invocations == 1, "a runner that ran nothing adds no invocation")
os.remove(dir .. "/study.csv")
status, log = run(("collect=true out='%s'"):format(dir), out .. "/collect.log")
assert(status == 0 and read(dir .. "/study.csv") == csv, "collect=true rebuilds study.csv:\n" .. log)

-- The folder holds one study: other shared settings are refused.
status, log = run(args:gsub("pack_steps=50000", "pack_steps=60000"), out .. "/other.log")
assert(status == 1 and log:find("holds a study made with joint=thickness=0.003 shear=1 pack_steps=50000", 1, true), log)
-- A setting not given follows the folder: the command without joint= still writes the study's runs.
status, log = run(("surfaces=S1 stresses=14 directions=x models=elastic out='%s' slurm='%s'"):format(dir, out .. "/same.sbatch"),
                  out .. "/same.log")
assert(status == 0 and log:find("joint=thickness=0.003 shear=1 pack_steps=50000, as the study in", 1, true)
       and (read(out .. "/same.sbatch") or ""):find(" thickness=0.003 shear=1 pack_steps=50000 threads=", 1, true),
       "joint= follows the folder:\n" .. log)
-- A study made with speedup=2 resumes at 2 from a command without it, and is refused where another is given.
local old = out .. "/fast_made"
asperity.mkdir(old .. "/.study")
local f = assert(io.open(old .. "/.study/settings.json", "w"))
f:write('{"size": 0, "joint": "", "normal_stiffness": 0, "events_every": 100, "speedup": 2}\n')
f:close()
status, log = run(("surfaces=S1 stresses=14 directions=x models=elastic out='%s' slurm='%s'"):format(old, out .. "/old.sbatch"),
                  out .. "/old.log")
assert(status == 0 and log:find("speedup=2, as the study in", 1, true)
       and (read(out .. "/old.sbatch") or ""):find(" model=elastic seed=1 speedup=2 threads=", 1, true),
       "speedup follows the folder:\n" .. log .. tostring(read(out .. "/old.sbatch")))
status, log = run(("surfaces=S1 stresses=14 directions=x models=elastic speedup=4 out='%s' slurm='%s'")
                  :format(old, out .. "/old4.sbatch"), out .. "/old4.log")
assert(status == 1 and log:find("holds a study made with speedup=2, not 4", 1, true), log)

-- 2. Failures: recorded with the message, the others still run, exit status = their number.
local bad = out .. "/bad"
status, log = run(("surfaces=S1 stresses=14 directions=x,y models=rigid jobs=2 threads=1 out='%s' " ..
                   "joint='overlap_limit=-1'"):format(bad), out .. "/bad.log")
assert(status == 2, ("two failed runs: exit status %d, want 2\n%s"):format(status, log))
for _, row in ipairs(json.read(bad .. "/study.json").runs) do
  assert(row.status == "failed" and row.message:find("joint.lua: parameter overlap_limit=%-1: must be > 0", 1), row.name .. ": " .. row.message)
end
assert(log:find("FAILED S1_14_y_rigid_s1", 1, true), "the failure is reported:\n" .. log)
-- Failed runs are kept (not rerun) unless retry=true.
status, log = run(("surfaces=S1 stresses=14 directions=x,y models=rigid out='%s' joint='overlap_limit=-1'"):format(bad), out .. "/bad2.log")
assert(status == 2 and log:find("2 failed before", 1, true) and not log:find("started", 1, true), "failed runs kept:\n" .. log)
status, log = run(("surfaces=S1 stresses=14 directions=x,y models=rigid retry=true out='%s' joint='overlap_limit=-1'"):format(bad),
                  out .. "/bad3.log")
assert(status == 2 and select(2, log:gsub("started S1_14_", "")) == 2, "retry=true runs them again:\n" .. log)

-- 3. The Slurm script of the first study.
local sb = out .. "/study.sbatch"
status, log = run(args .. (" slurm='%s'"):format(sb), out .. "/slurm.log")
assert(status == 0, "slurm=:\n" .. log)
local ok = os.execute("bash -n '" .. sb .. "'")
assert(ok, "bash -n rejects " .. sb)
local text = read(sb)
local named = {}
for name, cmd in text:gmatch("%d+%) name=([%w_.]+); cmd=(.-) ;;\n") do
  assert(not named[name], name .. " is named twice")
  -- The single-quoted word as the shell reads it.
  local word = cmd:match("^'(.*)'$"):gsub("'\\''", "'")
  named[name] = word
end
local count = 0
for _, row in ipairs(t.runs) do
  count = count + 1
  local used = read(dir .. "/" .. row.name .. "/command.txt"):gsub("\n$", "")
  assert(named[row.name] == used, ("%s: the Slurm command differs from the runner's:\n%s\n%s"):format(row.name, tostring(named[row.name]), used))
end
local n = 0
for _ in pairs(named) do n = n + 1 end
assert(n == count, ("the script names %d runs, the study has %d"):format(n, count))
-- Submission with a stand-in sbatch that logs its arguments.
local bin = out .. "/bin"
asperity.mkdir(bin)
local f = assert(io.open(bin .. "/sbatch", "w"))
f:write("#!/bin/sh\necho \"$@\" >> \"$(dirname \"$0\")/sbatch.log\"\necho 4242\n")
f:close()
os.execute("chmod +x '" .. bin .. "/sbatch'")
ok = os.execute(("PATH='%s':\"$PATH\" bash '%s' > '%s/submit.log' 2>&1"):format(bin, sb, out))
local calls = read(bin .. "/sbatch.log") or ""
assert(ok and calls:find("%-%-array=0%-1 .* pack") and calls:find("%-%-array=0%-1 %-%-dependency=afterany:4242 .* run"),
       "submission: " .. calls)
-- Constant normal stiffness reaches every run's command line.
status, log = run(("surfaces=S2 stresses=21 directions=y models=elastic normal_stiffness=20 out='%s' slurm='%s'")
                  :format(out .. "/cns", out .. "/cns.sbatch"), out .. "/cns.log")
assert(status == 0 and read(out .. "/cns.sbatch"):find(" surface=S2 stress=21 direction=y model=elastic seed=1 " ..
       "normal_control=stiffness normal_stiffness=20 speedup=4 threads=", 1, true), "CNS command line:\n" .. tostring(read(out .. "/cns.sbatch")))
-- speedup reaches the elastic runs, not the rigid and fracture ones (joint.lua refuses it there).
status, log = run(("surfaces=S1 stresses=14 directions=x models=rigid,elastic,fracture speedup=4 out='%s' slurm='%s'")
                  :format(out .. "/fast", out .. "/fast.sbatch"), out .. "/fast.log")
text = read(out .. "/fast.sbatch") or ""
for _, m in ipairs{"rigid", "elastic", "fracture"} do
  local line = text:match("name=S1_14_x_" .. m .. "_s1; cmd=([^\n]*)")
  assert(status == 0 and line, "speedup study: no command line for " .. m .. ":\n" .. log)
  assert((line:find(" speedup=4 ", 1, true) ~= nil) == (m == "elastic"), m .. ": speedup=4 where joint.lua takes it: " .. line)
end
-- A study at constant velocity says so to its elastic runs (joint.lua's elastic default is 4).
status, log = run(("surfaces=S1 stresses=14 directions=x models=elastic speedup=1 out='%s' slurm='%s'")
                  :format(out .. "/steady", out .. "/steady.sbatch"), out .. "/steady.log")
assert(status == 0 and (read(out .. "/steady.sbatch") or ""):find(" model=elastic seed=1 speedup=1 threads=", 1, true),
       "speedup=1 study:\n" .. log .. tostring(read(out .. "/steady.sbatch")))
status, log = run(("surfaces=S1 models=elastic out='%s' joint='speedup=2' slurm='%s'"):format(out .. "/fast2", out .. "/fast2.sbatch"),
                  out .. "/fast2.log")
assert(status ~= 0 and log:find("speedup", 1, true) and log:find("set by the study itself", 1, true), "joint='speedup=' refused:\n" .. log)
-- A task of a finished run exits at once without running it again.
local before = read(dir .. "/S1_14_x_rigid_s1/summary.json")
ok = os.execute(("SLURM_ARRAY_TASK_ID=0 bash '%s' pack > '%s/task.log' 2>&1"):format(sb, out))
assert(ok and read(dir .. "/S1_14_x_rigid_s1/summary.json") == before, "a finished run's task must skip it")
print("PASS")
