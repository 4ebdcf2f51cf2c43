-- The genesis (scripts/lib/genesis.lua, scenarios.md 1) on a small cube: the stress measured from
-- the contacts matches the closed form on a lattice; the isotropic stress is installed within its
-- tolerance; floaters are taken out, or placed where they touch four neighbours (the tangent
-- sphere against closed forms); the calibrated bonds hold what the wall removal leaves, 99.9 %
-- of them below st / 3, none broken.
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
-- Packed at genesis.damping, the stress installed again at the world's own before the floaters
-- and bonds (the stress asserted above is that one).
assert(mat.genesis.damping ~= mat.damping and g.finish_steps >= 1000,
       ("%d steps of the stress installation at the world's damping"):format(g.finish_steps))
assert(w:settings().damping == mat.damping, "the world's damping back after the packing")
local ids = {}
for _, id in pairs(box) do ids[#ids + 1] = id end
local b = genesis.bond(w, {sets = {g.kept}, material = mat.bond(), walls = ids})
assert(b.bonds > 0 and b.broken_in_relaxation == 0, ("%d bonds broke when the walls went"):format(b.broken_in_relaxation))
assert(b.bond_stress.p999_over_st <= 1 / 3, ("99.9 %% of the bonds need up to %.3f st to hold after the wall removal"):format(b.bond_stress.p999_over_st))
assert(b.defined_state == true, "the record says the genesis ended in the defined state")
assert(w:settings().rotation_lock_bonds == mat.rev.rotation_lock_bonds)
print(("genesis: %d particles, %d floaters, stress %.4g Pa, coordination %.2f, %d bonds, worst bond %.3f st")
      :format(n, g.floaters_removed, g.stress_pa, g.coordination, b.bonds, b.bond_stress.max_over_st))

-- 3. The sphere tangent to four constraints (genesis.tangent_spheres) against closed forms.
do
  -- Four spheres of radius R on a regular tetrahedron of edge a: the centroid, r = a sqrt(6) / 4 - R.
  local a, R = 3.0, 1.0
  local v = {{0, 0, 0}, {a, 0, 0}, {a / 2, a * math.sqrt(3) / 2, 0}, {a / 2, a * math.sqrt(3) / 6, a * math.sqrt(6) / 3}}
  local q = {}
  for k = 1, 4 do q[k] = {v[k][1], v[k][2], v[k][3], R, sphere = true} end
  local found = {}
  genesis.tangent_spheres(q, function(x, y, z, r) found[#found + 1] = {x, y, z, r} end)
  local inner = a * math.sqrt(6) / 4 - R
  local ok = false
  for _, f in ipairs(found) do
    if math.abs(f[4] - inner) < 1e-12 and math.abs(f[1] - a / 2) < 1e-12 and math.abs(f[3] - a * math.sqrt(6) / 12) < 1e-12 then ok = true end
  end
  assert(ok, "the tetrahedron's inscribed sphere")
  -- Three faces of a corner (x, y, z >= 0) and a sphere of radius R at (s, s, s):
  -- centre (r, r, r) with sqrt(3) (s - r) = r + R.
  local s3, Rs = 2.0, 0.5
  q = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {s3, s3, s3, Rs, sphere = true}}
  local want = (math.sqrt(3) * s3 - Rs) / (math.sqrt(3) + 1)
  ok = false
  genesis.tangent_spheres(q, function(x, y, z, r)
    if math.abs(r - want) < 1e-12 and math.abs(x - r) < 1e-12 and math.abs(z - r) < 1e-12 then ok = true end
  end)
  assert(ok, "the sphere in a corner touching a fourth sphere")
end

-- 4. Floaters placed (scenarios.md 1): cubes of three packings with every floater given the radius
-- and place at which it touches four neighbours; each then has at least three contacts, none
-- deeper than a hair, and the bonded specimen ends in the defined state.
for _, seed in ipairs{3, 4, 5} do
  local r = radii.truncated_gaussian{count = n, mean = mat.packing.mean_radius, sd = mat.packing.radius_sd, seed = seed,
                                     normalise_mean = true}
  local w2 = asperity.world{material = mat.contact, damping = mat.damping, density = mat.density, threads = 1,
                            rotation_lock_bonds = mat.rev.rotation_lock_bonds}
  local box2 = walls.box(w2, {min = lo, max = hi, material = {kn = mat.contact.kn, ks = mat.contact.ks, friction = 0}})
  local g2 = genesis.pack(w2, {min = lo, max = hi, radii = r, seed = seed, box = box2, stress = mat.genesis.stress,
                               grow_floaters = true})
  assert(g2.floaters_grown > 0, "the packing has floaters to place")
  assert(g2.floaters_removed <= 0.01 * n, ("%d floaters found no place"):format(g2.floaters_removed))
  assert(#g2.kept + g2.floaters_removed == n, "every particle kept or taken out")
  local counts = genesis.touching_counts(w2, g2.kept)
  local pos, rad = w2:positions(), w2:radii()
  for _, id in ipairs(g2.kept) do
    local x, y, z, rr = pos:get(id, 1), pos:get(id, 2), pos:get(id, 3), rad:get(id)
    local faces = 0
    for k, c in ipairs{x, y, z} do
      if c - lo[k] < rr then faces = faces + 1 end
      if hi[k] - c < rr then faces = faces + 1 end
    end
    assert(counts[id] + faces >= 3, ("particle %d touches %d particles and %d faces"):format(id, counts[id], faces))
  end
  local deepest = 0
  for _, id in ipairs(g2.kept) do
    for _, j in ipairs(g2.kept) do
      if j > id then
        local d = math.sqrt((pos:get(j, 1) - pos:get(id, 1)) ^ 2 + (pos:get(j, 2) - pos:get(id, 2)) ^ 2 + (pos:get(j, 3) - pos:get(id, 3)) ^ 2)
        deepest = math.max(deepest, (rad:get(id) + rad:get(j) - d) / math.min(rad:get(id), rad:get(j)))
      end
    end
  end
  assert(deepest < 1e-3, ("deepest overlap %.3g radii: the placed floaters must not press"):format(deepest))
  assert(g2.coordination > 4.2, ("coordination %.2f: the placed floaters' contacts count"):format(g2.coordination))
  local ids2 = {}
  for _, id in pairs(box2) do ids2[#ids2 + 1] = id end
  local b2 = genesis.bond(w2, {sets = {g2.kept}, material = mat.bond(), walls = ids2})
  assert(b2.broken_in_relaxation == 0 and b2.defined_state == true,
         ("defined state: %d broken, 99.9 %% below %.3f st"):format(b2.broken_in_relaxation, b2.bond_stress.p999_over_st))
  print(("floaters placed: %d of %d particles (%d taken out), coordination %.2f, deepest overlap %.2g radii")
        :format(g2.floaters_grown, n, g2.floaters_removed, g2.coordination, deepest))
end
print("PASS")
