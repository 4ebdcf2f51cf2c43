-- The REV (scripts/rev.lua) with the calibrated material of scripts/lib/materials.lua, on one of
-- the calibration's packings: E_REV, nu, the scaled tensile and compressive strengths and sc/st lie
-- within three standard deviations of the calibration's means over its packings (materials.lua
-- M.rev.calibration: a single 1 cm REV scatters that much), and the genesis leaves every bond
-- below st / 3 with none broken (scenarios.md 1). If the genesis or the bond model changes, this
-- fails and scripts/calibrate_rev.lua must be run again.
local out = assert(params.out, "give out=DIRECTORY")
local mat = require("materials")
local cal = mat.rev.calibration
params = {tests = "elastic,compression,tension", out = out, seed = cal.seeds[1], cache = out .. "/cache"}
local s = dofile(asperity.scripts_dir .. "/rev.lua")
local function within(value, stat, what)
  assert(math.abs(value - stat.mean) <= 3 * stat.sd,
         ("%s: %.6g, calibration %.6g +- %.3g (3 sd)"):format(what, value, stat.mean, stat.sd))
end
within(s.young_modulus_pa, cal.young_modulus_pa, "E_REV")
within(s.poisson_ratio, cal.poisson_ratio, "Poisson ratio")
within(s.tensile_strength_mpa, cal.tensile_strength_mpa, "scaled tensile strength")
within(s.compressive_strength_mpa, cal.compressive_strength_mpa, "scaled compressive strength")
within(s.strength_ratio, cal.strength_ratio, "sc / st")
-- The calibration's targets themselves (scenarios.md 2): the means, not this one packing.
assert(math.abs(cal.tensile_strength_mpa.mean - 6.6) <= 0.3, "calibrated tensile strength 6.6 +- 0.3 MPa")
assert(math.abs(cal.compressive_strength_mpa.mean / 74.6 - 1) <= 0.1, "calibrated compressive strength 74.6 MPa +- 10 %")
assert(cal.poisson_ratio.mean >= 0.17 and cal.poisson_ratio.mean <= 0.23, "calibrated nu in 0.17..0.23")
assert(math.abs(mat.rev.young_modulus / cal.young_modulus_pa.mean - 1) < 1e-3, "materials.lua's E_REV is the calibration's")
-- Genesis (scenarios.md 1): nothing broken by the wall removal, 99.9 % of the bonds well below
-- their strength (the maximum is reported, an extreme value that grows with the bond count).
assert(s.bonds_broken_in_relaxation == 0, ("%d bonds broke when the walls were removed"):format(s.bonds_broken_in_relaxation))
assert(s.bond_stress_p999_over_st <= 1 / 3, ("99.9 %% of the bonds need up to %.3f st after the wall removal"):format(s.bond_stress_p999_over_st))
assert(s.bond_stress_max_over_st >= s.bond_stress_p999_over_st, "the maximum is reported")
assert(s.genesis.stress_reached, "the genesis reached its isotropic stress")
assert(s.porosity_true < s.porosity_nominal, "the true porosity is lower than the nominal one")
for _, f in ipairs{"summary.json", "bond_stresses.csv", "bond_stresses_strength.png"} do
  local fh = assert(io.open(out .. "/" .. f), "missing " .. f)
  fh:close()
end
-- Every series file carries the calibrated stress scale (named as such: this REV's own is known
-- only after its elastic tests) and the run's parameters, the rate as given.
for _, f in ipairs{"elastic_compression.h5", "fracture_tension.h5"} do
  local function attr(name) return asperity.h5_attribute(out .. "/" .. f, "/", name) end
  assert(attr("stress_scale_calibrated") == mat.stress_scale(), f .. ": stress_scale_calibrated")
  assert(attr("stress_units"):find("Pa (model)", 1, true), f .. ": stress_units")
  assert(attr("parameter_seed") == cal.seeds[1] and attr("parameter_tests") == "elastic,compression,tension",
         f .. ": the parameters as attributes")
  assert(attr("parameter_lock_rotation") == "true", f .. ": a boolean parameter as text")
end
-- The beam's normal stiffness against the contact springs (bond_normal_stiffness, kbn A / kn) on
-- the same packing: at 2 every bonded pair's springs grow by 1.5 (normal: (1 + 2) / (1 + 1)) to
-- 1.75 (shear: (0.1 + 2 r) / (0.1 + r), ks = 0.1 kn, r = kbs / kbn = 0.3), unbonded contacts by 1. The
-- network's stiffness is homogeneous of degree one and monotone in each spring, so E grows, by at
-- most 1.75 (quasi-static elastic tests, rotations locked: no moments).
assert(mat.rev.bond_normal_stiffness == 1 and mat.rev.bond_shear_ratio == 0.3, "the bounds below assume kbn A = kn, r = 0.3")
params = {tests = "elastic", out = out .. "/stiffer_beams", seed = cal.seeds[1], cache = out .. "/cache",
          bond_normal_stiffness = 2}
local stiff = dofile(asperity.scripts_dir .. "/rev.lua")
local ratio = stiff.young_modulus_pa / s.young_modulus_pa
assert(ratio > 1 and ratio <= 1.75, ("E with kbn A = 2 kn / with kn: %.4f, outside (1, 1.75]"):format(ratio))
assert(asperity.h5_attribute(out .. "/stiffer_beams/elastic_compression.h5", "/", "parameter_bond_normal_stiffness") == 2,
       "bond_normal_stiffness recorded with the run's parameters")
print(("kbn A = 2 kn: E_REV x %.4f, nu %.3f"):format(ratio, stiff.poisson_ratio))
print(("E_REV %.4g Pa, nu %.3f, tensile %.3f MPa, compressive %.2f MPa, sc/st %.2f; worst bond %.3f st")
      :format(s.young_modulus_pa, s.poisson_ratio, s.tensile_strength_mpa, s.compressive_strength_mpa,
              s.strength_ratio, s.bond_stress_max_over_st))
print("PASS")
