-- Two levers of the genesis on the same packing (tests/scenarios/genesis.lua's 6 mm cube), each
-- reaching the same stress in fewer steps and the same state:
-- - the stress servo shrinking at a quarter of its gain (the default, materials.lua
--   genesis.shrink_gain; the scripts' genesis_shrink_gain): above the target it comes down with
--   the relaxation instead of overshooting below and creeping back (28 884 against 45 162 steps
--   at the full gain, with the mass floor);
-- - the mass floor (the default), measured at the full shrinking gain, where the servo follows
--   the relaxation in time (45 162 against 82 747 steps with true masses; at a quarter of the
--   gain the servo's updates set the pace, 28 884 against 28 679).
local mat = require("materials")
local radii = require("radii")
local walls = require("walls")
local genesis = require("genesis")

local L = 0.006
local lo, hi = {0, 0, 0}, {L, L, L}
local n = radii.count_for_porosity{volume = L ^ 3, porosity = mat.genesis.porosity, mean_radius = mat.packing.mean_radius}
local function packed(shrink_gain, mass_floor)
  local w = asperity.world{material = mat.contact, damping = mat.damping, density = mat.density, threads = 1,
                           rotation_lock_bonds = mat.rev.rotation_lock_bonds}
  local box = walls.box(w, {min = lo, max = hi, material = {kn = mat.contact.kn, ks = mat.contact.ks, friction = 0}})
  local r = radii.truncated_gaussian{count = n, mean = mat.packing.mean_radius, sd = mat.packing.radius_sd, seed = 3,
                                     normalise_mean = true}
  return genesis.pack(w, {min = lo, max = hi, radii = r, seed = 3, box = box, stress = mat.genesis.stress,
                          shrink_gain = shrink_gain, mass_floor = mass_floor}), w
end
local g, g2 = packed(1), packed(0.25)
for _, x in ipairs{g, g2} do
  assert(x.stress_reached and math.abs(x.stress_pa / mat.genesis.stress - 1) <= 0.1, "the stress installed")
end
assert(g2.steps < g.steps, ("shrink_gain 0.25: %d steps, gain 1: %d"):format(g2.steps, g.steps))
assert(math.abs(g2.coordination / g.coordination - 1) < 0.05,
       ("shrink_gain: coordination %.3f against %.3f"):format(g2.coordination, g.coordination))
print(("genesis: shrink_gain 0.25 %d steps, gain 1 %d; coordination %.3f, %.3f"):format(g2.steps, g.steps,
      g2.coordination, g.coordination))

-- The mass floor (genesis.pack's mass_floor, materials.lua genesis.mass_floor): with the lightest
-- particles weighing as a mean one the time step is longer, the same stress is reached in fewer
-- steps and the state is the same; the true masses are back at the end.
local true_masses = packed(1, 0)
local floored, wf = packed(1, 1)
assert(floored.stress_reached and true_masses.stress_reached, "the stress installed")
assert(floored.steps < true_masses.steps,
       ("mass floor: %d steps, true masses %d"):format(floored.steps, true_masses.steps))
assert(math.abs(floored.coordination / true_masses.coordination - 1) < 0.05,
       ("mass floor: coordination %.3f against %.3f"):format(floored.coordination, true_masses.coordination))
for _, id in ipairs(floored.kept) do
  assert(wf:density(id) == mat.density, ("particle %d: density %g after the genesis"):format(id, wf:density(id)))
end
print(("genesis: mass floor %d steps, true masses %d; coordination %.3f, %.3f"):format(floored.steps,
      true_masses.steps, floored.coordination, true_masses.coordination))
print("PASS")
