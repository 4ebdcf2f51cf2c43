-- A bonded bar of six spheres pulled apart by its end groups: bonds are installed between the
-- touching neighbours, break in tension when sigma reaches the tensile strength (model.md 5),
-- and every break is reported with its released energy; snapshots carry the bonds.
local out = assert(params.out, "give out=DIRECTORY")
local st = 1e3
local w = asperity.world{material = {kn = 1e3, ks = 1e2}, damping = 0.7, threads = 1}
for i = 0, 5 do w:add_particle({0.02 * i, 0, 0}, 0.01) end
assert(w:install_bonds{tensile_strength = st} == 5 and w:bond_count() == 5)
local b = w:bonds()[1]
assert(b.a == 1 and b.b == 2 and math.abs(b.beam_radius - 0.01) < 1e-15)

local snaps = asperity.snapshots{dir = out}
local first = snaps:write(w)
local pair = asperity.read_h5(first, "/bonds/pair")
assert(#pair == 5 and pair[1][1] == 0 and pair[1][2] == 1, "bond pairs are particle rows (from 0)")
assert(asperity.h5_attribute(first, "/bonds/sigma", "units") == "Pa")

w:add_group({1}, {velocity = {-0.01, 0, 0}})
w:add_group({6}, {velocity = {0.01, 0, 0}})
local steps, why = w:run{steps = 100000, every = 10, stop_when = function(w) return w:break_count() > 0 end}
assert(why == "stop_when", "a bond broke")
local released = 0
for _, e in ipairs(w:break_events()) do
  assert(e.mode == "tension", e.mode)
  assert(e.sigma >= st and e.sigma < 1.05 * st, "broke at sigma = " .. e.sigma)
  released = released + e.released_energy
end
assert(math.abs(w:energies().released - released) <= 1e-12 * released, "released energy booked")
assert(#w:break_events(w:break_count()) == 1, "break_events(first) starts at `first`")
assert(asperity.bond_criterion(st, 0, st) == 1 and asperity.bond_criterion(-10 * st, 0, st) >= 0.999)
snaps:write(w)
assert(io.open(out .. "/particles_bonds.xdmf"), "bonds XDMF written")
print("PASS")
