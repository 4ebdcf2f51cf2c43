-- Boxes of plane walls.
--
--   local walls = require("walls")
--   local box = walls.box(world, {min = {0, 0, 0}, max = {1, 1, 1}, open_top = true})
--   -- box.bottom, box.top (unless open), box.x_min, box.x_max, box.y_min, box.y_max: wall ids
local M = {}

function M.box(world, o)
  assert(type(o) == "table" and o.min and o.max, "walls.box: give min = {x, y, z} and max = {x, y, z}")
  for k in pairs(o) do
    if not ({min = true, max = true, open_top = true, material = true})[k] then
      error("walls.box: unknown option '" .. tostring(k) .. "' (min, max, open_top, material)", 2)
    end
  end
  local lo, hi, m = o.min, o.max, o.material
  local ids = {}
  local function plane(name, point, normal)
    ids[name] = world:add_plane{point = point, normal = normal, material = m}
  end
  plane("bottom", {lo[1], lo[2], lo[3]}, {0, 0, 1})
  if not o.open_top then plane("top", {hi[1], hi[2], hi[3]}, {0, 0, -1}) end
  plane("x_min", {lo[1], lo[2], lo[3]}, {1, 0, 0})
  plane("x_max", {hi[1], hi[2], hi[3]}, {-1, 0, 0})
  plane("y_min", {lo[1], lo[2], lo[3]}, {0, 1, 0})
  plane("y_max", {hi[1], hi[2], hi[3]}, {0, -1, 0})
  return ids
end

return M
