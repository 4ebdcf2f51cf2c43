-- Placing particles.
--
--   local pack = require("pack")
--   local first, last = pack.grid(world, {min = {0,0,0}, max = {1,1,1}, count = 400,
--                                         radius = 0.01, spread = 0.2, seed = 1})
--
-- grid: `count` spheres on a simple cubic lattice filling the box from the bottom, pitch
-- 2 * rmax * (1 + gap) with rmax = radius * (1 + spread), so that no two overlap; radii uniform
-- in radius * [1 - spread, 1 + spread]. Each centre is shifted at random by up to the free room
-- (jitter = true, the default) so the particles do not stand in columns when they fall.
-- All added in one bulk call.
local M = {}

function M.grid(world, o)
  for k in pairs(o) do
    if not ({min = true, max = true, count = true, radius = true, spread = true, seed = true,
             density = true, gap = true, jitter = true})[k] then
      error("pack.grid: unknown option '" .. tostring(k) .. "'", 2)
    end
  end
  local lo, hi, r = o.min, o.max, o.radius
  local spread = o.spread or 0
  local rmax = r * (1 + spread)
  local pitch = 2 * rmax * (1 + (o.gap or 0.05))
  local room = o.jitter == false and 0 or (pitch / 2 - rmax)
  local nx = math.floor((hi[1] - lo[1]) / pitch)
  local ny = math.floor((hi[2] - lo[2]) / pitch)
  local nz = math.floor((hi[3] - lo[3]) / pitch)
  local capacity = nx * ny * nz
  if o.count > capacity then
    error(("pack.grid: %d particles of radius %g do not fit (at most %d)"):format(o.count, rmax, capacity), 2)
  end
  math.randomseed(o.seed or 1)
  local xyz, radii = {}, {}
  local n = 0
  for k = 0, nz - 1 do
    for j = 0, ny - 1 do
      for i = 0, nx - 1 do
        if n == o.count then break end
        n = n + 1
        local function shift() return room * (2 * math.random() - 1) end
        xyz[#xyz + 1] = lo[1] + (i + 0.5) * pitch + shift()
        xyz[#xyz + 1] = lo[2] + (j + 0.5) * pitch + shift()
        xyz[#xyz + 1] = lo[3] + (k + 0.5) * pitch + shift()
        radii[n] = r * (1 + spread * (2 * math.random() - 1))
      end
    end
  end
  return world:add_particles(xyz, radii, o.density)
end

return M
