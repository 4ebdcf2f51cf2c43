-- Calibration of the bond tensile strength [thesis 3.3.2; scenarios.md 2.5]: find the bond
-- strength st of the elliptic criterion for which the REV's tensile strength, scaled to rock by
-- E_exp / E_REV [3-37], equals the target (Table 3-1: 6.6 MPa).
--
--   build/asperity run scripts/calibrate_rev.lua                      # out/calibration/
--   build/asperity run scripts/calibrate_rev.lua target_mpa=6.6 seed=2 compression=true
--
-- Each evaluation runs scripts/rev.lua (packing, bonding, wall removal, elastic test for E_REV,
-- tension to failure) with the trial st. The REV tensile strength is close to proportional to st
-- (the packing, E_REV and the internal bond stresses do not depend on it), so the next trial is
-- st * target / measured, a secant through the origin; it stops within `tolerance`. The search
-- starts above the strength every bond needs to survive the wall removal (rev.lua reports it):
-- below that, bonds break before any test and the REV is not the material being calibrated.
-- With compression=true the final st is also tested in compression (sc, sc/st).
-- Writes out/summary.json (the trials and the result) and prints the line to put into
-- scripts/lib/materials.lua.
local mat = require("materials")
local P = require("params").defaults{
  target_mpa = mat.rock.tensile_strength / 1e6,
  start = 0,                              -- Pa, first trial st (0: the calibrated one of materials.lua)
  tolerance = 0.01,                       -- relative, on the scaled tensile strength
  iterations = 8,
  seed = 1,
  compression = false,
  packing_stress = -1,                    -- Pa, passed to rev.lua (0: bond as packed; < 0: materials.lua's)
  stress_free_bonds = false,              -- passed to rev.lua
  out = "out/calibration",
}
local rev_material = mat.rev_for(P.stress_free_bonds)
if P.start <= 0 then P.start = rev_material.bond_tensile_strength end
if P.packing_stress < 0 then P.packing_stress = rev_material.packing_stress end
local out = asperity.mkdir(P.out)
local rev_script = asperity.scripts_dir .. "/rev.lua"

local function rev(st, tests, k)
  params = {tensile_strength = st, tests = tests, seed = P.seed, packing_stress = P.packing_stress,
            stress_free_bonds = P.stress_free_bonds, out = ("%s/trial_%02d"):format(out, k)}
  return dofile(rev_script)
end

local trials = {}
local st = P.start
local result
for k = 1, P.iterations do
  local s = rev(st, "elastic,tension", k)
  local floor = s.residual_bond_stress.strength_to_hold_max_pa
  local measured = s.tensile_strength_mpa
  trials[#trials + 1] = {bond_tensile_strength_pa = st, tensile_strength_mpa = measured,
                         tensile_strength_pa = s.tensile_strength_pa, young_modulus_pa = s.young_modulus_pa,
                         strength_to_hold_max_pa = floor}
  print(("trial %d: st = %.5g Pa -> REV tensile strength %.4g Pa = %.3f MPa (E_REV %.4g Pa); target %.3f MPa")
        :format(k, st, s.tensile_strength_pa, measured, s.young_modulus_pa, P.target_mpa))
  if math.abs(measured / P.target_mpa - 1) <= P.tolerance then
    result = {bond_tensile_strength_pa = st, young_modulus_pa = s.young_modulus_pa,
              tensile_strength_mpa = measured, strength_to_hold_max_pa = floor}
    break
  end
  local next_st = st * P.target_mpa / measured
  if next_st <= floor then
    error(("calibrate_rev: the target needs st = %.4g Pa, below the %.4g Pa some bonds need to survive " ..
           "the wall removal; lower the packing stress or raise the target"):format(next_st, floor))
  end
  st = next_st
end
if not result then
  error(("calibrate_rev: no st within %.0f %% of %.3f MPa after %d trials (see %s/summary.json)")
        :format(100 * P.tolerance, P.target_mpa, P.iterations, out))
end
if P.compression then
  local s = rev(result.bond_tensile_strength_pa, "elastic,compression,tension", #trials + 1)
  result.compressive_strength_mpa = s.compressive_strength_mpa
  result.tensile_strength_mpa_check = s.tensile_strength_mpa
  result.strength_ratio = s.strength_ratio
  print(("compression at the calibrated st: %.2f MPa (Table 3-1: %.1f MPa), sc/st = %.2f")
        :format(s.compressive_strength_mpa, mat.rock.compressive_strength / 1e6, s.strength_ratio))
end
asperity.write_json(out .. "/summary.json", {parameters = P, trials = trials, result = result})
print(("calibrated: bond_tensile_strength = %.5g Pa (E_REV = %.5g Pa, REV tensile strength %.3f MPa " ..
       "scaled) after %d trials; put it in scripts/lib/materials.lua (%s)")
      :format(result.bond_tensile_strength_pa, result.young_modulus_pa, result.tensile_strength_mpa, #trials,
              P.stress_free_bonds and "M.rev_stress_free" or "M.rev"))
return result
