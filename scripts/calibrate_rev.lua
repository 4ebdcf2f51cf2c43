-- Calibration of the bonded material on the REV [thesis 3.3.2; scenarios.md 2.5]: the bond
-- strength st of the elliptic criterion for which the REV's tensile strength, scaled to rock by
-- E_exp / E_REV [3-37] and averaged over several packings (seeds), equals the target (Table 3-1:
-- 6.6 MPa); then the compressive strength, E, nu and their isotropy at that st, with the scatter
-- over the packings.
--
--   build/asperity run scripts/calibrate_rev.lua                               # out/calibration/
--   build/asperity run scripts/calibrate_rev.lua seeds=1,2,3,4 bond_shear_ratio=0.3 rotation_lock_bonds=3
--
-- The other micro-parameters (bond_shear_ratio, bond_normal_stiffness, bond_radius_factor,
-- rotation_lock_bonds, bond_gap, genesis_stress, porosity) are passed to rev.lua; materials.lua's
-- are the defaults.
-- Each packing is made once (rev.lua's cache). The REV tensile strength is proportional to st
-- while no bond breaks before the test (E_REV and the bond stresses the genesis leaves do not
-- depend on st), so the next trial is st * target / measured; it stops within `tolerance`.
-- Writes out/summary.json (trials, per-seed results, means and standard deviations) and prints the
-- line to put into scripts/lib/materials.lua.
local mat = require("materials")
local params_lib = require("params")
local P = params_lib.parse{
  script = "calibrate_rev.lua",
  path = "scripts/calibrate_rev.lua",
  about = "the bond tensile strength st for which the REV's scaled tensile strength, over several packings, is the target",
  {"target_mpa", mat.rock.tensile_strength / 1e6, unit = "MPa", above = 0, doc = "target tensile strength, scaled to rock (Table 3-1: 6.6)"},
  {"start", 0, unit = "Pa", min = 0, doc = "first trial st, model units (0: the calibrated one of materials.lua)"},
  {"tolerance", 0.01, above = 0, below = 1, doc = "relative, on the mean scaled tensile strength"},
  {"iterations", 6, type = "integer", min = 1, doc = "most trials"},
  {"seeds", "1,2,3,4,5", list = "number", min = 1, doc = "packings averaged (positive integers)"},
  {"compression", true, doc = "also test the calibrated st in compression"},
  {"isotropy", true, doc = "also E and nu along x and y"},
  {"bond_shear_ratio", mat.rev.bond_shear_ratio, min = 0, doc = "passed to rev.lua"},
  {"bond_normal_stiffness", mat.rev.bond_normal_stiffness, above = 0, doc = "passed to rev.lua"},
  {"bond_radius_factor", mat.rev.bond_radius_factor, above = 0, max = 1, doc = "passed to rev.lua"},
  {"rotation_lock_bonds", mat.rev.rotation_lock_bonds, type = "integer", min = 1, doc = "passed to rev.lua"},
  {"rotation_lock_beams", mat.rev.rotation_lock_beams, doc = "passed to rev.lua"},
  {"bond_gap", 0, unit = "m", min = 0, doc = "passed to rev.lua"},
  {"contact_strength", mat.rev.contact_strength, type = "string", doc = "passed to rev.lua (c > 0, \"inf\" or \"beam\")"},
  {"contact_shear_strength", mat.rev.contact_shear_strength, type = "string", doc = "passed to rev.lua (cs > 0, \"inf\" or \"same\")"},
  {"contact_bond_friction", mat.rev.contact_bond_friction, min = 0, doc = "passed to rev.lua"},
  {"grow_floaters", mat.genesis.grow_floaters, doc = "passed to rev.lua"},
  {"genesis_stress", mat.genesis.stress, unit = "Pa", above = 0, doc = "passed to rev.lua"},
  {"genesis_shrink_gain", mat.genesis.shrink_gain, above = 0, max = 1, doc = "passed to rev.lua"},
  {"genesis_mass_floor", mat.genesis.mass_floor, min = 0, max = 2, doc = "passed to rev.lua"},
  {"genesis_damping", mat.genesis.damping, min = 0, below = 1, doc = "passed to rev.lua"},
  {"porosity", mat.genesis.porosity, above = 0, below = 1, doc = "passed to rev.lua"},
  {"out", "out/calibration", nonempty = true, doc = "output folder (one folder per trial and seed)"},
  {"cache", "", doc = "packings cached here (\"\": out/cache)"},
  check = function(P, fail)
    local list = params_lib.split(P.seeds, true)
    if #list == 0 then fail("seeds", "must give at least one seed (e.g. seeds=1,2,3)") end
    for _, v in ipairs(list) do
      if math.tointeger(v) == nil then fail("seeds", ("'%s' is not an integer"):format(v)) end
    end
    local _, why = mat.contact_strength(P.contact_strength)
    if why then fail("contact_strength", why) end
    local _, why_shear = mat.contact_shear_strength(P.contact_shear_strength)
    if why_shear then fail("contact_shear_strength", why_shear) end
  end,
}
if not P then return end   -- help printed
if P.start <= 0 then P.start = mat.rev.bond_tensile_strength end
local out = asperity.mkdir(P.out)
local cache = P.cache ~= "" and P.cache or out .. "/cache"
local seeds = {}
for _, v in ipairs(params_lib.split(P.seeds, true)) do seeds[#seeds + 1] = math.tointeger(v) end
local rev_script = asperity.scripts_dir .. "/rev.lua"

local function rev(st, tests, seed, name)
  params = {tensile_strength = st, tests = tests, seed = seed, cache = cache,
            bond_shear_ratio = P.bond_shear_ratio, bond_normal_stiffness = P.bond_normal_stiffness,
            bond_radius_factor = P.bond_radius_factor,
            rotation_lock_bonds = P.rotation_lock_bonds, rotation_lock_beams = P.rotation_lock_beams, bond_gap = P.bond_gap,
            contact_strength = P.contact_strength, contact_shear_strength = P.contact_shear_strength,
            contact_bond_friction = P.contact_bond_friction,
            grow_floaters = P.grow_floaters,
            genesis_stress = P.genesis_stress, genesis_shrink_gain = P.genesis_shrink_gain, genesis_mass_floor = P.genesis_mass_floor, genesis_damping = P.genesis_damping, porosity = P.porosity,
            out = ("%s/%s_seed%d"):format(out, name, seed)}
  return dofile(rev_script)
end

local function stats(list, key)
  local n, s, s2 = 0, 0, 0
  for _, r in ipairs(list) do
    local v = r[key]
    if v then n, s, s2 = n + 1, s + v, s2 + v * v end
  end
  if n == 0 then return nil end
  local m = s / n
  return {mean = m, sd = n > 1 and math.sqrt(math.max(0, (s2 - n * m * m) / (n - 1))) or 0, n = n}
end

local trials = {}
local st = P.start
local result
for k = 1, P.iterations do
  local per_seed = {}
  for _, seed in ipairs(seeds) do
    local s = rev(st, "elastic,tension", seed, ("trial%02d"):format(k))
    per_seed[#per_seed + 1] = {seed = seed, tensile_strength_mpa = s.tensile_strength_mpa,
                               young_modulus_pa = s.young_modulus_pa, poisson_ratio = s.poisson_ratio,
                               broken_in_relaxation = s.broken_in_relaxation,
                               bond_stress_max_over_st = s.bond_stress_max_over_st}
  end
  local t = stats(per_seed, "tensile_strength_mpa")
  trials[#trials + 1] = {bond_tensile_strength_pa = st, tensile_strength_mpa = t, per_seed = per_seed}
  print(("trial %d: st = %.5g Pa -> REV tensile strength %.3f +- %.3f MPa over %d packings; target %.3f MPa")
        :format(k, st, t.mean, t.sd, t.n, P.target_mpa))
  if math.abs(t.mean / P.target_mpa - 1) <= P.tolerance then
    result = {bond_tensile_strength_pa = st, tensile_strength_mpa = t}
    break
  end
  st = st * P.target_mpa / t.mean
end
if not result then
  error(("calibrate_rev: no st within %.0f %% of %.3f MPa after %d trials (see %s/summary.json)")
        :format(100 * P.tolerance, P.target_mpa, P.iterations, out))
end

-- The calibrated st on every packing: all tests asked for.
local tests = "elastic,tension" .. (P.compression and ",compression" or "") .. (P.isotropy and ",isotropy" or "")
local finals = {}
for _, seed in ipairs(seeds) do
  local s = rev(result.bond_tensile_strength_pa, tests, seed, "final")
  local e, nu = s.young_modulus_by_axis_pa, s.poisson_ratio_by_axis
  finals[#finals + 1] = {seed = seed, young_modulus_pa = s.young_modulus_pa, poisson_ratio = s.poisson_ratio,
                         tensile_strength_mpa = s.tensile_strength_mpa, compressive_strength_mpa = s.compressive_strength_mpa,
                         strength_ratio = s.strength_ratio, young_modulus_spread = s.young_modulus_spread,
                         poisson_ratio_spread = s.poisson_ratio_spread,
                         young_modulus_x = e and e.x, young_modulus_y = e and e.y, young_modulus_z = e and e.z,
                         poisson_ratio_x = nu and nu.x, poisson_ratio_y = nu and nu.y, poisson_ratio_z = nu and nu.z,
                         bond_stress_max_over_st = s.bond_stress_max_over_st,
                         bonds_broken_in_relaxation = s.bonds_broken_in_relaxation,
                         particles = s.n_particles, bonds_per_particle = s.bonds_per_particle,
                         porosity_nominal = s.porosity_nominal, porosity_true = s.porosity_true}
end
for _, key in ipairs{"young_modulus_pa", "poisson_ratio", "tensile_strength_mpa", "compressive_strength_mpa",
                     "strength_ratio", "young_modulus_spread", "poisson_ratio_spread", "bond_stress_max_over_st",
                     "young_modulus_x", "young_modulus_y", "young_modulus_z", "poisson_ratio_x", "poisson_ratio_y",
                     "poisson_ratio_z", "bonds_per_particle", "porosity_nominal", "porosity_true"} do
  result[key] = stats(finals, key)
end
-- Isotropy over the packings: the means along x, y and z (each packing alone is noisier).
if P.isotropy then
  local function spread(a, b, c)
    local m = (a + b + c) / 3
    return (math.max(a, b, c) - math.min(a, b, c)) / m
  end
  result.young_modulus_spread_of_means = spread(result.young_modulus_x.mean, result.young_modulus_y.mean,
                                                result.young_modulus_z.mean)
  result.poisson_ratio_spread_of_means = spread(result.poisson_ratio_x.mean, result.poisson_ratio_y.mean,
                                                result.poisson_ratio_z.mean)
end
result.per_seed = finals
asperity.write_json(out .. "/summary.json", {parameters = P, trials = trials, result = result})
local function ms(t, fmt) return t and (fmt .. " +- " .. fmt):format(t.mean, t.sd) or "-" end
print(("calibrated over %d packings: st = %.5g Pa; E_REV %s Pa, nu %s, tensile %s MPa, compressive %s MPa, sc/st %s")
      :format(#seeds, result.bond_tensile_strength_pa, ms(result.young_modulus_pa, "%.4g"), ms(result.poisson_ratio, "%.3f"),
              ms(result.tensile_strength_mpa, "%.2f"), ms(result.compressive_strength_mpa, "%.1f"),
              ms(result.strength_ratio, "%.2f")))
if P.isotropy then
  print(("isotropy: E x/y/z %.4g / %.4g / %.4g Pa (spread of the means %.1f %%), nu %.3f / %.3f / %.3f (%.1f %%)")
        :format(result.young_modulus_x.mean, result.young_modulus_y.mean, result.young_modulus_z.mean,
                100 * result.young_modulus_spread_of_means, result.poisson_ratio_x.mean, result.poisson_ratio_y.mean,
                result.poisson_ratio_z.mean, 100 * result.poisson_ratio_spread_of_means))
end
local record = {seeds = seeds}
for _, key in ipairs{"young_modulus_pa", "poisson_ratio", "tensile_strength_mpa", "compressive_strength_mpa",
                     "strength_ratio"} do
  if result[key] then record[key] = {mean = result[key].mean, sd = result[key].sd} end  -- none without compression
end
-- The bond micro-parameters given here that differ from materials.lua's go there too.
local changed = {}
for _, key in ipairs{"bond_shear_ratio", "bond_normal_stiffness", "bond_radius_factor", "rotation_lock_bonds",
                     "rotation_lock_beams", "contact_strength", "contact_shear_strength", "contact_bond_friction"} do
  if P[key] ~= mat.rev[key] then
    changed[#changed + 1] = ("%s = %s,"):format(key, type(P[key]) == "string" and ("%q"):format(P[key]) or tostring(P[key]))
  end
end
print(("put into scripts/lib/materials.lua M.rev: young_modulus = %.5g, bond_tensile_strength = %.5g,%s\n  calibration = %s")
      :format(result.young_modulus_pa.mean, result.bond_tensile_strength_pa,
              #changed > 0 and (" " .. table.concat(changed, " ")) or "", require("genesis").serialise(record)))
return result
