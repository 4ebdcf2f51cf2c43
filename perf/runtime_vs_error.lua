-- Run time against error (issue 7): the joint test (scripts/joint.lua) or the REV tests
-- (scripts/rev.lua, scene=rev) under varied numerical settings, each compared with a reference
-- run at a 4x slower loading rate, a smaller time step and finer records. For each setting: wall
-- time, and the relative error of each measure (joint: peak and residual shear stress, maximum
-- dilatancy; REV: Young's modulus, compressive and tensile strength); settings whose largest
-- error is within `tolerance` are "accepted", and the fastest accepted one is what the scene's
-- defaults should be.
--
--   build/asperity run perf/runtime_vs_error.lua                                  -- the default joint
--   build/asperity run perf/runtime_vs_error.lua size=0.012 thickness=0.004 shear=2 out=out/rve_small
--   build/asperity run perf/runtime_vs_error.lua only=reference,default,velocity_x2
--   build/asperity run perf/runtime_vs_error.lua size=0.05 reference=slower only=reference,default,speedup_1
--   build/asperity run perf/runtime_vs_error.lua scene=rev out=out/rve_rev        -- the REV (~15 min)
--
-- Writes into `out`: runtime_vs_error.csv (one row per setting, in the order below),
-- runtime_vs_error.json (the same with names and messages), pareto.png (error against wall time)
-- and one directory per run (the scene's own outputs). A setting the engine refuses (a health
-- check: time step too large, loading too fast) is recorded as refused with its message: that is
-- the answer wanted from the stress settings, not a failure of the study.
--
-- Uniform density scaling is not a separate axis: multiplying every mass by f is the same motion
-- at velocity x sqrt(f) (t' = t / sqrt f turns m f a = F into m a' = F; local damping and friction
-- do not depend on rate), so the velocity rows cover it.
local P = require("params").defaults{
  scene = "joint",     -- joint | rev
  surface = "S1",
  model = "elastic",
  size = 0.02,
  thickness = 0.006,
  shear = 5,
  stress = 14,
  velocity = 1.5e-5,   -- the joint's default shear velocity, m/s
  record = 0.01,       -- the joint's default record interval, mm
  rate = 1e-6,         -- the REV's default platen velocity, m/s
  every = 100,         -- the REV's default steps between records
  tolerance = 0.01,    -- accepted error
  reference = "strict", -- strict: velocity / 4, dt 0.5, records / 4; slower: velocity / 4 only (scenarios.md 6's "a run 4x slower")
  seed = 1,            -- the joint's packing seed
  genesis_mass_floor = require("materials").genesis.mass_floor,   -- the joint's packing (0: the packing of true masses)
  joint = "",          -- more key=value parameters for every run of the scene's script, space-separated (e.g. tensile_strength=0.0301)
  reuse = false,       -- true: a setting whose folder holds the summary.json of a finished run with its parameters is read, not run again
  only = "",           -- comma-separated setting names (default: all)
  out = "out/runtime_vs_error",
  cache = "out/cache",
  threads = 0,
}
if P.scene ~= "joint" and P.scene ~= "rev" then error("scene must be joint or rev, got '" .. P.scene .. "'") end
if P.reference ~= "strict" and P.reference ~= "slower" then
  error("reference must be strict (velocity / 4, dt 0.5, records / 4) or slower (velocity / 4 only), got '" .. P.reference .. "'")
end
local strict = P.reference == "strict"
asperity.mkdir(P.out)
local v, rec = P.velocity, P.record

-- Each scene: its script, the parameters every run gets, the settings (name, what it changes,
-- parameters; the reference first: every error is against it) and the measures compared.
local scenes = {
  joint = {
    script = "joint.lua",
    base = {surface = P.surface, model = P.model, size = P.size, thickness = P.thickness,
            shear = P.shear, stress = P.stress, velocity = P.velocity, record = P.record,
            seed = P.seed, genesis_mass_floor = P.genesis_mass_floor, cache = P.cache, threads = P.threads,
            progress = false},
    settings = {
      -- The reference: 4x slower at constant velocity with true masses, whatever the defaults.
      strict and {"reference", "velocity / 4, dt 0.5 x estimate, records / 4", {velocity = v / 4, dt_safety = 0.5, record = rec / 4,
                                                                                  speedup = 1, mass_floor = 0}}
             or {"reference", "velocity / 4", {velocity = v / 4, speedup = 1, mass_floor = 0}},
      {"default", "the joint's defaults (elastic: mass floor 0.75, speedup 4)", {}},
      {"velocity_x0.5", "velocity / 2", {velocity = v / 2}},
      {"velocity_x2", "velocity x 2", {velocity = 2 * v}},
      {"velocity_x4", "velocity x 4", {velocity = 4 * v}},
      {"speedup_1", "constant velocity (joint.lua speedup; the elastic default is 4)", {speedup = 1}},
      {"speedup_2", "after the peak up to 2 x velocity (joint.lua speedup)", {speedup = 2}},
      {"speedup_4", "after the peak up to 4 x velocity", {speedup = 4}},
      {"dt_0.5", "dt 0.5 x estimate", {dt_safety = 0.5}},
      {"dt_0.8", "dt 0.8 x estimate (the engine's default)", {dt_safety = 0.8}},
      {"mass_floor_0", "true masses (joint.lua mass_floor)", {mass_floor = 0}},
      {"mass_floor_0.75", "particles below 0.75 mean radius weigh as one of it", {mass_floor = 0.75}},
      {"mass_floor_1", "particles below the mean radius weigh as one of it", {mass_floor = 1}},
      {"skin_0.5", "skin 2.5e-5 m (0.05 mean radius; the default is 0.1)", {skin = 2.5e-5}},
      {"skin_4", "skin 2e-4 m (0.4 mean radius, the default before 2026-11-26)", {skin = 2e-4}},
      {"record_x0.5", "records every 0.005 mm", {record = rec / 2}},
      {"record_x5", "records every 0.05 mm", {record = 5 * rec}},
      -- Stress settings: where results degrade, and whether the engine says so.
      {"stress_velocity_x10", "velocity x 10", {velocity = 10 * v}},
      {"stress_dt_1.3", "dt 1.3 x estimate", {dt_safety = 1.3}},
      -- Contacts soft or stiff for the load. Scaling every stiffness by f is the motion at velocity
      -- v / sqrt(f) (as density scaling, above: the velocity rows); what changes the physics is the
      -- stiffness against the load, i.e. the normal stress at fixed stiffness. These rows are other
      -- tests ("other" = true): no error against the reference (it would be physics, not numerics);
      -- they are read for the overlaps and the warnings.
      {"stress_load_x2", "normal stress x 2 (contacts twice as soft for the load)", {stress = 2 * P.stress}, other = true},
      {"stress_load_x4", "normal stress x 4", {stress = 4 * P.stress}, other = true},
      {"stress_load_x8", "normal stress x 8", {stress = 8 * P.stress}, other = true},
    },
    measures = {{"peak_mpa [MPa]", "peak_shear_stress_mpa"}, {"residual_mpa [MPa]", "residual_shear_stress_mpa"},
                {"dilatancy_mm [mm]", "max_dilatancy_mm"}},
    -- What the run's own checks saw (summary.json): quasi-static, and overlaps small.
    health = {{"kinetic_ratio_max [1]", "kinetic_ratio_max"}, {"overlap_ratio_max [1]", "overlap_ratio_max"}},
    steps = function(r) return r.steps end,
    title = ("%s %s joint"):format(P.surface, P.model),
  },
  rev = {
    script = "rev.lua",
    base = {rate = P.rate, every = P.every, tests = "elastic,compression,tension", threads = 1},
    settings = {
      strict and {"reference", "rate / 4, dt 0.5 x estimate, records / 4", {rate = P.rate / 4, dt_safety = 0.5, every = math.floor(P.every / 4)}}
             or {"reference", "rate / 4", {rate = P.rate / 4}},
      {"default", "rev.lua's defaults", {}},
      {"rate_x0.5", "rate / 2", {rate = P.rate / 2}},
      {"rate_x2", "rate x 2", {rate = 2 * P.rate}},
      {"rate_x4", "rate x 4", {rate = 4 * P.rate}},
      {"dt_0.5", "dt 0.5 x estimate", {dt_safety = 0.5}},
      {"dt_1.0", "dt 1.0 x estimate", {dt_safety = 1.0}},
      {"record_x0.5", "records every 50 steps", {every = math.floor(P.every / 2)}},
      {"record_x5", "records every 500 steps", {every = 5 * P.every}},
      {"stress_rate_x10", "rate x 10", {rate = 10 * P.rate}},
      {"stress_dt_1.3", "dt 1.3 x estimate", {dt_safety = 1.3}},
    },
    measures = {{"young_modulus_pa [Pa]", "young_modulus_pa"}, {"compressive_strength_pa [Pa]", "compressive_strength_pa"},
                {"tensile_strength_pa [Pa]", "tensile_strength_pa"}},
    -- Steps of the tests (the packing and bonding are the same in every run).
    steps = function(r)
      local n = 0
      for _, t in pairs(r.elastic or {}) do n = n + (t.steps or 0) end
      for _, t in pairs(r.fracture or {}) do if type(t) == "table" then n = n + (t.steps or 0) end end
      return n
    end,
    title = "REV",
    health = {},
  },
}
local scene = scenes[P.scene]
for item in P.joint:gmatch("%S+") do
  local k, x = item:match("^([%w_]+)=(.*)$")
  if not k then error("joint: expected key=value items, got '" .. item .. "'") end
  scene.base[k] = tonumber(x) or (x == "true" and true) or (x == "false" and false) or x
end
local settings = scene.settings
local wanted = {}
for name in P.only:gmatch("[^,]+") do wanted[name] = true end
do
  local names, known = {}, {}
  for _, s in ipairs(settings) do names[#names + 1] = s[1]; known[s[1]] = true end
  for name in pairs(wanted) do
    if not known[name] then
      error(("only: no setting '%s' for scene %s; the settings: %s"):format(name, P.scene, table.concat(names, ", ")), 0)
    end
  end
end
if next(wanted) and not wanted.reference then wanted.reference = true end

local function run(name, overrides)
  local given = {out = P.out .. "/" .. name}
  for k, x in pairs(scene.base) do given[k] = x end
  for k, x in pairs(overrides) do given[k] = x end
  if P.reuse then
    local ok, done = pcall(require("json").read, given.out .. "/summary.json")
    local same = ok and type(done) == "table" and type(done.parameters) == "table"
    if same then
      for k, x in pairs(given) do
        if k ~= "progress" and k ~= "threads" and k ~= "cache" and done.parameters[k] ~= x then same = false end
      end
    end
    if same then
      io.stderr:write(("[runtime_vs_error] %s: reusing %s/summary.json\n"):format(name, given.out))
      return true, done, done.wall_seconds or 0 / 0
    end
  end
  params = given
  local t0 = asperity.wall_time()
  local ok, result = pcall(dofile, asperity.scripts_dir .. "/" .. scene.script)
  return ok, result, asperity.wall_time() - t0
end

local rows, ref = {}, nil
local columns = {"setting [1]", "wall_seconds [s]", "steps [1]"}
for _, m in ipairs(scene.measures) do columns[#columns + 1] = m[1] end
for _, m in ipairs(scene.measures) do columns[#columns + 1] = "error_" .. m[1]:match("^[%w_]+") .. " [1]" end
columns[#columns + 1] = "error_max [1]"
columns[#columns + 1] = "accepted [1]"
for _, m in ipairs(scene.health) do columns[#columns + 1] = m[1] end
local csv = asperity.series(columns)
local function rel(a, b) return math.abs(a / b - 1) end
for index, s in ipairs(settings) do
  local name, what, overrides = s[1], s[2], s[3]
  if next(wanted) == nil or wanted[name] then
    io.stderr:write(("[runtime_vs_error] %s: %s\n"):format(name, what))
    local ok, r, seconds = run(name, overrides)
    local row = {name = name, what = what, wall_seconds = seconds, values = {}, errors = {}}
    if not ok then
      row.refused = tostring(r)
      io.stderr:write(("[runtime_vs_error] %s refused: %s\n"):format(name, row.refused:match("[^\n]*")))
    else
      row.steps = scene.steps(r)
      for k, m in ipairs(scene.measures) do row.values[k] = r[m[2]] end
      row.normal_stress_deviation_p95 = r.normal_stress_deviation_p95
      row.energy_balance_error = r.energy_balance_error
      row.health = {}
      for k, m in ipairs(scene.health) do row.health[m[2]] = r[m[2]] end
      if name == "reference" then ref = row end
      if ref then
        local values, errors = {index, seconds, row.steps}, {}
        row.error_max = s.other and 0 / 0 or 0
        for k = 1, #scene.measures do
          row.errors[k] = s.other and 0 / 0 or rel(row.values[k], ref.values[k])
          if not s.other then row.error_max = math.max(row.error_max, row.errors[k]) end
          values[#values + 1] = row.values[k]
          errors[#errors + 1] = row.errors[k]
        end
        row.accepted = not s.other and row.error_max <= P.tolerance
        for _, e in ipairs(errors) do values[#values + 1] = e end
        values[#values + 1] = row.error_max
        values[#values + 1] = row.accepted and 1 or 0
        for _, m in ipairs(scene.health) do values[#values + 1] = r[m[2]] or 0 / 0 end
        csv:record(table.unpack(values))
      end
    end
    if name == "reference" and not ref then error("the reference run failed: " .. tostring(row.refused)) end
    rows[#rows + 1] = row
  end
end

csv:write(P.out .. "/runtime_vs_error")
-- The candidates for the defaults: not the reference, and not the stress rows, which probe where
-- results degrade (a time step above the stability estimate is never a default, however close).
local fastest
for _, row in ipairs(rows) do
  if row.accepted and row.name ~= "reference" and not row.name:match("^stress_")
     and (not fastest or row.wall_seconds < fastest.wall_seconds) then
    fastest = row
  end
end
asperity.write_json(P.out .. "/runtime_vs_error.json", {parameters = P, rows = rows,
  fastest_accepted = fastest and fastest.name or nil})
pcall(function()
  csv:plot{file = P.out .. "/pareto.png", x = "wall_seconds", y = {"error_max"}, points = true, logy = true,
           title = ("run time against error, %s (largest error of the measures)"):format(scene.title)}
end)

local head = ("%-22s %9s"):format("setting", "wall s")
for _, m in ipairs(scene.measures) do head = head .. (" %12s"):format(m[1]:match("^[%w_]+"):sub(1, 12)) end
head = head .. ("  %9s %9s"):format("err max", "accepted")
for _, m in ipairs(scene.health) do head = head .. (" %14s"):format(m[2]:sub(1, 14)) end
print(head .. "  what")
for _, row in ipairs(rows) do
  if row.refused then
    print(("%-22s %9.1f %s"):format(row.name, row.wall_seconds, "refused: " .. row.refused:match("[^\n]*")))
  else
    local line = ("%-22s %9.1f"):format(row.name, row.wall_seconds)
    for k = 1, #scene.measures do line = line .. (" %12.5g"):format(row.values[k]) end
    local err = row.error_max == row.error_max and ("%9.4f"):format(row.error_max) or ("%9s"):format("-")
    line = line .. ("  %s %9s"):format(err, tostring(row.accepted))
    for _, m in ipairs(scene.health) do line = line .. (" %14.3g"):format(row.health[m[2]] or 0 / 0) end
    print(line .. "  " .. row.what)
  end
end
print("fastest within " .. P.tolerance .. " (stress rows excluded): " .. (fastest and fastest.name or "none"))
