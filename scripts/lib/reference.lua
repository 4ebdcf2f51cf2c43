-- What the reference study measured on its joints (Varela Valdez 2015, Tables 4-1 / 4-2; the
-- spec's reference.md, section 2): 10 cm x 10 cm joints sheared 5 mm under 14 MPa of constant
-- normal load, averaged over the x and y directions. MPa; residual at 5 mm; K0 the initial shear
-- stiffness in MPa/mm. Four of the eight surfaces.
--
--   local ref = require("reference")
--   local r = ref.joint("S5", "elastic", 14)   -- {peak = 22.34, residual = 12.63, k0 = 82.9} or nil
--   local q = ref.ratios("rigid", 14)          -- {peak = 1.14, residual = 0.63} (tau / sigma_n) or nil
local M = {}

M.citation = "A. Varela Valdez, Mechanical behavior of rock joints: influence of joint roughness on " ..
             "its closure and shear behavior, PhD thesis, Universite de Bordeaux and Universidad " ..
             "Autonoma de Nuevo Leon, 2015"
M.normal_stress_mpa = 14
-- The surfaces the tables give, in their order.
M.surfaces = {"S1", "S4", "S5", "S8"}

local T = {   -- surface = {rigid, elastic, fracture} x {peak, residual, k0}
  S1 = {rigid = {16.15, 10.24, 56.9}, elastic = {18.05, 12.48, 82.8}, fracture = {17.92, 11.68, 78.8}},
  S4 = {rigid = {12.32, 9.07, 53.2}, elastic = {13.06, 11.30, 105.3}, fracture = {13.07, 10.82, 96.1}},
  S5 = {rigid = {20.51, 9.00, 64.1}, elastic = {22.34, 12.63, 82.9}, fracture = {22.05, 10.82, 76.0}},
  S8 = {rigid = {15.34, 8.74, 62.5}, elastic = {16.53, 10.54, 88.6}, fracture = {16.36, 10.59, 89.2}},
}

-- Peak and residual shear stress over the normal stress, read across the four surfaces.
local RATIOS = {rigid = {peak = 1.14, residual = 0.63}, elastic = {peak = 1.25, residual = 0.84},
                fracture = {peak = 1.24, residual = 0.78}}

local function at_reference_stress(stress_mpa) return math.abs(stress_mpa - M.normal_stress_mpa) < 1e-9 end

-- The study's values for this surface, model and normal stress, or nil where it has none.
function M.joint(surface, model, stress_mpa)
  local row = T[surface]
  if not row or not row[model] or not at_reference_stress(stress_mpa) then return nil end
  local v = row[model]
  return {peak = v[1], residual = v[2], k0 = v[3], label = "thesis Table 4-1"}
end

-- tau / sigma_n at the peak and at 5 mm for this model (any of the four surfaces), or nil.
function M.ratios(model, stress_mpa)
  local r = RATIOS[model]
  if not r or not at_reference_stress(stress_mpa) then return nil end
  return {peak = r.peak, residual = r.residual, label = "thesis, mean of four surfaces"}
end

return M
