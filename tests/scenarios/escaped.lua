-- specimen.take_out_escaped: debris thrown clear of a specimen is tagged, frozen and made inert;
-- particles inside the box, platen members and particles already taken out are left alone; the
-- taken-out particle stops moving and no longer triggers neighbour rebuilds.
local specimen = require("specimen")

local w = asperity.world{material = {kn = 0.1, ks = 0.01, friction = 0.5}}
local R = 5e-4
local inside = w:add_particle({0, 0, 0}, R)
local neighbour = w:add_particle({2.2 * R, 0, 0}, R)
local flying = w:add_particle({0.02, 0, 0}, R)          -- 2 cm out, moving fast
local platen = w:add_particle({0, 0.02, 0}, R)          -- out of the box but a platen member
w:set_tag({inside, neighbour, flying, platen}, 1)
w:add_group({platen}, {translation = "fixed"})
w:set_velocity(flying, {0.05, 0, 0})   -- a quarter of a radius per step
w:cycle(10)
local box = {min = {-0.005, -0.005, -0.005}, max = {0.005, 0.005, 0.005}}
local LOST = 3

local before = w:stats().rebuilds
w:cycle(200)
local moving_rebuilds = w:stats().rebuilds - before
assert(moving_rebuilds > 50, ("a flying particle rebuilds the list often: %d rebuilds in 200 steps"):format(moving_rebuilds))

local out = specimen.take_out_escaped(w, box, LOST)
assert(#out == 1 and out[1] == flying, ("taken out: %d ids, first %s"):format(#out, tostring(out[1])))
assert(w:tag(flying) == LOST and w:tag(inside) == 1 and w:tag(platen) == 1, "only the escaped particle is tagged")
assert(w:inert_count() == 1, ("inert particles: %d"):format(w:inert_count()))
assert(w:group_of(flying) and w:group_of(inside) == nil, "the escaped particle is frozen in a group of its own")

local x0 = w:position(flying)[1]
before = w:stats().rebuilds
w:cycle(200)
assert(w:position(flying)[1] == x0, "the taken-out particle no longer moves")
assert(w:stats().rebuilds - before <= 1, ("rebuilds after taking it out: %d"):format(w:stats().rebuilds - before))
assert(#specimen.take_out_escaped(w, box, LOST) == 0, "a particle is taken out once")
print("PASS")
