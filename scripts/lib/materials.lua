-- Material defaults shared by the scenarios: the soft contact model of the thesis, the bonds of
-- the REV (with the calibrated bond tensile strength), the target rock, and the stress scale.
--
--   local mat = require("materials")
--   local w = asperity.world{material = mat.contact, damping = mat.damping, density = mat.density}
--   w:install_bonds(mat.bond())                         -- breakable, calibrated strength
--   w:install_bonds(mat.bond{breakable = false})        -- the elastic model
--   local mpa = mat.to_rock_mpa(sigma_model)             -- scaled stress [3-37]
local M = {}

-- Contacts [thesis 3.3]: kn = 0.1 N/m, ks = kn / 10, friction 0.5; local damping 0.7.
M.contact = {kn = 0.1, ks = 0.01, friction = 0.5}
M.damping = 0.7
M.density = 2500            -- kg/m^3 (the source gives none)

-- Packing [thesis 3.3, scenarios.md 1]: radii Gaussian 0.5 mm +- 0.1 mm cut at 3 SD, n = 0.51.
M.packing = {mean_radius = 0.5e-3, radius_sd = 0.1e-3, cut = 3, porosity = 0.51}

-- Genesis [scenarios.md 1; lib/genesis.lua]: the particle count from the thesis's porosity
-- definition [3-35] at `porosity` (denser than the thesis's 0.51: a frictionless assembly jams
-- near 0.45 in a 1 cm box), compacted without friction, the isotropic `stress` installed by a
-- common radius factor, particles with fewer than `floater_contacts` contacts taken out.
M.genesis = {porosity = 0.45, stress = 1e-3, floater_contacts = 3, ratio = 1e-2}

-- Target rock, thesis Table 3-1 (mortar replicas of granite).
M.rock = {young_modulus = 30853e6, poisson_ratio = 0.187, compressive_strength = 74.6e6,
          tensile_strength = 6.6e6}

-- The REV (scripts/rev.lua, seed 1, defaults) and its calibrated bond strength, from
--   build/asperity run scripts/calibrate_rev.lua compression=true      (2026-11-23, 2 trials)
-- E_REV from the elastic compression test; st such that the REV tensile strength scaled by
-- E_exp / E_REV is Table 3-1's 6.6 MPa (0.007719 Pa in the model). The same st gives a
-- compressive strength of 131.8 MPa scaled (Table 3-1: 74.6), sc/st = 20 (source: about 10);
-- see issue notes: the packing is looser than the source's (coordination 3).
M.rev = {
  young_modulus = 103.8,          -- Pa, E_REV (model units)
  bond_tensile_strength = 0.035192, -- Pa, st of the elliptic criterion
  bond_shear_ratio = 0.3,         -- kbs / kbn of the parallel bonds
  bond_radius_factor = 1,         -- lambda [3-26]
  rotation_lock_bonds = 3,        -- bonded particles do not rotate while they hold this many bonds
}

-- Bond material for world:install_bonds: beams as stiff as the contact springs (kbn A = kn,
-- kbs A = ks), lambda = 1, the calibrated strength; `over` replaces fields.
function M.bond(over)
  local b = {beam_kn = M.contact.kn, beam_ks = M.contact.kn * M.rev.bond_shear_ratio,
             radius_factor = M.rev.bond_radius_factor,
             tensile_strength = M.rev.bond_tensile_strength}
  for k, v in pairs(over or {}) do b[k] = v end
  if b.breakable == false then b.tensile_strength = nil end
  return b
end

-- The smallest bond tensile strength st for which a bond at stresses (sigma, tau) holds under the
-- elliptic criterion [3-46..3-49]: ((sigma - h)/a)^2 + (tau/b)^2 = 1 with a = 5.5 st,
-- h = -4.5 st, b = 5 st a / sqrt(a^2 - h^2), solved for st (a quadratic in 1/st).
function M.strength_to_hold(sigma, tau)
  local beta = 5 * 5.5 / math.sqrt(5.5 ^ 2 - 4.5 ^ 2)
  local A = sigma ^ 2 / 5.5 ^ 2 + tau ^ 2 / beta ^ 2
  if A == 0 then return 0 end
  local B = 2 * 4.5 * sigma / 5.5 ^ 2
  local C = 4.5 ^ 2 / 5.5 ^ 2 - 1
  local u = (-B + math.sqrt(B * B - 4 * A * C)) / (2 * A)
  return 1 / u
end

-- Stress scale [3-37]: sigma_rock = sigma_model * E_exp / E_REV.
function M.stress_scale(young_modulus_rev)
  return M.rock.young_modulus / (young_modulus_rev or M.rev.young_modulus)
end
function M.to_rock_mpa(sigma_model, young_modulus_rev)
  return sigma_model * M.stress_scale(young_modulus_rev) / 1e6
end

return M
