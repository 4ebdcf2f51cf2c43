-- The genesis (scripts/lib/genesis.lua, scenarios.md 1) on a small cube: the stress measured from
-- the contacts matches the closed form on a lattice; the isotropic stress is installed within its
-- tolerance; floaters are taken out; the calibrated bonds hold what the wall removal leaves with
-- none above st / 3 and none broken.
local mat = require("materials")
local radii = require("radii")
local walls = require("walls")
local genesis = require("genesis")

-- 1. world:contact_stress (Love-Weber) on a simple cubic lattice of n^3 equal spheres pressed by
-- overlap U: each of the 3 n^2 (n - 1) contacts carries kn U at a centre distance d = 2R - U, so
-- p = 3 n^2 (n - 1) kn U d / (3 V).
do
  local w = asperity.world{material = {kn = 0.1, ks = 0.01, friction = 0}, damping = 0.7}
  local R, U, n = 1e-3, 2e-5, 3
  local d = 2 * R - U
  for i = 0, n - 1 do for j = 0, n - 1 do for k = 0, n - 1 do
    w:add_particle({i * d, j * d, k * d}, R)
  end end end
  w:cycle(1)
  local V = (n * d) ^ 3
  local p, k, count = w:contact_stress(0, V)
  local contacts = 3 * n * n * (n - 1)
  local expected = contacts * 0.1 * U * d / (3 * V)
  assert(count == contacts, ("%d contacts, expected %d"):format(count, contacts))
  assert(math.abs(p / expected - 1) < 1e-9, ("lattice stress %.10g, closed form %.10g"):format(p, expected))
  -- affine stiffness against a common radius factor: each overlap grows by 2R per unit of factor
  local stiffness = contacts * 0.1 * 2 * R * d / (3 * V)
  assert(math.abs(k / stiffness - 1) < 1e-9, ("affine stiffness %.10g, closed form %.10g"):format(k, stiffness))
  assert(w:contact_stress(7, V) == 0, "no particle of tag 7: no stress")
end

-- 2. The genesis of a 6 mm cube.
local L = 0.006
local w = asperity.world{material = mat.contact, damping = mat.damping, density = mat.density, threads = 1,
                         rotation_lock_bonds = mat.rev.rotation_lock_bonds}
local lo, hi = {0, 0, 0}, {L, L, L}
local box = walls.box(w, {min = lo, max = hi, material = {kn = mat.contact.kn, ks = mat.contact.ks, friction = 0}})
local n = radii.count_for_porosity{volume = L ^ 3, porosity = mat.genesis.porosity, mean_radius = mat.packing.mean_radius}
local r = radii.truncated_gaussian{count = n, mean = mat.packing.mean_radius, sd = mat.packing.radius_sd, seed = 3,
                                   normalise_mean = true}
local g = genesis.pack(w, {min = lo, max = hi, radii = r, seed = 3, box = box, stress = mat.genesis.stress})
assert(g.stress_reached, ("stress %.4g Pa, target %.4g"):format(g.stress_pa, mat.genesis.stress))
assert(math.abs(g.stress_pa / mat.genesis.stress - 1) <= 0.1, "the installed stress is within 10 % of the target")
assert(g.floaters_removed < 0.25 * n, ("%d of %d particles were floaters"):format(g.floaters_removed, n))
assert(w:inert_count() == #g.floaters, "floaters are inert")
assert(g.coordination > 3.5, ("coordination %.2f of the jammed assembly"):format(g.coordination))
assert(g.porosity_true < g.porosity_nominal, "true porosity below the thesis's nominal one")
local ids = {}
for _, id in pairs(box) do ids[#ids + 1] = id end
local b = genesis.bond(w, {sets = {g.kept}, material = mat.bond(), walls = ids})
assert(b.bonds > 0 and b.broken_in_relaxation == 0, ("%d bonds broke when the walls went"):format(b.broken_in_relaxation))
assert(b.bond_stress.max_over_st <= 1 / 3, ("a bond needs %.3f st to hold after the wall removal"):format(b.bond_stress.max_over_st))
assert(b.defined_state == true, "the record says the genesis ended in the defined state")
assert(w:settings().rotation_lock_bonds == mat.rev.rotation_lock_bonds)
print(("genesis: %d particles, %d floaters, stress %.4g Pa, coordination %.2f, %d bonds, worst bond %.3f st")
      :format(n, g.floaters_removed, g.stress_pa, g.coordination, b.bonds, b.bond_stress.max_over_st))
print("PASS")
