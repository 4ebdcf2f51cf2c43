-- pack.mean_box_wall_stress adds the faces in a fixed order. Lua 5.4 seeds the order in which
-- pairs() visits string keys per process, so a sum in pairs() order could end in another last
-- digit in another run of the same script (and the REV's stress installation compares that mean
-- with its target). Stresses whose sum depends on the order: 1e16 then five ones (each one is
-- below half an ulp of 1e16 and is lost) against the ones first (which add up to 5 and survive).
local pack = require("pack")
local force = {x_min = 1e16, x_max = 1, y_min = 1, y_max = 1, bottom = 1, top = 1}
local ids, names = {}, {}
for name in pairs(force) do ids[name] = #names + 1; names[#names + 1] = name end
local world = {wall_force = function(_, id)
  local f = force[names[id]]
  return {x = f, y = f, z = f}
end}
local mean = pack.mean_box_wall_stress(world, ids, {0, 0, 0}, {1, 1, 1})
local fixed = 0
for _, name in ipairs{"x_min", "x_max", "y_min", "y_max", "bottom", "top"} do fixed = fixed + force[name] end
assert(mean == fixed / 6, ("mean %.17g, in the fixed order %.17g"):format(mean, fixed / 6))
assert(fixed == 1e16, "the order must matter for this test to mean anything")
print("PASS")
