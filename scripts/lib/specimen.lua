-- A specimen between two platens, and what is measured on it [thesis 3.3.1, 3-38..3-44].
--
--   local specimen = require("specimen")
--   local ext = specimen.extent(world)                        -- {min = {..}, max = {..}}
--   local pl = specimen.platens(world, {thickness = 1e-3})    -- bottom fixed, top fixed for now
--   world:set_group_velocity(pl.top, {0, 0, -1e-6})           -- compression
--   local meter = specimen.strain_meter(world, specimen.gauges(world, {extent = ext, platens = pl}))
--   local e = meter:read(world)      -- axial, x, y, lateral, shear_xz, shear_xz_layers
--   local s = specimen.stresses(world, pl, L * L)   -- axial (tension +), shear_x (along +x)
--
-- Platens: the particles whose centres lie within `thickness` of the bottom (top) face of the
-- specimen form one rigid group each, rotation fixed, translation fixed until a script moves them.
-- The faces are those of the particles' bounding box (centre +- radius).
--
-- Gauges (sets of particle ids, platen members excluded): `lower` and `upper`, the particles whose
-- centres lie within layer/2 of 1/4 and 3/4 of the height; `x_min`, `x_max`, `y_min`, `y_max`, the
-- particles within `face` of the lateral faces and between those two heights (the middle slab, away
-- from the platens' end restraint). Particles without a bond are left out (bonded_only = false keeps
-- them).
--
-- Strains (extension positive) from mean positions relative to the state when the meter was made:
--   axial     = change of (mean z upper - mean z lower) / its initial value            [3-38]
--   x, y      = change of (mean x of x_max - mean x of x_min) / its initial value (y alike) [3-39, 3-40]
--   lateral   = (x + y) / 2                                                          [3-41]
--   shear_xz_layers = change of (mean x upper - mean x lower) / (initial z distance)  [3-42]
--   shear_xz  = shear_xz_layers + change of (mean z of x_max - mean z of x_min) / (initial x
--               distance): the engineering shear strain du_x/dz + du_z/dx averaged over the middle
--               slab. A cube sheared by its platens also bends; the bending turns horizontal
--               lines (du_x/dz) as much as it turns vertical ones the other way (du_z/dx), so only
--               the sum is the shear strain that tau = G gamma relates to the mean shear stress
--               Fx / L^2 (which is exact on every horizontal section).
local M = {}

local function all_ids(world)
  local ids = {}
  for id = 1, world:particle_count() do ids[id] = id end
  return ids
end

-- Bounding box of the particles (centre +- radius), of `ids` or all.
function M.extent(world, ids)
  ids = ids or all_ids(world)
  local pos, rad = world:positions(), world:radii()
  local lo, hi = {math.huge, math.huge, math.huge}, {-math.huge, -math.huge, -math.huge}
  for _, id in ipairs(ids) do
    local r = rad:get(id)
    for k = 1, 3 do
      local x = pos:get(id, k)
      lo[k] = math.min(lo[k], x - r)
      hi[k] = math.max(hi[k], x + r)
    end
  end
  return {min = lo, max = hi}
end

function M.platens(world, o)
  o = o or {}
  for k in pairs(o) do
    if not ({thickness = true, ids = true, extent = true})[k] then
      error("specimen.platens: unknown option '" .. tostring(k) .. "' (thickness, ids, extent)", 2)
    end
  end
  local ids = o.ids or all_ids(world)
  local ext = o.extent or M.extent(world, ids)
  local t = o.thickness or 1e-3
  local pos = world:positions()
  local bottom, top = {}, {}
  for _, id in ipairs(ids) do
    local z = pos:get(id, 3)
    if z - ext.min[3] < t then bottom[#bottom + 1] = id
    elseif ext.max[3] - z < t then top[#top + 1] = id end
  end
  local fixed = {translation = "fixed", rotation = "fixed"}
  return {bottom = world:add_group(bottom, fixed), top = world:add_group(top, fixed),
          bottom_ids = bottom, top_ids = top, extent = ext}
end

function M.gauges(world, o)
  local ext = o.extent or M.extent(world)
  local layer, face = o.layer or 1e-3, o.face or 1e-3
  local skip = {}
  if o.platens then
    for _, id in ipairs(o.platens.bottom_ids) do skip[id] = true end
    for _, id in ipairs(o.platens.top_ids) do skip[id] = true end
  end
  -- A particle without a bond (a "floater" of the packing) does not follow the deformation of the
  -- bonded skeleton: it does not count.
  if world:bond_count() > 0 and o.bonded_only ~= false then
    local bonded = {}
    for _, b in ipairs(world:bonds{fields = {"a", "b"}}) do bonded[b.a], bonded[b.b] = true, true end
    for id = 1, world:particle_count() do
      if not bonded[id] then skip[id] = true end
    end
  end
  local z0, h = ext.min[3], ext.max[3] - ext.min[3]
  local zl, zu = z0 + h / 4, z0 + 3 * h / 4
  local g = {lower = {}, upper = {}, x_min = {}, x_max = {}, y_min = {}, y_max = {}}
  local pos = world:positions()
  for id = 1, world:particle_count() do
    if not skip[id] then
      local x, y, z = pos:row(id)
      if math.abs(z - zl) <= layer / 2 then table.insert(g.lower, id) end
      if math.abs(z - zu) <= layer / 2 then table.insert(g.upper, id) end
      if z >= zl and z <= zu then
        if x - ext.min[1] < face then table.insert(g.x_min, id) end
        if ext.max[1] - x < face then table.insert(g.x_max, id) end
        if y - ext.min[2] < face then table.insert(g.y_min, id) end
        if ext.max[2] - y < face then table.insert(g.y_max, id) end
      end
    end
  end
  for name, set in pairs(g) do
    assert(#set > 0, "specimen.gauges: the " .. name .. " set is empty (specimen too small?)")
  end
  return g
end

local function means(pos, set)
  local sx, sy, sz = 0, 0, 0
  for _, id in ipairs(set) do
    local x, y, z = pos:row(id)
    sx, sy, sz = sx + x, sy + y, sz + z
  end
  local n = #set
  return sx / n, sy / n, sz / n
end

local function snapshot(world, g)
  local pos = world:positions()
  local m = {}
  for name, set in pairs(g) do m[name] = {means(pos, set)} end
  return m
end

local Meter = {}
Meter.__index = Meter

function M.strain_meter(world, gauges)
  return setmetatable({gauges = gauges, ref = snapshot(world, gauges)}, Meter)
end

function Meter:read(world)
  local m, r = snapshot(world, self.gauges), self.ref
  local hz0 = r.upper[3] - r.lower[3]
  local wx0 = r.x_max[1] - r.x_min[1]
  local wy0 = r.y_max[2] - r.y_min[2]
  local axial = (m.upper[3] - m.lower[3]) / hz0 - 1
  local ex = (m.x_max[1] - m.x_min[1]) / wx0 - 1
  local ey = (m.y_max[2] - m.y_min[2]) / wy0 - 1
  local layers = ((m.upper[1] - m.lower[1]) - (r.upper[1] - r.lower[1])) / hz0
  local turn = ((m.x_max[3] - m.x_min[3]) - (r.x_max[3] - r.x_min[3])) / wx0
  local layers_y = ((m.upper[2] - m.lower[2]) - (r.upper[2] - r.lower[2])) / hz0
  local turn_y = ((m.y_max[3] - m.y_min[3]) - (r.y_max[3] - r.y_min[3])) / wy0
  return {axial = axial, x = ex, y = ey, lateral = (ex + ey) / 2, shear_xz = layers + turn,
          shear_xz_layers = layers, shear_yz = layers_y + turn_y, shear_yz_layers = layers_y}
end

-- Stresses from the platen forces over `area` (the nominal cross-section L^2 [3-43, 3-44]): the
-- mean of what the top and the bottom platen feel (equal at equilibrium). axial: tension positive;
-- shear_x: the shear stress the specimen carries when the top platen moves along +x.
function M.stresses(world, platens, area)
  local ft, fb = world:group_force(platens.top), world:group_force(platens.bottom)
  return {axial = -(ft.z - fb.z) / 2 / area, shear_x = -(ft.x - fb.x) / 2 / area,
          shear_y = -(ft.y - fb.y) / 2 / area, top = -ft.z / area, bottom = fb.z / area}
end

-- Mean stress tensor (tension positive) of the bonds and contacts whose contact point lies between
-- heights zlo and zhi, over the volume area * (zhi - zlo) (Love-Weber: sigma_ij = -1/V sum F_i l_j,
-- F the force on b, l = x_b - x_a). It is not symmetric when particle rotations are locked: the
-- lock supplies the couples that balance the contact moments. Returns a table s[i][j] (i: force
-- component, j: branch component, 1..3 = x..z).
function M.slab_stress(world, zlo, zhi, area)
  local pos = world:positions()
  local s = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}
  local function add(c, fn, fs)
    if c.point.z < zlo or c.point.z > zhi then return end
    local n = c.normal
    local f = {fn * n.x + fs.x, fn * n.y + fs.y, fn * n.z + fs.z}
    local xa, ya, za = pos:row(c.a)
    local xb, yb, zb = pos:row(c.b)
    local l = {xb - xa, yb - ya, zb - za}
    for i = 1, 3 do
      for j = 1, 3 do s[i][j] = s[i][j] + f[i] * l[j] end
    end
  end
  local fields = {fields = {"a", "b", "point", "normal", "normal_force", "shear_force"}}
  for _, b in ipairs(world:bonds(fields)) do add(b, b.normal_force, b.shear_force) end
  for _, c in ipairs(world:contacts(fields)) do add(c, c.normal_force, c.shear_force) end
  local v = area * (zhi - zlo)
  for i = 1, 3 do
    for j = 1, 3 do s[i][j] = -s[i][j] / v end
  end
  return s
end

-- Least-squares line y = a + b x through the points (xs[i], ys[i]) for which keep(i) holds (all
-- if nil). Returns slope b, intercept a and the coefficient of determination R^2.
function M.fit_line(xs, ys, keep)
  local n, sx, sy, sxx, sxy, syy = 0, 0, 0, 0, 0, 0
  for i = 1, #xs do
    if not keep or keep(i) then
      local x, y = xs[i], ys[i]
      n, sx, sy = n + 1, sx + x, sy + y
      sxx, sxy, syy = sxx + x * x, sxy + x * y, syy + y * y
    end
  end
  assert(n >= 2, "specimen.fit_line: fewer than two points")
  local dxx, dxy, dyy = sxx - sx * sx / n, sxy - sx * sy / n, syy - sy * sy / n
  local b = dxy / dxx
  local r2 = dyy > 0 and (dxy * dxy) / (dxx * dyy) or 1
  return b, (sy - b * sx) / n, r2
end

-- Debris thrown out of a specimen: the particles of no rigid group, not yet tagged `tag`, whose
-- centre lies outside `box` = {min = {x, y, z}, max = {x, y, z}}. A particle freed by bond breaks
-- and thrown clear of every body flies on at constant speed (local damping acts on forces only):
-- it carries nothing, yet its travel triggers the neighbour rebuilds and stretches the cell grid.
-- They are taken out like floaters: tagged `tag`, frozen in a fixed group, inert. Returns their ids.
function M.take_out_escaped(world, box, tag)
  local lo, hi = box.min, box.max
  local X = world:positions()
  local out = {}
  for id = 1, world:particle_count() do
    local p = X[id]
    if (p[1] < lo[1] or p[1] > hi[1] or p[2] < lo[2] or p[2] > hi[2] or p[3] < lo[3] or p[3] > hi[3])
        and world:tag(id) ~= tag and not world:group_of(id) then
      out[#out + 1] = id
    end
  end
  if #out > 0 then
    world:set_tag(out, tag)
    world:add_group(out, {translation = "fixed"})   -- inert particles must belong to a rigid body
    world:set_inert(out)
  end
  return out
end

return M
