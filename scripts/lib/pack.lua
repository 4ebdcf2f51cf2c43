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
--
--   local r = require("radii").truncated_gaussian{count = 935, mean = 0.5e-3, sd = 0.1e-3, seed = 1}
--   local box = require("walls").box(world, {min = {0,0,0}, max = {0.01,0.01,0.01}})
--   local res = pack.expand(world, {min = {0,0,0}, max = {0.01,0.01,0.01}, radii = r, seed = 1,
--                                   walls = box})
--
-- expand: radius-expansion packing [thesis 3.3; scenarios.md 1]. The centres are placed at random
-- in the region (the box min..max, cut by `inside(x, y, z, r)` if given, e.g. the side of a mould),
-- not overlapping one another at the initial radii (the final ones times initial_scale, 1/10);
-- then the radii grow in `stages` (40) equal factors, cycling `stage_steps` (250) steps after each
-- (small steps: a light particle squeezed by a large growth step is shot away), with a Verlet
-- skin of 0.8 final mean radii (an automatic skin follows the growing radii, and at a tenth of
-- them a step's travel exceeds it: a neighbour build every 3-4 steps, against every 17 with this
-- one; the world's own skin, if set, is kept); then the assembly cycles until the
-- unbalanced-force ratio (mean unbalanced / mean contact force, PFC's) is below `ratio` (1e-4).
-- The region must be closed by walls the caller made. Returns {first, last, steps, ratio, seconds,
-- porosity_nominal, porosity_true, mean_radius, contacts, coordination, wall_stress (with `walls`
-- from walls.box: name -> Pa, compression positive)}.
-- The porosities refer to the box volume unless `volume` is given (a region cut by a mould).
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

local function box_volume(lo, hi) return (hi[1] - lo[1]) * (hi[2] - lo[2]) * (hi[3] - lo[3]) end

-- Random centres for `radii` (already scaled) in the box lo..hi, accepted by inside(x, y, z, r),
-- without overlaps among themselves (a hash grid keeps it linear).
local function place(radii, lo, hi, inside, rng, attempts)
  local rmax = 0
  for i = 1, #radii do rmax = math.max(rmax, radii[i]) end
  local cell = 2 * rmax
  local grid, xyz = {}, {}
  local function key(i, j, k) return (i * 4096 + j) * 4096 + k end
  for n = 1, #radii do
    local r = radii[n]
    local placed = false
    for _ = 1, attempts do
      local x = rng:uniform(lo[1] + r, hi[1] - r)
      local y = rng:uniform(lo[2] + r, hi[2] - r)
      local z = rng:uniform(lo[3] + r, hi[3] - r)
      if not inside or inside(x, y, z, r) then
        local ci, cj, ck = (x - lo[1]) // cell, (y - lo[2]) // cell, (z - lo[3]) // cell
        local free = true
        for di = -1, 1 do
          for dj = -1, 1 do
            for dk = -1, 1 do
              local list = grid[key(ci + di, cj + dj, ck + dk)]
              if list then
                for _, m in ipairs(list) do
                  local dx, dy, dz = xyz[3 * m - 2] - x, xyz[3 * m - 1] - y, xyz[3 * m] - z
                  if dx * dx + dy * dy + dz * dz < (radii[m] + r) ^ 2 then free = false break end
                end
              end
              if not free then break end
            end
            if not free then break end
          end
          if not free then break end
        end
        if free then
          xyz[3 * n - 2], xyz[3 * n - 1], xyz[3 * n] = x, y, z
          local k = key(ci, cj, ck)
          grid[k] = grid[k] or {}
          table.insert(grid[k], n)
          placed = true
          break
        end
      end
    end
    if not placed then
      error(("pack.expand: no room for particle %d of %d after %d attempts (region too small or initial_scale too large)"):format(n, #radii, attempts), 3)
    end
  end
  return xyz
end

-- Stresses on the walls of walls.box (name -> Pa, compression positive): |force . normal| / area.
function M.box_wall_stresses(world, box, lo, hi)
  local L = {hi[1] - lo[1], hi[2] - lo[2], hi[3] - lo[3]}
  local area = {x_min = L[2] * L[3], x_max = L[2] * L[3], y_min = L[1] * L[3], y_max = L[1] * L[3],
                bottom = L[1] * L[2], top = L[1] * L[2]}
  local axis = {x_min = "x", x_max = "x", y_min = "y", y_max = "y", bottom = "z", top = "z"}
  local out = {}
  for name, id in pairs(box) do
    if area[name] then out[name] = math.abs(world:wall_force(id)[axis[name]]) / area[name] end
  end
  return out
end

-- After radii change, the engine's time-step estimate at the next neighbour rebuild still counts
-- the contacts (overlaps) of the old radii, so a sudden growth that creates many new contacts runs
-- for up to dt_interval steps above the critical step. One step computes the new overlaps;
-- set_dt(0) then forces a fresh estimate before the next one.
function M.refresh_dt(world)
  world:cycle(1)
  if world:settings().dt == 0 then world:set_dt(0) end
end

-- The mass floor (model.md 3): the particles `ids` whose radius (radii[k] for ids[k], or their
-- current one) is below `floor` weigh as a sphere of radius `floor`: their density is raised by
-- (floor / R)^3 (set_radius keeps densities). The lightest particles set the critical time step
-- [3-30]; where the motion is quasi-static they need not be that light. Returns the mass added and
-- the particles' mass before.
function M.floor_masses(world, ids, floor, radii)
  local added, total = 0, 0
  for k, id in ipairs(ids) do
    local r, m = radii and radii[k] or world:radius(id), world:mass(id)
    total = total + m
    if r < floor then
      world:set_density(id, world:density(id) * (floor / r) ^ 3)
      added = added + world:mass(id) - m
    end
  end
  return added, total
end

function M.expand(world, o)
  local known = {min = true, max = true, inside = true, radii = true, seed = true, rng = true,
                 initial_scale = true, stages = true, stage_steps = true, ratio = true,
                 max_steps = true, walls = true, volume = true, density = true, attempts = true,
                 progress = true, mass_floor = true}
  for k in pairs(o) do
    if not known[k] then error("pack.expand: unknown option '" .. tostring(k) .. "'", 2) end
  end
  assert(o.min and o.max and o.radii, "pack.expand: min, max and radii are required")
  local t0 = asperity.wall_time()
  local rng = o.rng or require("random").new(o.seed or 1)
  local s0 = o.initial_scale or 0.1
  local stages = o.stages or 40
  local final = o.radii
  local small = {}
  for i = 1, #final do small[i] = final[i] * s0 end
  local xyz = place(small, o.min, o.max, o.inside, rng, o.attempts or 1000)
  local before = world:particle_count()
  local first, last = world:add_particles(xyz, small, o.density)
  -- `mass_floor` (m), on the final radii: a quasi-static packing ends in an equilibrium that
  -- masses do not enter, so the caller restores the densities once it is packed.
  if o.mass_floor and o.mass_floor > 0 then
    local ids = {}
    for i = 1, #final do ids[i] = first + i - 1 end
    M.floor_masses(world, ids, o.mass_floor, final)
  end
  local alone = before == 0   -- the world holds only these particles: scale_radii does it at once
  local automatic_skin = world:settings().skin == 0
  if automatic_skin then
    local sum = 0
    for i = 1, #final do sum = sum + final[i] end
    world:set_skin(0.8 * sum / #final)
  end
  local steps = 0
  local factor = (1 / s0) ^ (1 / stages)
  for stage = 1, stages do
    local scale = s0 * factor ^ stage
    if stage == stages then scale = 1 end
    if alone then
      world:scale_radii(scale / (s0 * factor ^ (stage - 1)))
    end
    -- set every radius exactly (no drift from repeated products)
    for i = 1, #final do world:set_radius(first + i - 1, final[i] * scale) end
    M.refresh_dt(world)
    steps = steps + 1 + world:cycle((o.stage_steps or 250) - 1)
  end
  if automatic_skin then world:set_skin(0) end
  -- Below jamming the particles end without contacts: no ratio (infinite), stop there too.
  local why = "steps"
  local n = world:run{steps = o.max_steps or 1000000, every = 100, progress = o.progress,
    stop_when = function(w)
      if w:unbalanced_force_ratio() <= (o.ratio or 1e-4) then why = "equilibrium" return true end
      if w:contact_count() == 0 and w:stats().wall_contacts == 0 then why = "no contacts" return true end
    end}
  steps = steps + n
  local volume = o.volume or box_volume(o.min, o.max)
  local rtab = {}
  for i = 1, #final do rtab[i] = final[i] end
  local nominal, true_n, mean = require("radii").porosity(rtab, volume)
  local contacts = world:contact_count()
  local res = {first = first, last = last, count = #final, steps = steps, reached = why == "equilibrium",
               jammed = why ~= "no contacts",
               ratio = world:unbalanced_force_ratio(), seconds = asperity.wall_time() - t0,
               porosity_nominal = nominal, porosity_true = true_n, mean_radius = mean,
               contacts = contacts, coordination = 2 * contacts / #final}
  if o.walls then res.wall_stress = M.box_wall_stresses(world, o.walls, o.min, o.max) end
  return res
end

-- Multiply the radii of particles first..last by `factor` (all at once with scale_radii when they are
-- the whole world, which also re-derives the neighbour skin), then refresh the time step.
function M.scale(world, first, last, factor)
  if first == 1 and last == world:particle_count() then
    world:scale_radii(factor)
  else
    for id = first, last do world:set_radius(id, world:radius(id) * factor) end
  end
  M.refresh_dt(world)
end

-- Mean of box_wall_stresses over the walls of `box` (Pa).
-- Summed in a fixed order: pairs() visits string keys in an order that Lua 5.4 seeds per process,
-- which made the last digit of the mean (and the REV's stress installation, which compares it
-- with its target) differ between two runs of the same script.
local BOX_FACES = {"x_min", "x_max", "y_min", "y_max", "bottom", "top"}
function M.mean_box_wall_stress(world, box, lo, hi)
  local stresses = M.box_wall_stresses(world, box, lo, hi)
  local s, n = 0, 0
  for _, name in ipairs(BOX_FACES) do
    if stresses[name] then s, n = s + stresses[name], n + 1 end
  end
  return s / n
end

-- Isotropic stress installation (as in PFC's bonded-particle genesis, Potyondy & Cundall 2004):
-- after the expansion, scale the radii of first..last by a common factor until the mean stress on
-- the box walls is `target` (Pa) within `tolerance` (relative), cycling to equilibrium after each
-- change. A packing just above jamming carries a stress that is very sensitive to its density (a
-- radius change of 0.4 % takes a 1 cm REV from 0.3 Pa to nothing), and the expansion may end on
-- either side; so the factor is first bracketed (steps growing from `step`, 0.1 %) and then found
-- by bisection. The stress locked into the packing becomes internal bond stress when the walls go.
-- Returns {factor, stress, iterations, steps, reached}; the porosity changes by factor^3.
function M.install_stress(world, o)
  local known = {first = true, last = true, walls = true, min = true, max = true, target = true,
                 tolerance = true, ratio = true, max_steps = true, iterations = true, step = true,
                 measure = true}
  for k in pairs(o) do
    if not known[k] then error("pack.install_stress: unknown option '" .. tostring(k) .. "'", 2) end
  end
  local lo, hi, box = o.min, o.max, o.walls
  local measure = o.measure or function() return M.mean_box_wall_stress(world, box, lo, hi) end
  local target, tol = o.target, o.tolerance or 0.2
  local steps, iterations = 0, 0
  local f_now = 1
  local function stress_at(f)
    if f ~= f_now then
      M.scale(world, o.first, o.last, f / f_now)
      f_now = f
    end
    -- A packing without contacts has no equilibrium ratio (infinite): stop there too.
    local n = world:run{steps = o.max_steps or 200000, every = 100, stop_when = function(w)
      return w:unbalanced_force_ratio() <= (o.ratio or 1e-4) or
             (w:contact_count() == 0 and w:stats().wall_contacts == 0)
    end}
    steps = steps + n
    iterations = iterations + 1
    return measure()
  end
  local function good(p) return math.abs(p - target) <= tol * target end
  local p = stress_at(1)
  local f_lo, f_hi, p_lo, p_hi   -- stress below / above the target
  local step = o.step or 1e-3
  if p > target then f_hi, p_hi = 1, p else f_lo, p_lo = 1, p end
  local max_it = o.iterations or 30
  while not good(p) and not (f_lo and f_hi) and iterations < max_it do   -- bracket
    local f = f_lo and not f_hi and f_lo * (1 + step) or f_hi * (1 - step)
    step = step * 2
    p = stress_at(f)
    if p > target then f_hi, p_hi = f, p else f_lo, p_lo = f, p end
  end
  -- Above jamming the stress of a packing grows about linearly with the radius factor: where both
  -- ends of the bracket carry stress, the line through them finds the target in a few steps
  -- (regula falsi, halving the weight of an end kept twice: Illinois). Below jamming (no stress at
  -- the lower end) the line says nothing: bisection.
  local kept_side
  while not good(p) and iterations < max_it and f_hi - f_lo > 1e-7 do
    local f
    if p_lo > 0 then
      f = f_lo + (target - p_lo) * (f_hi - f_lo) / (p_hi - p_lo)
      if not (f > f_lo and f < f_hi) then f = 0.5 * (f_lo + f_hi) end
    else
      f = 0.5 * (f_lo + f_hi)
    end
    p = stress_at(f)
    if p > target then
      f_hi, p_hi = f, p
      if kept_side == "lo" and p_lo > 0 then p_lo = 0.5 * (p_lo + target) end
      kept_side = "lo"
    else
      f_lo, p_lo = f, p
      if kept_side == "hi" then p_hi = 0.5 * (p_hi + target) end
      kept_side = "hi"
    end
  end
  return {factor = f_now, stress = p, iterations = iterations, steps = steps, reached = good(p)}
end

return M
