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
local holds = asperity.read_h5(first, "/bonds/holds")
assert(#holds == 5 and holds[1] == 3, "each bond says which part holds: both")

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

-- Contact bonds apart from the beams (model.md 5): the same bar with c = 2 loses its first beam
-- at st, holds on by the contact bond, which breaks at 2 st A; every kind counted on its own.
local w2 = asperity.world{material = {kn = 1e3, ks = 1e2}, damping = 0.7, threads = 1}
for i = 0, 5 do w2:add_particle({0.02 * i, 0, 0}, 0.01) end
assert(w2:install_bonds{tensile_strength = st, contact_strength = 2} == 5)
w2:add_group({1}, {velocity = {-0.01, 0, 0}})
w2:add_group({6}, {velocity = {0.01, 0, 0}})
w2:run{steps = 100000, every = 10, stop_when = function(w) return w:break_count() > 0 end}
local beams = w2:break_count()  -- the bar's bonds carry the same force: several may go at once
assert(beams >= 1 and w2:break_count("contact_bond") == 0 and w2:bond_count() == 5 - beams)
local held = 0
for _, bd in ipairs(w2:bonds()) do
  if not bd.beam then
    assert(bd.contact_bond and bd.normal_force < 0, "the contact bond alone pulls")
    held = held + 1
  end
end
assert(held == beams and #w2:bonds() == 5, "the broken beams' pairs are still tied")
w2:run{steps = 100000, every = 10, stop_when = function(w) return w:break_count("contact_bond") > 0 end}
local e = w2:break_events()[w2:break_count("all")]
assert(e.kind == "contact_bond" and e.mode == "tension", e.kind .. " " .. e.mode)
assert(e.sigma >= 2 * st and e.sigma < 2.05 * st, "the contact bond broke at -Fn / A = " .. e.sigma)
assert(w2:break_count("all") == w2:break_count("beam") + w2:break_count("contact_bond"))
assert(w2:break_events(1)[1].kind == "beam")
local ok, err = pcall(w2.break_count, w2, "beams")
assert(not ok and tostring(err):find('"beam", "contact_bond" or "all"'), tostring(err))
ok, err = pcall(w2.set_bond_strength, w2, {tensile_strength = st, contact_strength = -1})
assert(not ok and tostring(err):find("contact_strength"), tostring(err))
w2:set_bond_strength{tensile_strength = st, contact_strength = math.huge}  -- never breaks from now on
-- Rows carry the fields their help lists (both from one table, for_each_info in world.hpp), and
-- each field is set.
local function keys(row) local t = {}; for k in pairs(row) do t[#t + 1] = k end; table.sort(t); return table.concat(t, ",") end
local bond_keys = keys(w2:bonds()[1])
assert(bond_keys == "a,b,beam,beam_radius,bending_moment,contact_bond,gap,normal,normal_force,point,shear_force,sigma,tau,twisting_moment",
       bond_keys)
assert(keys(w2:break_events()[1]) == "a,b,kind,mode,position,released_energy,sigma,step,tau,time", keys(w2:break_events()[1]))
-- `fields` lists only the fields asked for, with the same values; an unknown name or a list that
-- is not one is refused by name.
local whole, some = w2:bonds(), w2:bonds{fields = {"sigma", "b", "a"}}
assert(#some == #whole and #some > 0)
for k = 1, #whole do
  assert(keys(some[k]) == "a,b,sigma", keys(some[k]))
  assert(some[k].a == whole[k].a and some[k].b == whole[k].b and some[k].sigma == whole[k].sigma)
end
assert(keys(w2:bonds{fields = {}}[1]) == "")
ok, err = pcall(w2.bonds, w2, {fields = {"a", "sigmaa"}})
assert(not ok and tostring(err):find('fields%[2%] is "sigmaa", not a field; fields are {a, b,'), tostring(err))
ok, err = pcall(w2.bonds, w2, {fields = "a"})
assert(not ok and tostring(err):find("fields"), tostring(err))
ok, err = pcall(w2.contacts, w2, {fields = {"overlap", 1}})
assert(not ok and tostring(err):find("fields%[2%] is number"), tostring(err))
print("PASS")
