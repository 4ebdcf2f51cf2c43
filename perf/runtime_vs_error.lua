-- Run time against error (issue 7): the joint test (scripts/joint.lua) under varied numerical
-- settings, each compared with a reference run at a 4x slower loading rate, a smaller time step
-- and finer records. For each setting: wall time, and the relative error of the peak and residual
-- shear stress and of the maximum dilatancy; settings whose largest error is within `tolerance`
-- are "accepted", and the fastest accepted one is what the joint's defaults should be.
--
--   build/asperity run perf/runtime_vs_error.lua                                  -- the default joint
--   build/asperity run perf/runtime_vs_error.lua size=0.012 thickness=0.004 shear=2 out=out/rve_small
--   build/asperity run perf/runtime_vs_error.lua only=reference,default,velocity_x2
--
-- Writes into `out`: runtime_vs_error.csv (one row per setting, in the order below),
-- runtime_vs_error.json (the same with names and messages), pareto.png (error against wall time)
-- and one directory per run (the joint's own outputs). A setting the engine refuses (a health
-- check: time step too large, loading too fast) is recorded as refused with its message: that is
-- the answer wanted from the stress settings, not a failure of the study.
--
-- Uniform density scaling is not a separate axis: multiplying every mass by f is the same motion
-- at velocity x sqrt(f) (t' = t / sqrt f turns m f a = F into m a' = F; local damping and friction
-- do not depend on rate), so the velocity rows cover it.
local P = require("params").defaults{
  surface = "S1",
  model = "elastic",
  size = 0.02,
  thickness = 0.006,
  shear = 5,
  stress = 14,
  velocity = 1.5e-5,   -- the joint's default shear velocity, m/s
  record = 0.01,       -- the joint's default record interval, mm
  tolerance = 0.01,    -- accepted error
  only = "",           -- comma-separated setting names (default: all)
  out = "out/runtime_vs_error",
  cache = "out/cache",
  threads = 0,
}
asperity.mkdir(P.out)
local v, rec = P.velocity, P.record

-- name, what it changes, joint parameters. The reference comes first: every error is against it.
local settings = {
  {"reference", "velocity / 4, dt 0.5 x estimate, records / 4", {velocity = v / 4, dt_safety = 0.5, record = rec / 4}},
  {"default", "the joint's defaults", {}},
  {"velocity_x0.5", "velocity / 2", {velocity = v / 2}},
  {"velocity_x2", "velocity x 2", {velocity = 2 * v}},
  {"velocity_x4", "velocity x 4", {velocity = 4 * v}},
  {"dt_0.5", "dt 0.5 x estimate", {dt_safety = 0.5}},
  {"dt_0.8", "dt 0.8 x estimate (the engine's default)", {dt_safety = 0.8}},
  {"skin_0.5", "skin 5e-5 m (about 0.2 R)", {skin = 5e-5}},
  {"skin_2", "skin 2e-4 m (about 0.8 R)", {skin = 2e-4}},
  {"record_x0.5", "records every 0.005 mm", {record = rec / 2}},
  {"record_x5", "records every 0.05 mm", {record = 5 * rec}},
  -- Stress settings: where results degrade, and whether the engine says so.
  {"stress_velocity_x10", "velocity x 10", {velocity = 10 * v}},
  {"stress_dt_1.3", "dt 1.3 x estimate", {dt_safety = 1.3}},
}
local wanted = {}
for name in P.only:gmatch("[^,]+") do wanted[name] = true end
if next(wanted) and not wanted.reference then wanted.reference = true end

local function run(name, overrides)
  local given = {surface = P.surface, model = P.model, size = P.size, thickness = P.thickness,
                 shear = P.shear, stress = P.stress, velocity = P.velocity, record = P.record,
                 out = P.out .. "/" .. name, cache = P.cache, threads = P.threads, progress = false}
  for k, x in pairs(overrides) do given[k] = x end
  params = given
  local t0 = asperity.wall_time()
  local ok, result = pcall(dofile, asperity.scripts_dir .. "/joint.lua")
  return ok, result, asperity.wall_time() - t0
end

local rows, ref = {}, nil
local csv = asperity.series{"setting [1]", "wall_seconds [s]", "steps [1]", "peak_mpa [MPa]",
  "residual_mpa [MPa]", "dilatancy_mm [mm]", "error_peak [1]", "error_residual [1]",
  "error_dilatancy [1]", "error_max [1]", "accepted [1]"}
local function rel(a, b) return math.abs(a / b - 1) end
for index, s in ipairs(settings) do
  local name, what, overrides = s[1], s[2], s[3]
  if next(wanted) == nil or wanted[name] then
    io.stderr:write(("[runtime_vs_error] %s: %s\n"):format(name, what))
    local ok, r, seconds = run(name, overrides)
    local row = {name = name, what = what, wall_seconds = seconds}
    if not ok then
      row.refused = tostring(r)
      io.stderr:write(("[runtime_vs_error] %s refused: %s\n"):format(name, row.refused:match("[^\n]*")))
    else
      row.steps, row.peak, row.residual, row.dilatancy = r.steps, r.peak_shear_stress_mpa,
        r.residual_shear_stress_mpa, r.max_dilatancy_mm
      row.normal_stress_deviation_p95 = r.normal_stress_deviation_p95
      row.energy_balance_error = r.energy_balance_error
      if name == "reference" then ref = row end
      if ref then
        row.error_peak, row.error_residual = rel(row.peak, ref.peak), rel(row.residual, ref.residual)
        row.error_dilatancy = rel(row.dilatancy, ref.dilatancy)
        row.error_max = math.max(row.error_peak, row.error_residual, row.error_dilatancy)
        row.accepted = row.error_max <= P.tolerance
        csv:record(index, seconds, row.steps, row.peak, row.residual, row.dilatancy, row.error_peak,
                   row.error_residual, row.error_dilatancy, row.error_max, row.accepted and 1 or 0)
      end
    end
    if name == "reference" and not ref then error("the reference run failed: " .. tostring(row.refused)) end
    rows[#rows + 1] = row
  end
end

csv:write(P.out .. "/runtime_vs_error")
local fastest
for _, row in ipairs(rows) do
  if row.accepted and row.name ~= "reference" and (not fastest or row.wall_seconds < fastest.wall_seconds) then
    fastest = row
  end
end
asperity.write_json(P.out .. "/runtime_vs_error.json", {parameters = P, rows = rows,
  fastest_accepted = fastest and fastest.name or nil})
pcall(function()
  csv:plot{file = P.out .. "/pareto.png", x = "wall_seconds", y = {"error_max"}, points = true, logy = true,
           title = ("run time against error, %s %s joint (largest of the peak, residual, dilatancy errors)"):format(
             P.surface, P.model)}
end)

print(("%-22s %9s %9s %9s %9s %9s %9s  %s"):format("setting", "wall s", "peak", "residual", "dilat.",
  "err max", "accepted", "what"))
for _, row in ipairs(rows) do
  if row.refused then
    print(("%-22s %9.1f %s"):format(row.name, row.wall_seconds, "refused: " .. row.refused:match("[^\n]*")))
  else
    print(("%-22s %9.1f %9.3f %9.3f %9.3f %9.4f %9s  %s"):format(row.name, row.wall_seconds, row.peak,
      row.residual, row.dilatancy, row.error_max or 0, tostring(row.accepted), row.what))
  end
end
print("fastest within " .. P.tolerance .. ": " .. (fastest and fastest.name or "none"))
