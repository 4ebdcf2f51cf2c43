-- A rigid platen pressed at constant speed onto a settled layer of spheres: rigid groups by
-- predicate, prescribed velocities, group forces, and a force-displacement plot.
--   build/asperity run scripts/examples/03_platen.lua out=out/platen
local out = params.out or "out/platen"
asperity.mkdir(out)

local w = asperity.world{gravity = {0, 0, -9.81}, material = {kn = 1e4, ks = 1e3}, threads = 1}
local box = require("walls").box(w, {min = {0, 0, 0}, max = {0.16, 0.16, 1}, open_top = true})
require("pack").grid(w, {min = {0, 0, 0}, max = {0.16, 0.16, 1}, count = 120, radius = 0.01,
                         spread = 0.1, gap = 0.5})
w:run{stop_when = "equilibrium", ratio = 3e-2, steps = 50000}

-- The platen: a square layer of spheres above the pile, made one rigid group.
local top = select(3, w:positions():max())
local first, last
for i = 0, 7 do
  for j = 0, 7 do
    local id = w:add_particle({0.01 + 0.02 * i, 0.01 + 0.02 * j, top + 0.03}, 0.01)
    first, last = first or id, id
  end
end
local platen = w:add_group(function(id) return id >= first end, {velocity = {0, 0, -0.02}})
local z0 = w:group_position(platen).z

-- Record the force the pile puts on the platen while it moves down 1.5 cm.
local s = asperity.series{"displacement [m]", "force [N]", "floor_force [N]"}
w:run{stop_when = function(w) return z0 - w:group_position(platen).z > 0.015 end, every = 50,
      callback = function(w)
        s:record(z0 - w:group_position(platen).z, w:group_force(platen).z, w:wall_force(box.bottom).z)
      end,
      show = function(w) return {force = w:group_force(platen).z} end}

s:write(out .. "/platen")
s:plot{file = out .. "/platen.png", x = "displacement", y = {"force", "floor_force"}}
print(("platen force after %.3g m: %.4g N (%d contacts)"):format(
  s:last("displacement"), s:last("force"), w:contact_count()))
