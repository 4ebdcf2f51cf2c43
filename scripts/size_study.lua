-- The size study (scenarios.md 3): the same joint at several sizes, to find the smallest that is
-- representative, i.e. whose peak and residual shear stress lie within `tolerance` of the largest
-- size's, for every model asked.
--
--   build/asperity run scripts/size_study.lua                              -- S1, 2/3/5/10 cm, rigid + elastic
--   build/asperity run scripts/size_study.lua sizes=0.02,0.05 seeds=1,2,3 jobs=2 threads=1 out=out/size
--   build/asperity run scripts/size_study.lua collect=true out=out/size    -- table and plot again
--
-- Each size is one study (scripts/study.lua, one folder DIR/size_<cm>cm, with its resume rules);
-- the packed specimens go to one cache (DIR/cache unless cache= says), shared by the sizes and by
-- later studies. Writes DIR/size_study.csv (one row per size and model: mean and scatter over the
-- seeds, the difference from the largest size), DIR/size_study.json (the same, and the verdict),
-- DIR/size_study.png (peak and residual against size, with the reference study's 10 cm values).
-- Exit status: the number of runs not finished (at most 100).
local json = require("json")
local params_lib = require("params")
local figures = require("figures")
local reference = require("reference")

local P = params_lib.parse{
  script = "size_study.lua",
  path = "scripts/size_study.lua",
  about = "one joint at several sizes: the smallest representative size (scenarios.md 3)",
  {"sizes", "0.02,0.03,0.05,0.1", list = "number", unit = "m", above = 0, doc = "joint sides, the largest the reference"},
  {"models", "rigid,elastic", list = "string", oneof = {"rigid", "elastic", "fracture"}, doc = "particle models"},
  {"surface", "S1", oneof = {"S1", "S2", "S3", "S4", "S5", "S6", "S7", "S8"}, doc = "the surface"},
  {"stress", 14, unit = "MPa", above = 0, doc = "normal stress, scaled to rock"},
  {"direction", "x", oneof = {"x", "y"}, doc = "shear direction"},
  {"seeds", "1", list = "number", min = 1, doc = "surface realisations (whole numbers)"},
  {"tolerance", 0.1, above = 0, doc = "representative: peak and residual within this fraction of the largest size's"},
  {"joint", "", doc = "more key=value parameters for every joint.lua run, space-separated"},
  {"out", "out/size_study", nonempty = true, doc = "the study's folder"},
  {"cache", "", doc = "the folder of the packed specimens (\"\": out/cache)"},
  {"jobs", 0, type = "integer", min = 0, doc = "runs at once (0: the machine's cores / threads)"},
  {"threads", 0, type = "integer", min = 0, doc = "threads of each run (0: the cores / jobs)"},
  {"collect", false, doc = "true: only rebuild the table and the plot from out's folders"},
  {"asperity", "", file = true, doc = "the program each run uses (\"\": the one running this script)"},
  check = function(P, fail)
    local sizes = params_lib.split(P.sizes, true)
    if #sizes < 2 then fail("sizes", "needs at least two sizes: the largest is the reference of the others") end
    local seen = {}
    for _, s in ipairs(sizes) do
      if seen[s] then fail("sizes", ("%g is listed twice"):format(s)) end
      seen[s] = true
    end
    for _, s in ipairs(params_lib.split(P.seeds, true)) do
      if math.tointeger(s) == nil then fail("seeds", ("'%s' is not a whole number"):format(tostring(s))) end
    end
  end,
}
if not P then return end   -- help printed

local function log(fmt, ...) io.stderr:write(("[size_study] " .. fmt .. "\n"):format(...)) end

local sizes = params_lib.split(P.sizes, true)
table.sort(sizes)
local largest = sizes[#sizes]
local models = params_lib.split(P.models)

local sh = require("shell")
local DIR = sh.absolute(P.out):gsub("/+$", "")
local CACHE = P.cache ~= "" and sh.absolute(P.cache) or DIR .. "/cache"
local exe = P.asperity ~= "" and sh.absolute(P.asperity) or sh.program()
local study_script = sh.absolute(asperity.scripts_dir) .. "/study.lua"
local function folder(size) return ("%s/size_%gcm"):format(DIR, size * 100) end

asperity.mkdir(DIR)
local unfinished = 0
for _, size in ipairs(sizes) do
  local args = {exe, "run", study_script, "surfaces=" .. P.surface, "stresses=" .. params_lib.exact(P.stress),
                "directions=" .. P.direction, "models=" .. P.models, "seeds=" .. P.seeds,
                "size=" .. params_lib.exact(size), "out=" .. folder(size), "cache=" .. CACHE,
                "events_every=0", "report=false", "jobs=" .. P.jobs, "threads=" .. P.threads}
  if P.joint ~= "" then args[#args + 1] = "joint=" .. P.joint end
  if P.collect then args[#args + 1] = "collect=true" end
  for k, a in ipairs(args) do args[k] = sh.quote(a) end
  log("%g cm: %s", size * 100, P.collect and "collecting" or "running (finished runs are kept)")
  local ok, _, status = os.execute(table.concat(args, " "))
  if not ok then unfinished = unfinished + (status or 1) end
end

-- The table: per size and model, mean and sample standard deviation over the seeds.
local mean_sd = require("events").mean_sd
local function stats(v)
  local m, sd = mean_sd(v)
  return m, sd, #v
end
local cells = {}   -- cells[model][size] = {peak = {...}, residual = {...}, k0 = {...}, particles, seconds}
for _, m in ipairs(models) do cells[m] = {} end
for _, size in ipairs(sizes) do
  local ok, study = pcall(json.read, folder(size) .. "/study.json")
  for _, row in ipairs(ok and study.runs or {}) do
    local c = cells[row.model]
    if c and row.status == "finished" then
      c[size] = c[size] or {peak = {}, residual = {}, k0 = {}, particles = {}, seconds = {}}
      local t = c[size]
      t.peak[#t.peak + 1] = row.peak_shear_stress_mpa
      t.residual[#t.residual + 1] = row.residual_shear_stress_mpa
      t.k0[#t.k0 + 1] = row.initial_shear_stiffness_mpa_per_mm
      t.particles[#t.particles + 1] = row.n_particles
      t.seconds[#t.seconds + 1] = row.wall_seconds
    end
  end
end

local rows, verdict = {}, {}
for _, m in ipairs(models) do
  local ref = cells[m][largest]
  local ref_peak = ref and stats(ref.peak) or 0 / 0
  local ref_res = ref and stats(ref.residual) or 0 / 0
  local smallest
  for _, size in ipairs(sizes) do
    local t = cells[m][size]
    if t then
      local pk, pk_sd, n = stats(t.peak)
      local rs, rs_sd = stats(t.residual)
      local k0 = stats(t.k0)
      local row = {model = m, size_m = size, runs = n, peak_mpa = pk, peak_sd_mpa = pk_sd,
                   residual_mpa = rs, residual_sd_mpa = rs_sd, k0_mpa_per_mm = k0,
                   particles = stats(t.particles), wall_seconds = stats(t.seconds),
                   peak_vs_largest = pk / ref_peak - 1, residual_vs_largest = rs / ref_res - 1}
      row.representative = math.abs(row.peak_vs_largest) <= P.tolerance and math.abs(row.residual_vs_largest) <= P.tolerance
      rows[#rows + 1] = row
      if row.representative and not smallest then smallest = size end
      -- a size is only representative if every larger one is too (no lucky match below a bad one)
      if not row.representative then smallest = nil end
    end
  end
  verdict[m] = smallest
end
local default_size
for _, m in ipairs(models) do
  if not verdict[m] then default_size = nil break end
  default_size = math.max(default_size or 0, verdict[m])
end

local cols = {"model", "size_m", "runs", "peak_mpa", "peak_sd_mpa", "residual_mpa", "residual_sd_mpa",
              "k0_mpa_per_mm", "peak_vs_largest", "residual_vs_largest", "representative", "particles", "wall_seconds"}
local lines = {table.concat(cols, ",")}
for _, r in ipairs(rows) do
  local f = {}
  for k, c in ipairs(cols) do
    local v = r[c]
    f[k] = type(v) == "number" and (v ~= v and "nan" or ("%.6g"):format(v)) or tostring(v)
  end
  lines[#lines + 1] = table.concat(f, ",")
end
sh.write_atomic(DIR .. "/size_study.csv", table.concat(lines, "\n") .. "\n")
sh.write_atomic(DIR .. "/size_study.json", asperity.json{rows = rows, tolerance = P.tolerance, reference_size_m = largest,
                                               smallest_representative_m = verdict,
                                               default_size_m = default_size or false})

-- The plot: peak (solid) and residual (dashed) against size per model, the thesis's 10 cm values
-- as points.
local colors = {rigid = "#2060c0", elastic = "#d02020", fracture = "#208020"}
local series = {}
for _, m in ipairs(models) do
  for _, what in ipairs{"peak", "residual"} do
    local xs, ys = {}, {}
    for _, r in ipairs(rows) do
      if r.model == m then xs[#xs + 1], ys[#ys + 1] = r.size_m * 100, r[what .. "_mpa"] end
    end
    if #xs > 0 then
      series[#series + 1] = {title = ("%s %s"):format(m, what), x = xs, y = ys, style = "linespoints",
                             color = colors[m], dash = what == "residual" and 2 or nil, point = 7}
    end
    local ref = reference.joint(P.surface, m, P.stress)
    if ref then
      series[#series + 1] = {title = ("thesis 10 cm %s %s"):format(m, what), x = {10}, y = {ref[what]},
                             style = "points", color = colors[m], point = what == "peak" and 5 or 4}
    end
  end
end
if #series > 0 then
  local ok, err = pcall(figures.curves, {file = DIR .. "/size_study.png", xlabel = "joint side [cm]",
                                         ylabel = "shear stress [MPa]", series = series,
                                         xrange = ("%g:%g"):format(sizes[1] * 100 * 0.8, math.max(largest, 0.1) * 100 * 1.05),
                                         title = ("%s, %g MPa, -%s"):format(P.surface, P.stress, P.direction)})
  if not ok then log("no plot: %s", tostring(err)) end
end

for _, m in ipairs(models) do
  if not cells[m][largest] then
    log("%s: no finished run at the largest size (%g cm): no verdict", m, largest * 100)
  else
    log("%s: smallest representative size %s", m, verdict[m] and ("%g cm"):format(verdict[m] * 100) or "none")
  end
end
log("table: %s/size_study.csv; plot: %s/size_study.png", DIR, DIR)
os.exit(math.min(unfinished, 100))
