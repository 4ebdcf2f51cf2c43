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
-- common radius factor until the unbalanced-force ratio is `ratio` (or, where the packing creeps,
-- until its rattlers stop falling); particles with fewer than `floater_contacts` contacts
-- (floaters) are given the radius and place at which they touch four neighbours
-- (`grow_floaters`; those that find none are taken out). The stress is about 0.3 % of the REV's
-- compressive strength; the bonds then need at most a third of st after the wall removal (the largest bond
-- stress is about 8 times the mean stress, the tail of the contact forces). While packing, the
-- particles smaller than `mass_floor` x mean radius weigh as one of that radius: the lightest set
-- the critical time step [3-30], and the packed state is an equilibrium, which masses do not enter
-- (2.5x the time step; the same floater share at 1, 2 and 5 cm, where true masses left
-- 13-20 %). The stress servo shrinks the radii at a quarter of its gain
-- (`shrink_gain`), coming down to the stress with the relaxation: 1.4x fewer steps on three 5 cm
-- joints, the same state on average (perf/README.md). The packing steps run with a
-- local damping of 0.3 (`damping`; the material's 0.7 again once packed): near jamming a
-- frictionless packing relaxes by slow collective motions, which strong local damping holds back
-- (it takes 70 % of every accelerating force [3-28]), so its rattlers gathered over 75 000 steps on
-- a 10 cm joint against 24 000 at 0.3, to the same state (perf/README.md). The stress is then
-- installed again at the material's damping, the rattler criterion over `finish_patience` updates:
-- brought to rest under it without the servo a packing's stress fell by up to 44 %, and bonded
-- straight after the packing one REV packing of ten left its bonds at 0.337 st, above
-- scenarios.md 1's third.
M.genesis = {porosity = 0.45, stress = 8e-4, floater_contacts = 3, ratio = 1e-2, grow_floaters = true,
             mass_floor = 1, shrink_gain = 0.25, damping = 0.3, finish_patience = 5}

-- Target rock, thesis Table 3-1 (mortar replicas of granite).
M.rock = {young_modulus = 30853e6, poisson_ratio = 0.187, compressive_strength = 74.6e6,
          tensile_strength = 6.6e6}

-- The REV material [scenarios.md 2], calibrated on 1 cm REVs made by the genesis above, from
--   build/asperity run scripts/calibrate_rev.lua seeds=1,2,3,4,5,6,7,8,9,10
-- The micro-parameters the thesis leaves open (reference.md 1), chosen as scripts/README.md says
-- ("How the material is calibrated"): parallel bonds with kbs / kbn = 0.3 (Poisson ratio), the
-- thesis's rotation lock (a particle holding a bond does not rotate), contact bonds that break on
-- their own at c st A with c = 1.75 (the strength ratio sc / st), lambda = 1 and the engine's gap
-- tolerance. st is then the bond strength whose REV tensile strength, scaled by E_exp / E_REV, is
-- 6.6 MPa on average; the figures of each packing scatter by the standard deviations of
-- `calibration`. The joint's fracture model does not hold on this material yet (scripts/README.md).
M.rev = {
  young_modulus = 112.11,         -- Pa, E_REV (model units), mean over the packings
  bond_tensile_strength = 0.028229, -- Pa, st of the elliptic criterion
  bond_shear_ratio = 0.3,         -- kbs / kbn of the parallel bonds
  bond_normal_stiffness = 1,      -- kbn A / kn: the beam against the contact springs (model.md 5)
  bond_radius_factor = 1,         -- lambda [3-26]
  -- A bonded particle does not rotate (1: the thesis's rule); with k > 1 a damaged one only while
  -- it still holds k (model.md 2; neighbor/topology.cpp).
  rotation_lock_bonds = 1,
  -- true: only bonds whose parallel bond holds lock rotation (model.md 5's alternative; false: a
  -- pair either part of which holds).
  rotation_lock_beams = false,
  -- The contact bond's strength factor c (model.md 5: Fcn = Fcs = c st A): "beam" breaks it with
  -- the parallel bond, "inf" never, a number > 0 at c st A.
  contact_strength = "1.75",
  -- Its shear strength factor, if not c ("same"): "inf" never, a number > 0 at cs st A.
  contact_shear_strength = "same",
  -- Its shear strength grows by mu_b Fn under compression Fn (0: model.md 5's contact bond).
  contact_bond_friction = 0,
  calibration = {seeds = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10},
                 young_modulus_pa = {mean = 112.11, sd = 3.169},
                 poisson_ratio = {mean = 0.18011, sd = 0.00611},
                 tensile_strength_mpa = {mean = 6.5929, sd = 0.3091},
                 compressive_strength_mpa = {mean = 75.164, sd = 2.783},
                 strength_ratio = {mean = 11.426, sd = 0.727}},
}

-- A contact-bond strength factor as a script gives it -> the number the engine takes: `word`
-- (its 0), "inf" (math.huge: never breaks) or a number > 0; nil and what is allowed otherwise.
local function strength_factor(text, word, allowed)
  if text == word then return 0 end
  if text == "inf" then return math.huge end
  local c = tonumber(text)
  if c and c > 0 and c < math.huge then return c end
  return nil, allowed
end

-- c of the contact bond (BondMaterial::contact_strength): "beam" (0: breaks with the beam),
-- "inf" or a number > 0.
function M.contact_strength(text)
  return strength_factor(text, "beam", "must be \"beam\" (breaks with the parallel bond), \"inf\" (never breaks) " ..
                                       "or a number > 0 (c of c st A)")
end

-- cs of its shear strength (BondMaterial::contact_shear_strength): "same" (0: as c), "inf" or a
-- number > 0.
function M.contact_shear_strength(text)
  return strength_factor(text, "same", "must be \"same\" (as contact_strength), \"inf\" (never breaks in shear) " ..
                                       "or a number > 0 (cs of cs st A)")
end

-- The beam's stiffnesses (beam_kn = kbn A, beam_ks = kbs A) from the contact's kn: kbn A =
-- normal kn (1: the beam as stiff as the contact springs), kbs = shear_ratio kbn.
function M.beam_stiffness(kn, normal, shear_ratio)
  local kbn = normal * kn
  return kbn, kbn * shear_ratio
end

-- Bond material for world:install_bonds: the calibrated beam stiffnesses (M.beam_stiffness),
-- lambda, the calibrated strength; `over` replaces fields.
function M.bond(over)
  local kbn, kbs = M.beam_stiffness(M.contact.kn, M.rev.bond_normal_stiffness, M.rev.bond_shear_ratio)
  local b = {beam_kn = kbn, beam_ks = kbs,
             radius_factor = M.rev.bond_radius_factor,
             tensile_strength = M.rev.bond_tensile_strength,
             contact_strength = (M.contact_strength(M.rev.contact_strength)),
             contact_shear_strength = (M.contact_shear_strength(M.rev.contact_shear_strength)),
             contact_bond_friction = M.rev.contact_bond_friction}
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
