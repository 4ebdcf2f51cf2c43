-- The study's report (scripts/lib/study_report.lua) on made-up runs whose numbers follow, or break,
-- the expected behaviours of scenarios.md 7: the verdicts, the comparison counts, the untestable
-- cases, the mean and scatter over seeds, and the files written.
local report = require("study_report")
local json = require("json")
local out = assert(params.out, "give out=DIRECTORY")
os.execute("rm -rf '" .. out .. "'")
asperity.mkdir(out)

-- S5 (H 0.52) against S1 (H 0.75); rigid < fracture < elastic; 21 MPa above 14 MPa; seeds 1 and 2
-- differ by 10 % (seed 2 higher).
local H = {S1 = 0.75, S5 = 0.52}
local base = {rigid = 10, fracture = 12, elastic = 13}
local rows = {}
for _, seed in ipairs{1, 2} do
  for _, surface in ipairs{"S1", "S5"} do
    for _, stress in ipairs{14, 21} do
      for _, model in ipairs{"rigid", "elastic", "fracture"} do
        local peak = base[model] * (surface == "S5" and 1.5 or 1) * stress / 14 * (seed == 2 and 1.1 or 1)
        rows[#rows + 1] = {
          name = ("%s_%g_x_%s_s%d"):format(surface, stress, model, seed), status = "finished", surface = surface,
          H = H[surface], Lc_mm = 16, s2_mm2 = 0.547, stress_mpa = stress, size = 0.05, direction = "x", model = model, seed = seed,
          peak_shear_stress_mpa = peak, residual_shear_stress_mpa = 0.6 * stress * (seed == 2 and 1.1 or 1),
          initial_shear_stiffness_mpa_per_mm = 50 * stress / 14 + (model == "rigid" and 0 or 30),
          max_dilatancy_mm = ({rigid = 1.0, elastic = 0.9, fracture = 0.5})[model] * (surface == "S5" and 1.4 or 1) * 14 / stress,
          broken_bonds = model == "fracture" and (surface == "S5" and 300 or 100) or 0,
          -- the fracture runs meet scenarios.md 4's damage and closure criteria
          closure_mm = ({rigid = 0.02, elastic = 0.03, fracture = 0.035})[model],
          broken_bonds_in_closure = model == "fracture" and 5 or 0,
          broken_bonds_near_share = model == "fracture" and 0.9 or nil,
          broken_bond_fraction = model == "fracture" and 0.05 or nil,
          contact_decay_exponent = -0.5, energy_shares_friction = 0.8, energy_shares_damping = 0.1,
          -- the rigid run of each surface and seed packs its specimen (50 s of its time)
          wall_seconds = ({rigid = 60, elastic = 300, fracture = 900})[model], resumes = model == "fracture" and seed or 0,
          specimen_packed = model == "rigid", specimen_seconds = model == "rigid" and 50 or 0,
          peak_memory_bytes = ({rigid = 3e8, elastic = 2e8, fracture = 2.5e8})[model] * (surface == "S5" and 1.2 or 1),
        }
      end
    end
  end
end
rows[#rows + 1] = {name = "S1_14_y_rigid_s1", status = "failed", surface = "S1", stress_mpa = 14, direction = "y",
                   model = "rigid", seed = 1, message = "boom"}
-- Curves: a peak at 0.5 mm, then a fall with undulations for rigid and elastic, smooth for fracture;
-- contacts rise to 1 mm, then fall.
local curves = {}
for _, r in ipairs(rows) do
  if r.status == "finished" then
    local c = {displacement = {}, shear_stress_mpa = {}, dilatancy = {}, contacts = {}, broken_bonds = {}}
    for k = 0, 50 do
      local u = k * 0.1
      local tau = u <= 0.5 and r.peak_shear_stress_mpa * u / 0.5 or
                  r.residual_shear_stress_mpa + (r.peak_shear_stress_mpa - r.residual_shear_stress_mpa) * math.exp(-(u - 0.5))
      if r.model ~= "fracture" and u > 0.5 then tau = tau + 0.5 * math.sin(8 * u) end
      c.displacement[k + 1], c.shear_stress_mpa[k + 1] = u, tau
      c.dilatancy[k + 1] = r.max_dilatancy_mm * u / 5
      c.contacts[k + 1] = u <= 1 and 10 + 20 * u or 30 * u ^ -0.5
      c.broken_bonds[k + 1] = r.broken_bonds * u / 5
    end
    curves[r.name] = c
  end
end

local T = {}
for _, t in ipairs(report.trends(rows, curves)) do T[t.id] = t end
local function expect(id, verdict, comparisons)
  local t = assert(T[id], "no trend " .. id)
  assert(t.verdict == verdict, ("%s: %s, want %s"):format(id, t.verdict, verdict))
  if comparisons then
    assert(t.comparisons == comparisons, ("%s: %d comparisons, want %d"):format(id, t.comparisons, comparisons))
  end
end
-- 3 models x 2 stresses x 2 seeds of each S5/S1 pair.
expect("peak_grows_as_hurst_falls", "shown", 12)
expect("dilatancy_grows_as_hurst_falls", "shown", 12)
expect("peak_grows_with_variance", "untestable", 0)
expect("peak_falls_with_correlation_length", "untestable", 0)
expect("hurst_strongest", "untestable")
expect("directions_alike", "untestable", 0)
expect("stress_peak", "shown", 12)
expect("stress_residual", "shown", 12)
expect("stress_initial_shear_stiffness", "shown", 12)
expect("stress_dilatancy", "shown", 12)
expect("elastic_above_rigid_peak", "shown", 8)
expect("fracture_between", "shown", 16)
expect("dilatancy_by_model", "shown", 16)
expect("fracture_removes_undulations", "shown", 16)
expect("contacts_rise_then_decay", "shown", 24)
expect("breaks_grow_with_roughness", "shown", 4)
expect("friction_takes_most", "shown", 24)
-- Residual independent of the surface: here it is (CV 0 across surfaces), while the peak is not.
expect("residual_independent_of_surface", "shown", 12)
-- The change goes from the lower H (S5) to the higher (S1): S1 peaks a third below S5.
assert(math.abs(T.peak_grows_as_hurst_falls.mean_relative_change + 1 / 3) < 1e-12, "S1 peaks a third below S5")

-- One comparison turned round: most still agree.
local saved = rows[1].peak_shear_stress_mpa       -- S1 14 rigid seed 1
rows[1].peak_shear_stress_mpa = 100
T = {}
for _, t in ipairs(report.trends(rows, curves)) do T[t.id] = t end
expect("peak_grows_as_hurst_falls", "partly", 12)
assert(T.peak_grows_as_hurst_falls.agree == 11, "11 of 12 agree")
-- All turned round: not shown.
rows[1].peak_shear_stress_mpa = saved
for _, r in ipairs(rows) do
  if r.surface == "S1" and r.status == "finished" then r.peak_shear_stress_mpa = 10 * r.peak_shear_stress_mpa end
end
T = {}
for _, t in ipairs(report.trends(rows, curves)) do T[t.id] = t end
expect("peak_grows_as_hurst_falls", "not shown", 12)
for _, r in ipairs(rows) do
  if r.surface == "S1" and r.status == "finished" then r.peak_shear_stress_mpa = r.peak_shear_stress_mpa / 10 end
end

-- Surfaces that differ only in Lc and gave identical runs (a joint no larger than 2 Lc: the same
-- surface): untestable, with the reason; a pair of equal values agrees with neither direction.
local lc_rows, lc_curves = {}, {}
for _, surface in ipairs{"S1", "S3"} do
  for _, model in ipairs{"rigid", "elastic"} do
    local name = surface .. "_14_x_" .. model .. "_s1"
    lc_rows[#lc_rows + 1] = {name = name, status = "finished", surface = surface, H = 0.75, Lc_mm = surface == "S1" and 16 or 20,
                             s2_mm2 = 0.547, stress_mpa = 14, direction = "x", model = model, seed = 1,
                             peak_shear_stress_mpa = model == "rigid" and 30 or 32, residual_shear_stress_mpa = 5,
                             initial_shear_stiffness_mpa_per_mm = 50, max_dilatancy_mm = 1.5, broken_bonds = 0,
                             contact_decay_exponent = -0.5, energy_shares_friction = 0.9, energy_shares_damping = 0.05}
    lc_curves[name] = curves["S1_14_x_" .. model .. "_s1"]
  end
end
T = {}
for _, t in ipairs(report.trends(lc_rows, lc_curves)) do T[t.id] = t end
expect("peak_falls_with_correlation_length", "untestable", 2)
assert(T.peak_falls_with_correlation_length.ties == 2 and T.peak_falls_with_correlation_length.reason:find("same surface", 1, true),
       "identical runs: " .. tostring(T.peak_falls_with_correlation_length.reason))
assert(T.hurst_strongest.mean_abs_relative_change.Lc == nil, "an unresolved Lc is not a statistic H beats")
lc_rows[3].peak_shear_stress_mpa = 29  -- S3 rigid below S1 rigid: agrees; the elastic pair stays equal
T = {}
for _, t in ipairs(report.trends(lc_rows, lc_curves)) do T[t.id] = t end
expect("peak_falls_with_correlation_length", "not shown", 2)
assert(T.peak_falls_with_correlation_length.agree == 1 and T.peak_falls_with_correlation_length.ties == 1, "one agrees, one equal")

-- Mean and sample SD over the seeds: peaks p and 1.1 p.
local cases = report.cases(rows)
assert(#cases == 12, ("%d cases, want 12"):format(#cases))
for _, c in ipairs(cases) do
  assert(c.seeds == 2, "two seeds per case")
  local p = base[c.model] * (c.surface == "S5" and 1.5 or 1) * c.stress_mpa / 14
  assert(math.abs(c.peak_shear_stress_mpa_mean - 1.05 * p) < 1e-9 * p, "mean over seeds")
  assert(math.abs(c.peak_shear_stress_mpa_sd - 0.1 * p / math.sqrt(2)) < 1e-9 * p, "sample SD over seeds")
end

-- The fracture model against scenarios.md 4: per case (2 surfaces x 2 stresses) the mean over the
-- two seeds of its fracture runs against its rigid and elastic runs.
local function criteria() return report.fracture_criteria(rows) end
local FC = criteria()
assert(#FC.cases == 4 and FC.cases_meeting_all == 4, ("%d cases, %d meet all"):format(#FC.cases, FC.cases_meeting_all))
for _, c in ipairs(FC.cases) do
  assert(c.seeds == 2 and c.rigid_runs == 2 and c.elastic_runs == 2 and c.criteria_judged == 6, "every criterion judged")
  local p = base.fracture * (c.surface == "S5" and 1.5 or 1) * c.stress_mpa / 14
  assert(math.abs(c.values.peak_shear_stress_mpa.fracture - 1.05 * p) < 1e-9 * p, "the mean over seeds")
end
-- Each criterion turned by one change to the S1, 14 MPa case's runs (seed 1 moves the mean of two).
local function s1_14(model, seed)
  for _, r in ipairs(rows) do
    if r.surface == "S1" and r.stress_mpa == 14 and r.model == model and r.seed == seed and r.status == "finished" then return r end
  end
end
local function case_s1_14()
  for _, c in ipairs(criteria().cases) do if c.surface == "S1" and c.stress_mpa == 14 then return c end end
end
local turns = {
  {"peak", "fracture", "peak_shear_stress_mpa", 7},               -- mean 8.5: below rigid's 10.5
  {"peak", "fracture", "peak_shear_stress_mpa", 15.3},            -- mean 14.4: 5.3 % above elastic's 13.65
  {"residual", "fracture", "residual_shear_stress_mpa", 20},
  {"k0", "fracture", "initial_shear_stiffness_mpa_per_mm", 110},  -- mean 95: 19 % above elastic's 80
  {"closure", "fracture", "closure_mm", 0.02},                    -- mean 0.0275: less than elastic's 0.03
  {"closure", "fracture", "broken_bonds_in_closure", -5},          -- none on average
  {"near", "fracture", "broken_bonds_near_share", 0.6},           -- mean 0.75
  {"broken", "fracture", "broken_bond_fraction", 0.2},            -- mean 0.125
}
for _, t in ipairs(turns) do
  local r = s1_14(t[2], 1)
  local saved_value = r[t[3]]
  r[t[3]] = t[4]
  local c = case_s1_14()
  assert(c.met[t[1]] == false and c.criteria_met == 5 and not c.meets,
         ("%s = %s: want criterion %s failed alone, got %d of %d"):format(t[3], tostring(t[4]), t[1], c.criteria_met, c.criteria_judged))
  r[t[3]] = saved_value
end
-- A peak 2.9 % above the elastic one still meets it (the spec's 3 %).
do
  local r = s1_14("fracture", 1)
  local saved_value = r.peak_shear_stress_mpa
  r.peak_shear_stress_mpa = 2 * 1.029 * 13.65 - 1.1 * 12   -- the mean of the two seeds: 1.029 x 13.65
  assert(case_s1_14().met.peak == true, "2.9 % above the higher is within the spec's 3 %")
  r.peak_shear_stress_mpa = saved_value
end
-- Without the elastic runs of a case, the criteria that compare with them are not judged.
for _, r in ipairs(rows) do if r.surface == "S5" and r.model == "elastic" then r.status = "pending" end end
for _, c in ipairs(criteria().cases) do
  if c.surface == "S5" then
    assert(c.met.peak == nil and c.met.k0 == nil and c.met.closure == nil and c.met.near == true and c.criteria_judged == 2,
           "S5 without elastic runs: two criteria judged")
    assert(not c.meets, "a case not judged on every criterion does not meet them")
  end
end
for _, r in ipairs(rows) do if r.surface == "S5" and r.model == "elastic" then r.status = "finished" end end

-- The files, from run folders holding shear.csv.
for name, c in pairs(curves) do
  asperity.mkdir(out .. "/" .. name)
  local f = assert(io.open(out .. "/" .. name .. "/shear.csv", "w"))
  f:write("displacement [mm],shear_stress_mpa [MPa],dilatancy [mm],contacts [1],broken_bonds [1]\n")
  for k = 1, #c.displacement do
    f:write(("%.17g,%.17g,%.17g,%.17g,%.17g\n"):format(c.displacement[k], c.shear_stress_mpa[k], c.dilatancy[k],
                                                      c.contacts[k], c.broken_bonds[k]))
  end
  f:close()
end
report.write{dir = out, rows = rows, elapsed = {seconds = 4000, invocations = 2, jobs = 2, threads = 1}}
local md = io.open(out .. "/trends.md"):read("a")
-- Run time: 8 runs a model (2 surfaces, 2 stresses, 2 seeds); 8 specimens packed by the rigid runs.
assert(md:find("The runner ran for **1 h 06 min** in all (2 invocations, the last 2 jobs of 1 thread at a time", 1, true), md)
assert(md:find("The runs' wall times add up to 2 h 48 min", 1, true), md)          -- 8 x (60 + 300 + 900) s
assert(md:find("8 specimens were packed, 6 min 40 s of it", 1, true), md)
assert(md:find("| rigid | 8 | 8 min 00 s | 1 min 00 s | 1 min 00 s | 0 | 360 MB |", 1, true), md)
assert(md:find("| fracture | 8 | 2 h 00 min | 15 min 00 s | 15 min 00 s | 8 | 300 MB |", 1, true), md)
assert(md:find("| peak shear stress grows as H falls | shown | 12 / 12 | mean relative change -33.3 %", 1, true), md)
assert(md:find("12 cases ran with two or more seeds", 1, true), "the scatter over seeds is reported:\n" .. md)
assert(md:find("- peak_shear_stress_mpa: 6.7 %", 1, true), "SD / mean of p and 1.1 p is 6.7 %:\n" .. md)
-- Against the reference: S1 rigid at 14 MPa ran with seeds 1 and 2 (peaks 10 and 11), the thesis's 16.15;
-- S4 did not run.
assert(md:find("## Against the reference (reference.md 2, 14 MPa)", 1, true), md)
assert(md:find("joints of 5 cm", 1, true), md)
assert(md:find("| S1 | rigid | 2 | 10.50 / 16.15 (-35 %) |", 1, true), md)
assert(md:find("| S4 | elastic | 0 | not run / 13.06 |", 1, true), md)
assert(md:find("- rigid, mean difference over the surfaces run: peak ", 1, true), md)
-- The figures inline, by section, with paths relative to the study folder.
assert(md:find("### Peak and residual against the surface statistics", 1, true), md)
assert(md:find("](plots/strength_vs_H_14.png)", 1, true), md)
assert(md:find("](plots/shear_fracture_21_x.png)", 1, true), md)
local images = 0
for path in md:gmatch("!%[[^%]]*%]%(([^)]+)%)") do
  images = images + 1
  local f = io.open(out .. "/" .. path)
  assert(f, "trends.md shows a figure that is not there: " .. path)
  f:close()
end
local pngs = 0
for _ in io.popen("ls '" .. out .. "/plots'"):lines() do pngs = pngs + 1 end
assert(images >= pngs, ("trends.md shows %d figures, plots/ holds %d"):format(images, pngs))
local tj = json.read(out .. "/trends.json")
assert(#tj.trends == 21, ("trends.json: %d behaviours"):format(#tj.trends))
assert(tj.fracture_criteria.cases_meeting_all == 4 and #tj.fracture_criteria.cases == 4, "trends.json: the fracture criteria")
assert(#tj.fracture_criteria.criteria == 6 and tj.fracture_criteria.criteria[6].id == "broken", "trends.json names the criteria")
assert(md:find("## The fracture model against scenarios.md 4", 1, true), md)
assert(md:find("**4 of 4 cases meet all six criteria** (the spec judges the mean of 3 realisations: 4 ran fewer seeds)", 1, true), md)
assert(md:find("| S1 14 MPa x | 2 | 12.60 (10.50 .. 13.65) yes |", 1, true), md)
for _, png in ipairs{"shear_fracture_21_x", "models_S5_14", "strength_vs_H_14", "strength_vs_H_21", "shear_stiffness_vs_stress",
                     "energy_shares_rigid"} do
  local f = io.open(out .. "/plots/" .. png .. ".png")
  assert(f, png .. ".png missing")
  f:close()
end
print("PASS")
