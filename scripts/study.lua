-- The study (scenarios.md 7, 8): closure + shear runs of joint.lua over surfaces x normal stresses x
-- directions x models x surface realisations, side by side, resumable, gathered into one table, a
-- trend report, comparison plots and the event statistics of the fracture runs.
--
--   build/asperity run scripts/study.lua                                   -- all 96 runs, out/study/
--   build/asperity run scripts/study.lua surfaces=S1,S4,S5 directions=x jobs=2 threads=1 out=out/s
--   build/asperity run scripts/study.lua collect=true out=out/s            -- tables and report again
--   build/asperity run scripts/study.lua slurm=study.sbatch out=/scratch/s -- a Slurm job array
--   build/asperity run scripts/study.lua --help                            -- the parameters
--
-- Every run is a child process `asperity run scripts/joint.lua ... out=DIR/NAME.part` started by
-- DIR/.study/run.sh, which renames the folder to DIR/NAME once the run has written its summary
-- (DIR/NAME.failed with the exit status if it failed). So a folder DIR/NAME is always a finished
-- run, and rerunning the same command skips it: a run that was killed is left as NAME.part and
-- resumes from the state it saved (joint.lua checkpoint_every; on SIGTERM too), or starts again
-- if it saved none. The runs of one surface and seed share one packed specimen (joint.lua's cache):
-- the first of them packs it, and the others start only once it is cached, so a specimen is
-- packed once however many jobs run at once.
--
-- Writes DIR/study.csv and DIR/study.json (one row per run), rewritten (to a temporary name, then
-- renamed) whenever a run ends; then the report (scripts/lib/study_report.lua): trends.json,
-- trends.md, plots/*.png, and events/ (scenarios.md 8). Exit status: the number of asked runs not
-- finished (failed or interrupted; at most 100).
local json = require("json")
local params_lib = require("params")

-- What the runner sets on every joint.lua command line itself: not to be given again through `joint`.
local RESERVED = {surface = true, stress = true, direction = true, model = true, seed = true, out = true,
                  threads = true, cache = true, size = true, progress = true, normal_control = true,
                  normal_stiffness = true, events_every = true, speedup = true}
-- The ones the study varies, each with the study's own list parameter.
local VARIED = {surface = "surfaces", stress = "stresses", direction = "directions", model = "models", seed = "seeds"}

local P = params_lib.parse{
  script = "study.lua",
  path = "scripts/study.lua",
  about = "closure + shear runs of joint.lua over surfaces x stresses x directions x models x seeds, " ..
          "resumable; one table, a trend report, plots, event statistics",
  {"surfaces", "S1,S2,S3,S4,S5,S6,S7,S8", list = "string", oneof = {"S1", "S2", "S3", "S4", "S5", "S6", "S7", "S8"},
   doc = "the generated surfaces"},
  {"stresses", "14,21", list = "number", unit = "MPa", above = 0, doc = "normal stresses, scaled to rock"},
  {"directions", "x,y", list = "string", oneof = {"x", "y"}, doc = "shear directions"},
  {"models", "rigid,elastic,fracture", list = "string", oneof = {"rigid", "elastic", "fracture"},
   doc = "particle models"},
  {"seeds", "1", list = "number", min = 1, doc = "surface realisations, whole numbers (one phase field per seed, " ..
   "shared by S1..S8; the packing uses the same seed)"},
  {"size", 0, unit = "m", min = 0, doc = "side of the joints (0: joint.lua's default)"},
  {"normal_stiffness", 0, unit = "MPa/mm", min = 0,
   doc = "> 0: every run under constant normal stiffness (normal_control=stiffness); 0: constant normal load"},
  {"speedup", 4, type = "integer", oneof = {1, 2, 4},
   doc = "joint.lua's speedup for the elastic runs (the loading rate may rise to this factor after the " ..
   "peak; 4 is joint.lua's elastic default); the rigid and fracture runs keep 1 (their results move with it; " ..
   "rigid runs take seconds)"},
  {"events_every", 100, type = "integer", unit = "steps", min = 0,
   doc = "between the energy samples of the fracture runs, for the event statistics (0: none)"},
  {"joint", "", doc = "more key=value parameters for every joint.lua run, space-separated (not those the study sets)"},
  {"out", "out/study", nonempty = true, doc = "the study's folder (one study per folder)"},
  {"cache", "", doc = "the folder of the packed specimens (\"\": out/cache); studies may share one"},
  {"jobs", 0, type = "integer", min = 0, doc = "runs at once (0: the machine's cores / threads)"},
  {"threads", 0, type = "integer", min = 0, doc = "threads of each run (0: the cores / jobs, at least 1)"},
  {"retry", false, doc = "true: runs that failed before are run again"},
  {"collect", false, doc = "true: only rebuild the tables and the report from out's folders"},
  {"slurm", "", doc = "a file: write a Slurm job-array script for the runs instead of running them"},
  {"report", true, doc = "false: tables only (no trends, plots, event statistics)"},
  {"asperity", "", file = true, doc = "the program each run uses (\"\": the one running this script)"},
  {"poll", 0.5, unit = "s", above = 0, doc = "between looks at the running jobs"},
  {"heartbeat", 600, unit = "s", min = 0, doc = "between progress lines while runs go on (0: only at starts and ends)"},
  notes = "A folder out/NAME is a finished run; rerunning the same command skips it (see scripts/README.md, \"The study\").",
  check = function(P, fail)
    -- The lists: not empty, no item twice, seeds whole numbers.
    for _, name in ipairs{"surfaces", "stresses", "directions", "models", "seeds"} do
      local items = params_lib.split(P[name], name == "stresses" or name == "seeds")
      if #items == 0 then fail(name, "must name at least one") end
      local seen = {}
      for _, v in ipairs(items) do
        if seen[v] then fail(name, ("'%s' is listed twice"):format(tostring(v))) end
        seen[v] = true
        if name == "seeds" and math.tointeger(v) == nil then
          fail(name, ("'%s' is not a whole number; seeds must be whole numbers >= 1"):format(tostring(v)))
        end
      end
    end
    for item in P.joint:gmatch("%S+") do
      local k = item:match("^([%a_][%w_]*)=")
      if not k then fail("joint", ("'%s' is not of the form key=value"):format(item)) end
      if RESERVED[k] then
        fail("joint", ("'%s' is set by the study itself (use its own parameter%s)"):format(k,
             VARIED[k] and ("s, e.g. " .. VARIED[k] .. "=") or ""))
      end
    end
  end,
}
if not P then return end   -- help printed

local function log(fmt, ...) io.stderr:write(("[study] " .. fmt .. "\n"):format(...)) end
local function fail(fmt, ...) error((fmt):format(...), 0) end

local surfaces = params_lib.split(P.surfaces)
local stresses = params_lib.split(P.stresses, true)
local directions = params_lib.split(P.directions)
local models = params_lib.split(P.models)
local seeds = {}
for k, v in ipairs(params_lib.split(P.seeds, true)) do seeds[k] = math.tointeger(v) end
local function words(text)
  local t = {}
  for item in text:gmatch("%S+") do t[#t + 1] = item end
  return t
end
local extra = words(P.joint)

local sh = require("shell")
local shell_quote, capture, absolute = sh.quote, sh.capture, sh.absolute
local DIR = absolute(P.out):gsub("/+$", ""):gsub("/%./", "/")
local CACHE = P.cache ~= "" and absolute(P.cache):gsub("/+$", "") or DIR .. "/cache"
-- The program: the one running this script, unless told.
local exe = P.asperity ~= "" and absolute(P.asperity) or sh.program()
local joint_script = absolute(asperity.scripts_dir) .. "/joint.lua"

-- The runs ---------------------------------------------------------------------------------------
-- Surface statistics (surfaces.md 4), from the generator's own table.
local surface_stats = {}
for k = 1, 8 do
  local name = "S" .. k
  local p = asperity.surface.generate{name = name, n = 9, side = 0.01, seed = 1}:params()
  surface_stats[name] = {H = p.H, Lc_mm = p.Lc * 1e3, s2_mm2 = p.variance * 1e6}
end

local function run_name(surface, stress, direction, model, seed)
  return ("%s_%g_%s_%s_s%d"):format(surface, stress, direction, model, seed)
end
-- The inverse, for folders found on disk (collect).
local function parse_name(name)
  local surface, stress, direction, model, seed = name:match("^(S%d)_([%d%.e%+%-]+)_([xy])_(%a+)_s(%d+)$")
  if not surface then return nil end
  return {name = name, surface = surface, stress = tonumber(stress), direction = direction, model = model,
          seed = tonumber(seed)}
end

local runs = {}
for _, seed in ipairs(seeds) do
  for _, surface in ipairs(surfaces) do
    for _, stress in ipairs(stresses) do
      for _, direction in ipairs(directions) do
        for _, model in ipairs(models) do
          runs[#runs + 1] = {name = run_name(surface, stress, direction, model, seed), surface = surface,
                             stress = stress, direction = direction, model = model, seed = seed,
                             group = surface .. "_s" .. seed}
        end
      end
    end
  end
end

-- Cores, jobs, threads.
local cores = tonumber(capture("nproc 2>/dev/null")) or 1
local jobs, threads = P.jobs, P.threads
if jobs == 0 and threads == 0 then threads = 1 end
if jobs == 0 then jobs = math.max(1, cores // threads) end
if threads == 0 then threads = math.max(1, cores // jobs) end

local number_text = params_lib.exact   -- the shortest decimal that reads back as the same number

-- The command line of one run: the same string here and in the Slurm script.
local function command(run)
  local args = {exe, "run", joint_script, "surface=" .. run.surface, "stress=" .. number_text(run.stress),
                "direction=" .. run.direction, "model=" .. run.model, "seed=" .. run.seed}
  if P.size > 0 then args[#args + 1] = "size=" .. number_text(P.size) end
  if P.normal_stiffness > 0 then
    args[#args + 1] = "normal_control=stiffness"
    args[#args + 1] = "normal_stiffness=" .. number_text(P.normal_stiffness)
  end
  if run.genesis_threads then args[#args + 1] = "genesis_threads=" .. run.genesis_threads end
  if run.model == "elastic" then args[#args + 1] = "speedup=" .. P.speedup end
  if run.model == "fracture" and P.events_every > 0 then args[#args + 1] = "events_every=" .. P.events_every end
  for _, item in ipairs(extra) do args[#args + 1] = item end
  args[#args + 1] = "threads=" .. threads
  args[#args + 1] = "cache=" .. CACHE
  args[#args + 1] = "out=" .. DIR .. "/" .. run.name .. ".part"
  for k, a in ipairs(args) do args[k] = shell_quote(a) end
  return table.concat(args, " ")
end

-- Files (written to a temporary name and renamed, so no reader ever sees half a file) -------------
local exists, read_text, write_atomic = sh.exists, sh.read, sh.write_atomic

-- The wrapper that runs one command and renames its folder (POSIX sh; flock from util-linux keeps
-- two processes from running one run, e.g. a resumed runner and the last run of a killed one).
local RUN_SH = [=[#!/bin/sh
# One run of a study, written by scripts/study.lua (the runner and its Slurm script both call it):
#
#   run.sh NAME WATCH_PID RETRY 'COMMAND'
#
# Runs COMMAND (an `asperity run .../joint.lua ... out=STUDY/NAME.part` line) with its output in
# STUDY/NAME.part/log.txt. On success (exit 0 and a summary.json) the folder is renamed to
# STUDY/NAME, so a folder STUDY/NAME is always a finished run and a finished run is skipped; on
# failure to STUDY/NAME.failed, with exit_status, which is skipped too unless RETRY is 1. A run
# ended by a signal (kill, Ctrl-C: status above 128) stays STUDY/NAME.part: next time it resumes
# from the state it saved (joint.lua checkpoint_every, and on SIGTERM, which this script passes
# on), or starts again if it saved none. WATCH_PID > 0: a process (the runner) whose end stops
# the run too.
set -u
study=$(cd "$(dirname "$0")/.." && pwd)
name=$1
watch=$2
retry=$3
cmd=$4
final="$study/$name"
part="$final.part"
failed="$final.failed"
mkdir -p "$study/.study/locks"
exec 9>"$study/.study/locks/$name"
flock -w 600 9 || { echo "run.sh: $name is locked by another process" >&2; exit 75; }
[ -f "$final/summary.json" ] && exit 0
[ "$retry" = 1 ] || [ ! -f "$failed/exit_status" ] || exit 0
# A run stopped part-way that saved its state (joint.lua's .resume) continues from it; any other
# starts afresh.
if [ -f "$part/.resume/state.lua" ] || [ -f "$part/.resume.old/state.lua" ]; then
  echo "run.sh: resuming $name from its saved state" >> "$part/log.txt"
else
  rm -rf "$part"
  mkdir -p "$part"
fi
printf '%s\n' "$cmd" > "$part/command.txt"
sh -c "exec $cmd" >> "$part/log.txt" 2>&1 9>&- &
child=$!
# SIGTERM (a batch system's time limit, a study runner stopping): passed on to the run, which
# saves its state and ends; this script then waits for it.
trap 'kill -TERM "$child" 2>/dev/null' TERM
# A process that has ended but not been reaped yet (a zombie) still answers kill -0: read its state.
alive() {
  if [ -r "/proc/$1/stat" ]; then
    state=$(sed 's/^.*) //' "/proc/$1/stat" 2>/dev/null | cut -c1)
    [ -n "$state" ] && [ "$state" != Z ]
  else
    kill -0 "$1" 2>/dev/null
  fi
}
if [ "$watch" -gt 0 ]; then
  while kill -0 "$child" 2>/dev/null; do
    if ! alive "$watch"; then
      kill "$child" 2>/dev/null
      wait "$child"
      exit 143
    fi
    sleep 0.2
  done
fi
wait "$child"
status=$?
# A trapped signal ends the wait early: wait on for the run's own status.
while alive "$child"; do
  wait "$child"
  status=$?
done
if [ "$status" -eq 0 ] && [ -f "$part/summary.json" ]; then
  rm -rf "$failed" "$final"
  mv "$part" "$final"
elif [ "$status" -gt 128 ]; then
  exit "$status"
else
  echo "$status" > "$part/exit_status"
  rm -rf "$failed"
  mv "$part" "$failed"
fi
]=]

-- The state of a run on disk: finished, failed, interrupted (a .part left) or pending.
local function state_of(name)
  if exists(DIR .. "/" .. name .. "/summary.json") then return "finished" end
  if exists(DIR .. "/" .. name .. ".failed/exit_status") then return "failed" end
  if exists(DIR .. "/" .. name .. ".part/command.txt") then return "interrupted" end
  return "pending"
end
-- A failed run's message: the error line joint.lua's process printed (the line before the
-- traceback), else its last line.
local function failure_message(folder)
  local text = read_text(folder .. "/log.txt") or ""
  local lines = {}
  for line in text:gmatch("[^\n]+") do lines[#lines + 1] = line end
  for k = 2, #lines do
    if lines[k]:match("^stack traceback:") then return lines[k - 1] end
  end
  local status = read_text(folder .. "/exit_status")
  return lines[#lines] or ("exit status " .. tostring(status and status:gsub("%s", "")))
end

-- Tables -----------------------------------------------------------------------------------------
local function flatten(t, prefix, out)
  for k, v in pairs(t) do
    if type(k) == "string" and k ~= "parameters" then
      local key = prefix .. k
      if type(v) == "table" and v ~= json.null then
        if next(v) ~= nil and v[1] == nil then flatten(v, key .. "_", out) end
      elseif v == json.null then
        out[key] = 0/0
      elseif type(v) == "number" or type(v) == "boolean" or type(v) == "string" then
        out[key] = v
      end
    end
  end
  return out
end

local FIXED = {"name", "surface", "H", "Lc_mm", "s2_mm2", "stress_mpa", "direction", "model", "seed",
               "cns_stiffness_mpa_per_mm", "status", "message"}

-- Every run folder under DIR (finished, failed, interrupted) and every requested run not yet
-- there, one row each: what collect=true and the runner both write.
local function gather(requested)
  local names, seen = {}, {}
  local listing = io.popen("ls -1 " .. shell_quote(DIR) .. " 2>/dev/null")
  for entry in listing:lines() do
    local base = entry:gsub("%.part$", ""):gsub("%.failed$", "")
    if parse_name(base) and not seen[base] then seen[base] = true; names[#names + 1] = base end
  end
  listing:close()
  for _, run in ipairs(requested or {}) do
    if not seen[run.name] then seen[run.name] = true; names[#names + 1] = run.name end
  end
  local rows = {}
  for _, name in ipairs(names) do
    local id = parse_name(name)
    local stats = surface_stats[id.surface]
    local row = {name = name, surface = id.surface, H = stats.H, Lc_mm = stats.Lc_mm, s2_mm2 = stats.s2_mm2,
                 stress_mpa = id.stress, direction = id.direction, model = id.model, seed = id.seed,
                 cns_stiffness_mpa_per_mm = 0, message = ""}
    local state = state_of(name)
    row.status = state
    if state == "finished" then
      local ok, summary = pcall(json.read, DIR .. "/" .. name .. "/summary.json")
      if ok then
        flatten(summary, "", row)
        local p = summary.parameters or {}
        if p.normal_control == "stiffness" then row.cns_stiffness_mpa_per_mm = p.normal_stiffness end
        row.size = p.size
      else
        row.status, row.message = "failed", "unreadable summary.json: " .. tostring(summary)
      end
    elseif state == "failed" then
      row.message = failure_message(DIR .. "/" .. name .. ".failed")
    end
    rows[#rows + 1] = row
  end
  -- Ordered as the study lists them: seed, surface, stress, direction, model.
  local model_rank = {rigid = 1, elastic = 2, fracture = 3}
  table.sort(rows, function(a, b)
    if a.seed ~= b.seed then return a.seed < b.seed end
    if a.surface ~= b.surface then return a.surface < b.surface end
    if a.stress_mpa ~= b.stress_mpa then return a.stress_mpa < b.stress_mpa end
    if a.direction ~= b.direction then return a.direction < b.direction end
    return (model_rank[a.model] or 9) < (model_rank[b.model] or 9)
  end)
  return rows
end

local function columns_of(rows)
  local fixed, cols, seen = {}, {}, {}
  for _, c in ipairs(FIXED) do fixed[c] = true; cols[#cols + 1] = c end
  local more = {}
  for _, row in ipairs(rows) do
    for k in pairs(row) do
      if not fixed[k] and not seen[k] then seen[k] = true; more[#more + 1] = k end
    end
  end
  table.sort(more)
  for _, k in ipairs(more) do cols[#cols + 1] = k end
  return cols
end

local function csv_field(v)
  if v == nil then return "" end
  if type(v) == "number" then
    if v ~= v then return "nan" end
    if math.type(v) == "integer" then return tostring(v) end
    return ("%.10g"):format(v)
  end
  local s = tostring(v)
  if s:find('[,"\n]') then s = '"' .. s:gsub('"', '""') .. '"' end
  return s
end

local function write_tables(rows)
  local cols = columns_of(rows)
  local lines = {table.concat(cols, ",")}
  for _, row in ipairs(rows) do
    local f = {}
    for k, c in ipairs(cols) do f[k] = csv_field(row[c]) end
    lines[#lines + 1] = table.concat(f, ",")
  end
  write_atomic(DIR .. "/study.csv", table.concat(lines, "\n") .. "\n")
  write_atomic(DIR .. "/study.json", asperity.json({columns = cols, runs = rows}))
end

-- The runner's own wall time, added up over its invocations (the report's "Run time").
local ELAPSED = DIR .. "/.study/elapsed.json"
local function read_elapsed()
  if not exists(ELAPSED) then return nil end
  local ok, e = pcall(json.read, ELAPSED)
  return ok and type(e) == "table" and type(e.seconds) == "number" and e or nil
end

local function finish(rows)
  local failed = 0
  for _, row in ipairs(rows) do if row.status == "failed" then failed = failed + 1 end end
  if P.report then
    local ok, err = pcall(function()
      require("study_report").write{dir = DIR, rows = rows, log = log, elapsed = read_elapsed()}
    end)
    if not ok then log("report not complete: %s", tostring(err)) end
  end
  return failed
end

asperity.mkdir(DIR)

-- collect=true: tables and report from the folders ------------------------------------------------
if P.collect then
  local rows = gather(nil)
  write_tables(rows)
  local failed = finish(rows)
  log("collected %d runs from %s (%d failed): study.csv, study.json", #rows, DIR, failed)
  os.exit(math.min(failed, 100))
end

asperity.mkdir(DIR .. "/.study")
write_atomic(DIR .. "/.study/run.sh", RUN_SH)
-- The run names do not carry the settings every run shares, so a folder holds one study: a later
-- invocation with other settings would skip runs made differently and mix them in one table. A
-- setting not given follows the folder, so the command that started a study resumes it, even
-- where a default changed since.
do
  local settings = {size = P.size, joint = table.concat(extra, " "), normal_stiffness = P.normal_stiffness,
                    events_every = P.events_every, speedup = P.speedup}
  -- what a folder written before a setting existed was made with
  local made_without = {speedup = 1}
  local path = DIR .. "/.study/settings.json"
  if exists(path) then
    local before = json.read(path)
    for _, k in ipairs{"size", "joint", "normal_stiffness", "events_every", "speedup"} do
      local was = before[k]
      if was == nil then was = made_without[k] end
      if was ~= settings[k] and params[k] == nil then
        log("%s=%s, as the study in %s was made (not given here)", k, tostring(was), DIR)
        P[k] = was
        if k == "joint" then extra = words(was) end
      elseif was ~= settings[k] then
        fail("%s holds a study made with %s=%s, not %s: give another out= (or the same %s)", DIR, k,
             tostring(was), tostring(settings[k]), k)
      end
    end
  else
    write_atomic(path, asperity.json(settings))
  end
end

-- slurm=FILE: a job array instead of running ----------------------------------------------------
-- Two arrays: the packers (one run per surface and seed, which packs and caches the specimen),
-- then every other run, started once the packers have ended (afterany: a packer that failed
-- leaves its specimen to the first run that needs it).
if P.slurm ~= "" then
  local packers, others, have = {}, {}, {}
  for _, run in ipairs(runs) do
    if not have[run.group] then
      -- The cheapest run of the group packs: rigid if the study has it.
      local best = run
      for _, r in ipairs(runs) do
        if r.group == run.group and r.model == "rigid" then best = r; break end
      end
      have[run.group] = best
      packers[#packers + 1] = best
    end
  end
  for _, run in ipairs(runs) do
    if have[run.group] ~= run then others[#others + 1] = run end
  end
  local function cases(list)
    local t = {}
    for k, run in ipairs(list) do
      t[#t + 1] = ("    %d) name=%s; cmd=%s ;;"):format(k - 1, run.name, shell_quote(command(run)))
    end
    return table.concat(t, "\n")
  end
  local text = ([=[#!/bin/bash
# A Slurm job array for a study of asperity (written by scripts/study.lua; see scripts/README.md).
#
#   bash %s              submits: the packing array, then the run array after it
#   study %s: %d packing runs (one per surface and seed), then %d; %d threads per run
#
# Every task runs one joint.lua command through %s/.study/run.sh, the wrapper the runner uses:
# finished runs are skipped, a run killed part-way resumes from its saved state when its task runs
# again, a failed run is kept in NAME.failed (and run again only if the script was written with
# retry=true). A task near its time limit gets SIGTERM (--signal), passes it to its run, which
# saves its state, and is requeued (--requeue) to resume. Resubmit the same file to resume what
# is left; gather the results on any machine with:
#   asperity run scripts/study.lua collect=true out=%s
#SBATCH --job-name=asperity-study
#SBATCH --ntasks=1
#SBATCH --cpus-per-task=%d
#SBATCH --output=%s/.study/slurm-%%A_%%a.out
#SBATCH --signal=B:TERM@180
#SBATCH --requeue
set -u
study=%s
if [ -z "${SLURM_ARRAY_TASK_ID:-}" ]; then
  pack=$(sbatch --parsable --array=0-%d "$0" pack) || exit 1
  runs=%s
  echo "packing: job $pack"
  if [ "$runs" -gt 0 ]; then
    sbatch --parsable --array=0-$((runs - 1)) --dependency=afterany:"$pack" "$0" run || exit 1
  fi
  exit 0
fi
task=$SLURM_ARRAY_TASK_ID
case "${1:-}" in
pack)
  case "$task" in
%s
    *) echo "no packing task $task" >&2; exit 2 ;;
  esac ;;
run)
  case "$task" in
%s
    *) echo "no run task $task" >&2; exit 2 ;;
  esac ;;
*) echo "usage: bash $0 (submits), or as an array task with the argument pack or run" >&2; exit 2 ;;
esac
sh "$study/.study/run.sh" "$name" 0 %d "$cmd" &
child=$!
trap 'kill -TERM "$child" 2>/dev/null' TERM
wait "$child"
status=$?
while kill -0 "$child" 2>/dev/null; do
  wait "$child"
  status=$?
done
# Stopped by the time limit's SIGTERM with its state saved: back in the queue, to resume.
if [ "$status" -gt 128 ] && [ -n "${SLURM_ARRAY_JOB_ID:-}" ]; then
  scontrol requeue "${SLURM_ARRAY_JOB_ID}_${SLURM_ARRAY_TASK_ID}"
fi
exit "$status"
]=]):format(P.slurm, DIR, #packers, #others, threads, DIR, DIR, threads, DIR, shell_quote(DIR),
             #packers - 1, #others, cases(packers), cases(others), P.retry and 1 or 0)
  write_atomic(P.slurm, text)
  log("wrote %s: %d runs (%d packing, then %d), %d threads each; submit with: bash %s",
      P.slurm, #runs, #packers, #others, threads, P.slurm)
  return
end

-- The runner -------------------------------------------------------------------------------------
local my_pid = tonumber(capture("echo $PPID"))
local t0 = asperity.wall_time()
local clock = require("study_report").duration
local function sleep(seconds)
  -- Through popen, not os.execute: system() ignores SIGINT in the caller, so a Ctrl-C during the
  -- wait would not reach this script.
  local p = io.popen(("sleep %.3f"):format(seconds))
  p:read("a")
  p:close()
end

local pending, ready, todo = {}, {}, 0
local finished_before, failed_before = 0, 0
for _, run in ipairs(runs) do
  local state = state_of(run.name)
  if state == "finished" then
    ready[run.group] = true
    finished_before = finished_before + 1
  elseif state == "failed" and not P.retry then
    failed_before = failed_before + 1
  else
    pending[#pending + 1] = run
    run.restart = state == "interrupted"
  end
end
todo = #pending
log("%d runs in %s: %d finished before, %d failed before%s, %d to run; %d jobs x %d threads (%d cores)",
    #runs, DIR, finished_before, failed_before, failed_before > 0 and " (skipped; retry=true runs them again)" or "",
    todo, jobs, threads, cores)
write_tables(gather(runs))

-- This invocation's time joins the earlier ones' whenever a run ends and when the runner stops.
local elapsed_before = read_elapsed() or {seconds = 0, invocations = 0}
local function record_elapsed()
  if todo == 0 then return end
  write_atomic(ELAPSED, asperity.json{seconds = elapsed_before.seconds + (asperity.wall_time() - t0),
                                      invocations = elapsed_before.invocations + 1, jobs = jobs, threads = threads})
end

-- Wall time per model, for the estimates (packing runs separately: they include the packing),
-- from the start with the runs finished before (their summaries' wall time, every attempt).
local times = {}
for _, run in ipairs(runs) do
  if state_of(run.name) == "finished" then
    local ok, s = pcall(json.read, DIR .. "/" .. run.name .. "/summary.json")
    if ok and type(s) == "table" and type(s.wall_seconds) == "number" then
      local key = run.model .. (s.specimen_packed == true and "+pack" or "")
      times[key] = times[key] or {}
      table.insert(times[key], s.wall_seconds)
    end
  end
end
local function estimate(run, packs)
  local function mean(key)
    local t = times[key]
    if not t or #t == 0 then return nil end
    local s = 0
    for _, v in ipairs(t) do s = s + v end
    return s / #t
  end
  -- A model's own times only: a rigid run takes seconds where an elastic one takes minutes, so
  -- another model's time would be no estimate at all.
  if packs then return mean(run.model .. "+pack") or mean(run.model) end
  return mean(run.model) or mean(run.model .. "+pack")
end

local running, done, failed_now = {}, 0, 0
local last_heartbeat = asperity.wall_time()
local function started_count() local n = 0 for _ in pairs(running) do n = n + 1 end return n end
local function overall_left()
  local total, known, unknown = 0, true, {}
  -- One packer for each group not packed yet (unless one is running), the others after it.
  local packing = {}
  for _, job in pairs(running) do if job.packs then packing[job.run.group] = true end end
  for _, run in ipairs(pending) do
    local packs = not ready[run.group] and not packing[run.group]
    if packs then packing[run.group] = true end
    local e = estimate(run, packs)
    if e then total = total + e else known, unknown[run.model] = false, true end
  end
  local now = asperity.wall_time()
  for _, job in pairs(running) do
    local e = estimate(job.run, job.packs)
    if e then total = total + math.max(0, e - (now - job.t)) else known, unknown[job.run.model] = false, true end
  end
  if not known then
    local names = {}
    for m in pairs(unknown) do names[#names + 1] = m end
    table.sort(names)
    local why = ("no %s run finished yet"):format(table.concat(names, " or "))
    if total <= 0 then return ("time left not known yet (%s)"):format(why) end
    return ("at least %s left (%s)"):format(clock(total / jobs), why)
  end
  return "about " .. clock(total / jobs) .. " left"
end

-- How many runs could start now besides `run`: those whose specimen is ready, and one packer per
-- group neither ready nor busy.
local function startable_besides(run)
  local busy = {[run.group] = true}
  for _, job in pairs(running) do busy[job.run.group] = true end
  local n = 0
  for _, r in ipairs(pending) do
    if ready[r.group] then
      n = n + 1
    elseif not busy[r.group] then
      busy[r.group], n = true, n + 1
    end
  end
  return n
end

local function start(run, packs)
  -- A packer whose packing leaves job slots idle (every other run waits for its specimen) packs
  -- on those slots' cores too; its shear runs on `threads` (results do not depend on the count).
  if packs then
    local idle = jobs - started_count() - 1 - startable_besides(run)
    local more = math.min(math.max(cores, threads), threads * (1 + math.max(0, idle)))
    if more > threads then run.genesis_threads = more end
  end
  local line = ("sh %s %s %d %d %s >/dev/null 2>&1 & echo $!"):format(shell_quote(DIR .. "/.study/run.sh"),
    shell_quote(run.name), my_pid, P.retry and 1 or 0, shell_quote(command(run)))
  local pid = tonumber(capture(line))
  if not pid then fail("could not start the run %s", run.name) end
  running[run.name] = {run = run, pid = pid, t = asperity.wall_time(), packs = packs}
  local e = estimate(run, packs)
  log("started %s%s%s (%d of %d); %s", run.name,
      packs and (run.genesis_threads and (" (packs the specimen on %d threads)"):format(run.genesis_threads)
                 or " (packs the specimen)") or "",
      run.restart and " (again: it was interrupted)" or "", done + started_count(), todo,
      e and ("expected to end at %s (in about %s)"):format(os.date("%H:%M", os.time() + math.floor(e + 0.5)), clock(e))
        or "no estimate yet")
end

-- A wrapper is alive while /proc/PID is its run.sh (the pid of an ended one may be reused).
local function alive(job)
  local cmdline = read_text("/proc/" .. job.pid .. "/cmdline")
  return cmdline ~= nil and cmdline:find(job.run.name, 1, true) ~= nil and cmdline:find("run.sh", 1, true) ~= nil
end

local function next_run()
  -- A run whose specimen is cached (its group has a finished run) goes first in list order; a
  -- group with no finished run and nothing running gets one packer (rigid if pending: the cheapest).
  local busy = {}
  for _, job in pairs(running) do busy[job.run.group] = true end
  for k, run in ipairs(pending) do
    if ready[run.group] then return table.remove(pending, k), false end
  end
  for k, run in ipairs(pending) do
    if not busy[run.group] then
      for j = k, #pending do
        if pending[j].group == run.group and pending[j].model == "rigid" then return table.remove(pending, j), true end
      end
      return table.remove(pending, k), true
    end
  end
  return nil
end

local function run_all()
  while #pending > 0 or next(running) do
    while started_count() < jobs do
      local run, packs = next_run()
      if not run then break end
      start(run, packs)
    end
    sleep(P.poll)
    -- Between starts and ends of long runs: where the study stands, every `heartbeat` seconds.
    if P.heartbeat > 0 and asperity.wall_time() - last_heartbeat >= P.heartbeat then
      last_heartbeat = asperity.wall_time()
      local now, names = asperity.wall_time(), {}
      for name, job in pairs(running) do names[#names + 1] = ("%s %s"):format(name, clock(now - job.t)) end
      table.sort(names)
      log("%d of %d ended, running: %s; %s", done, todo, table.concat(names, ", "), overall_left())
    end
    -- A packer's specimen is cached once joint.lua analyses its DEM surfaces: the other runs of
    -- its group may start then instead of waiting for its shear (if that line ever changes, they
    -- wait for the packer to end, as they would anyway).
    for name, job in pairs(running) do
      if job.packs and not ready[job.run.group] then
        local text = read_text(DIR .. "/" .. name .. ".part/log.txt")
        if text and text:find("[joint] DEM surface:", 1, true) then
          ready[job.run.group] = true
          log("specimen of %s ready (packed by %s)", job.run.group, name)
        end
      end
    end
    local ended = {}
    for name, job in pairs(running) do
      if not alive(job) then ended[#ended + 1] = name end
    end
    table.sort(ended)
    for _, name in ipairs(ended) do
      local job = running[name]
      running[name] = nil
      local seconds = asperity.wall_time() - job.t
      local state = state_of(name)
      done = done + 1
      if state == "finished" then
        ready[job.run.group] = true
        local key = job.run.model .. (job.packs and "+pack" or "")
        times[key] = times[key] or {}
        table.insert(times[key], seconds)
        local ok, s = pcall(json.read, DIR .. "/" .. name .. "/summary.json")
        local what = ok and type(s.peak_shear_stress_mpa) == "number" and type(s.residual_shear_stress_mpa) == "number"
                     and (": peak %.2f MPa, residual %.2f MPa"):format(s.peak_shear_stress_mpa, s.residual_shear_stress_mpa) or ""
        log("finished %s in %s%s (%d of %d); %s", name, clock(seconds), what, done, todo, overall_left())
      elseif state == "failed" then
        failed_now = failed_now + 1
        log("FAILED %s after %s: %s (%d of %d); %s", name, clock(seconds),
            failure_message(DIR .. "/" .. name .. ".failed"), done, todo, overall_left())
      else
        failed_now = failed_now + 1
        log("INTERRUPTED %s after %s (stopped by a signal; the next run of the study resumes it)",
            name, clock(seconds))
      end
      record_elapsed()
      write_tables(gather(runs))
    end
  end
end
-- Ctrl-C: the runs stop with the runner (their wrappers see it go) and stay NAME.part.
local ok, err = pcall(run_all)
if not ok then
  if asperity.is_interrupted(err) then
    local names = {}
    for name in pairs(running) do names[#names + 1] = name end
    table.sort(names)
    log("interrupted: %s left part-way (resumed by the same command)",
        #names > 0 and table.concat(names, ", ") or "no run")
    record_elapsed()
    write_tables(gather(runs))
    os.exit(130)
  end
  error(err, 0)
end

record_elapsed()
local rows = gather(runs)
write_tables(rows)
finish(rows)
-- The exit status counts the requested runs that are not finished: failed now or before, or
-- interrupted.
local requested = {}
for _, run in ipairs(runs) do requested[run.name] = true end
local finished, failed = 0, 0
for _, row in ipairs(rows) do
  if requested[row.name] then
    if row.status == "finished" then finished = finished + 1 else failed = failed + 1 end
  end
end
log("done in %s: %d of %d runs finished, %d not (%d failed or interrupted this time); %s/study.csv, study.json",
    clock(asperity.wall_time() - t0), finished, #runs, failed, failed_now, DIR)
os.exit(math.min(failed, 100))
