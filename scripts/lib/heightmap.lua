-- A triangle mesh from a height map (e.g. a generated rough surface), for world:add_mesh.
--
--   local heightmap = require("heightmap")
--   local mesh = heightmap.mesh{heights = h, nx = 64, ny = 64, dx = 0.01, dy = 0.01,
--                               origin = {0, 0, 0}}
--   world:add_mesh{vertices = mesh.vertices, triangles = mesh.triangles}
--
-- heights: nx * ny values, row after row (x fastest), as a table or an asperity.Array. Each
-- grid cell becomes two triangles. Vertices go into an Array, built in one bulk call.
local M = {}

function M.mesh(o)
  local nx, ny, h = o.nx, o.ny, o.heights
  assert(nx and ny and nx >= 2 and ny >= 2, "heightmap.mesh: nx, ny >= 2 required")
  local dx, dy = o.dx or 1, o.dy or o.dx or 1
  local origin = o.origin or {0, 0, 0}
  if #h ~= nx * ny then error(("heightmap.mesh: %d heights given, nx * ny = %d"):format(#h, nx * ny), 2) end
  local v = asperity.array(nx * ny, 3)
  for j = 0, ny - 1 do
    for i = 0, nx - 1 do
      local k = j * nx + i + 1
      v[k] = {origin[1] + i * dx, origin[2] + j * dy, origin[3] + h[k]}
    end
  end
  local tris = {}
  for j = 0, ny - 2 do
    for i = 0, nx - 2 do
      local a = j * nx + i + 1
      local b, c, d = a + 1, a + nx, a + nx + 1
      tris[#tris + 1] = {a, b, d}
      tris[#tris + 1] = {a, d, c}
    end
  end
  return {vertices = v, triangles = tris}
end

return M
