-- The genesis of a joint's two halves (scripts/joint.lua): the surface, both halves packed, bonded
-- and relaxed in its mould, cached on disk.
--
--   local genesis = require("joint.genesis")
--   run.surface = genesis.surface(run.P)   -- the height map and the mould
--   if not genesis.specimen(run) then ... end   -- run.world, run.genesis_record; false: stop_after
--
-- surface: generated (S1..S8, surfaces.md table 4), a plane (`flat`), or loaded (`surface_file`),
-- on an odd grid of `spacing` over `size`.
-- specimen: both halves are made by the REV's genesis (lib/genesis.lua, scenarios.md 1) in one box
-- split by the mould, so the joint is made of the material the REV calibrates. Each half is bonded
-- on its own (never across the mould), unbreakable while prepared; the walls are removed, the
-- halves parted by `gap` and relaxed [scenarios.md 3.3]. The specimen is cached under a key of
-- everything that shaped it, so the three models and both directions reuse it.
local mat = require("materials")
local radii_lib = require("radii")
local genesis = require("genesis")
local heightmap = require("heightmap")
local context = require("joint.context")

local LOWER, UPPER, LOST = context.LOWER, context.UPPER, context.LOST

local M = {}

-- The surface: returns {map, n, nx, ny, h, Lx, Ly, heights, z}, z(x, y) the mould's height.
function M.surface(P)
  local n = 2 * math.floor(P.size / P.spacing / 2) + 1     -- odd grid
  local map
  if P.surface_file ~= "" then
    map = asperity.surface.load(P.surface_file)
  elseif P.surface == "flat" then
    local zeros = {}
    for k = 1, n * n do zeros[k] = 0.0 end
    map = asperity.surface.height_map{heights = zeros, spacing = P.spacing, nx = n}
  else
    map = asperity.surface.generate{name = P.surface, n = n, side = n * P.spacing, seed = P.seed}
  end
  local nx, ny = map:size()
  local h = map:spacing()
  local heights = {}
  for j = 1, ny do for i = 1, nx do heights[#heights + 1] = map:at(i, j) end end
  local function z_at(x, y)                                -- the mould, bilinear in each cell
    local fi, fj = x / h, y / h
    local i, j = math.max(0, math.min(nx - 2, math.floor(fi))), math.max(0, math.min(ny - 2, math.floor(fj)))
    local u, v = fi - i, fj - j
    local function z(a, b) return heights[(j + b) * nx + (i + a) + 1] end
    return (1 - u) * (1 - v) * z(0, 0) + u * (1 - v) * z(1, 0) + (1 - u) * v * z(0, 1) + u * v * z(1, 1)
  end
  -- the mesh spans (n - 1) spacings
  return {map = map, n = n, nx = nx, ny = ny, h = h, Lx = (nx - 1) * h, Ly = (ny - 1) * h,
          heights = heights, z = z_at}
end

-- The cache file of the specimen, keyed by everything that shaped it.
local function cache_file(P, s)
  local key = ("%s_%s_n%d_h%.6g_T%.6g_p%.4g_s%d_g%.6g_k%d_gs%.4g_fc%d_l%d_b%.4g_%.4g_gap%.4g"):format(
    P.surface_file ~= "" and P.surface_file:gsub("[^%w]", "_") or P.surface, mat.genesis.grow_floaters and "v12" or "v8", s.n, s.h, P.thickness,
    P.porosity, P.seed, P.gap, P.pack_steps, P.genesis_stress, mat.genesis.floater_contacts,
    mat.rev.rotation_lock_bonds, mat.rev.bond_shear_ratio, mat.rev.bond_radius_factor, P.bond_gap)
    .. (mat.rev.bond_normal_stiffness ~= 1 and ("_kb%.4g"):format(mat.rev.bond_normal_stiffness) or "")
    .. (P.wall_friction ~= 0 and ("_f%.3g"):format(P.wall_friction) or "")
    .. (P.genesis_shrink_gain ~= 1 and ("_sg%.3g"):format(P.genesis_shrink_gain) or "")
    .. (P.genesis_mass_floor ~= 0 and ("_mf%.3g"):format(P.genesis_mass_floor) or "")
    .. (P.genesis_damping ~= mat.damping and ("_gd%.3g"):format(P.genesis_damping) or "")
  return P.cache .. "/joint_" .. key .. ".h5"
end

-- Packs, bonds and relaxes both halves and caches them; returns the world and the genesis record,
-- or nil and a short record with stop_after=packing.
local function build(run)
  local P, s = run.P, run.surface
  local Lx, Ly, T, surface_z = s.Lx, s.Ly, P.thickness, s.z
  local function log(fmt, ...) run:log(fmt, ...) end
  -- Results do not depend on the thread count, so the genesis may use more cores than the shear.
  local threads = P.genesis_threads > 0 and P.genesis_threads or P.threads
  local w = asperity.world{material = mat.contact, damping = mat.damping, density = mat.density,
                           threads = threads, rotation_lock_bonds = mat.rev.rotation_lock_bonds}
  -- Boxes: sides, floor of the lower half, roof of the upper one; the mould between them. Made here
  -- rather than by lib/walls.lua, whose box adds the same planes in another order and through other
  -- points: the cached checkpoint keeps the walls as they were added, so its file would change.
  local wm = {kn = mat.contact.kn, ks = mat.contact.ks, friction = P.wall_friction}
  local planes = {
    w:add_plane{point = {0, 0, 0}, normal = {1, 0, 0}, material = wm},
    w:add_plane{point = {Lx, 0, 0}, normal = {-1, 0, 0}, material = wm},
    w:add_plane{point = {0, 0, 0}, normal = {0, 1, 0}, material = wm},
    w:add_plane{point = {0, Ly, 0}, normal = {0, -1, 0}, material = wm},
    w:add_plane{point = {0, 0, -T}, normal = {0, 0, 1}, material = wm},
    w:add_plane{point = {0, 0, T}, normal = {0, 0, -1}, material = wm},
  }
  local box = {x_min = planes[1], x_max = planes[2], y_min = planes[3], y_max = planes[4],
               bottom = planes[5], top = planes[6]}
  local mesh = heightmap.mesh{heights = s.heights, nx = s.nx, ny = s.ny, dx = s.h, dy = s.h, origin = {0, 0, 0}}
  local mould = w:add_mesh{vertices = mesh.vertices, triangles = mesh.triangles, material = wm}
  -- Particle count from the thesis porosity definition [3-35, 3-36] over both halves.
  local volume = Lx * Ly * 2 * T
  local count = radii_lib.count_for_porosity{volume = volume, porosity = P.porosity,
                                             mean_radius = mat.packing.mean_radius}
  local r = radii_lib.truncated_gaussian{count = count, mean = mat.packing.mean_radius,
                                         sd = mat.packing.radius_sd, seed = P.seed, normalise_mean = true}
  log("genesis of %d particles in two halves of %.1f x %.1f mm (surface %s, %d x %d grid)", count,
      Lx * 1e3, Ly * 1e3, P.surface_file ~= "" and P.surface_file or P.surface, s.nx, s.ny)
  local lo, hi = {0, 0, -T}, {Lx, Ly, T}   -- the box of both halves
  local g = genesis.pack(w, {min = lo, max = hi, radii = r, seed = P.seed, box = box, volume = volume,
                             stress = P.genesis_stress, friction = mat.contact.friction,
                             min_contacts = mat.genesis.floater_contacts, floater_tag = LOST,
                             grow_floaters = mat.genesis.grow_floaters, shrink_gain = P.genesis_shrink_gain,
                             mass_floor = P.genesis_mass_floor, damping = P.genesis_damping,
                             progress = P.progress, max_steps = P.pack_steps,
                             log = log,
                             split = function(x, y, z) return z < surface_z(x, y) and 1 or 2 end,
                             sets_count = 2,   -- each half gets its own radius factor
                             wall_contacts = function(x, y, z, rad)
                               local n = 0
                               if x < rad then n = n + 1 end
                               if Lx - x < rad then n = n + 1 end
                               if y < rad then n = n + 1 end
                               if Ly - y < rad then n = n + 1 end
                               if z + T < rad or T - z < rad then n = n + 1 end
                               -- the mould, by the vertical distance (a slope only makes it nearer)
                               if math.abs(z - surface_z(x, y)) < rad then n = n + 1 end
                               return n
                             end,
                             inside = function(x, y, z, rad)
                               local sz = surface_z(x, y)
                               return z + rad < sz - rad or z - rad > sz + rad
                             end,
                             -- away from the mould too, by the vertical distance, as above
                             interior = function(x, y, z, m) return math.abs(z - surface_z(x, y)) >= m end})
  if P.stop_after == "packing" then
    if P.save ~= "" then
      w:save(P.save)
      log("stopped after packing (stop_after): saved the packed world to %s", P.save)
    else
      log("stopped after packing (stop_after); nothing saved (give save=FILE to keep the world)")
    end
    return nil, {stopped_after = "packing", particles = w:particle_count(), steps = g.steps,
                 porosity_nominal = g.porosity_nominal, porosity_true = g.porosity_true,
                 seconds = g.seconds, saved = P.save ~= "" and P.save or nil}
  end
  -- Halves by side of the mould; tags 1 (lower) and 2 (upper). A particle squeezed out of the
  -- box during the compaction belongs to neither half.
  local pos = w:positions()
  local lower, upper, lost = {}, {}, {}
  local slack = 1e-9
  for _, id in ipairs(g.kept) do
    local p = pos[id]
    if p[1] < -slack or p[1] > Lx + slack or p[2] < -slack or p[2] > Ly + slack
       or p[3] < -T - slack or p[3] > T + slack then
      lost[#lost + 1] = id
    elseif p[3] < surface_z(p[1], p[2]) then lower[#lower + 1] = id else upper[#upper + 1] = id end
  end
  w:set_tag(lower, LOWER)
  w:set_tag(upper, UPPER)
  -- Bond each half on its own (never across the mould), unbreakable while prepared; remove the
  -- walls, part the halves by `gap`, relax [scenarios.md 3.3].
  local bond_material = mat.bond{breakable = false}
  if P.bond_gap > 0 then bond_material.tolerance = P.bond_gap end
  local walls_list = {mould}
  for _, id in ipairs(planes) do walls_list[#walls_list + 1] = id end
  local b = genesis.bond(w, {sets = {lower, upper}, material = bond_material, walls = walls_list, steps = 200000,
                             tensile_strength = mat.rev.bond_tensile_strength, progress = P.progress,
                             log = log,
                             before_relax = function(w)
    -- Particles of a half without a bond carry nothing and would drift off: made inert (neither
    -- integrated nor searched) and tagged LOST, like those squeezed out, so no half, platen or
    -- measure counts them.
    local bonded, across = {}, 0
    for _, bd in ipairs(w:bonds{fields = {"a", "b"}}) do
      bonded[bd.a], bonded[bd.b] = true, true
      if w:tag(bd.a) ~= w:tag(bd.b) then across = across + 1 end
    end
    if across > 0 then  -- the halves would be glued together: no joint to shear
      error(("%d bonds join the lower and the upper half: the specimen is not two halves"):format(across), 0)
    end
    local function keep(list)
      local kept = {}
      for _, id in ipairs(list) do
        if bonded[id] then kept[#kept + 1] = id else lost[#lost + 1] = id end
      end
      return kept
    end
    lower, upper = keep(lower), keep(upper)
    if #lost > 0 then
      w:set_tag(lost, LOST)
      w:add_group(lost, {translation = "fixed"})   -- inert particles must belong to a rigid body
      w:set_inert(lost)
    end
    for _, id in ipairs(upper) do
      local p = w:position(id)
      w:set_position(id, {p[1], p[2], p[3] + P.gap})
    end
  end})
  log("%d particles left out (floaters without a place %d; outside the box or without a bond %d); %d floaters placed",
      g.floaters_removed + #lost, g.floaters_removed, #lost, g.floaters_grown)
  w:save(run.cache_file)
  local record = {particles = w:particle_count(), lower = #lower, upper = #upper,
    left_out = g.floaters_removed + #lost, floaters_removed = g.floaters_removed, floaters_grown = g.floaters_grown,
    floater_share = g.floater_share, bonds = b.bonds,
    porosity_nominal = g.porosity_nominal, porosity_true = g.porosity_true, mean_radius = g.mean_radius,
    coordination = g.coordination, interior = g.interior, genesis_stress_pa = g.stress_pa, genesis_stress_target_pa = P.genesis_stress,
    genesis_stress_reached = g.stress_reached, radius_factor = g.radius_factor, genesis_steps = g.steps,
    genesis_seconds = g.seconds, relax_steps = b.relax_steps, relax_reached = b.relax_reached,
    bonds_broken_in_relaxation = b.broken_in_relaxation, bond_stress = b.bond_stress,
    bond_stress_max_over_st = b.bond_stress_max_over_st, bond_stress_p999_over_st = b.bond_stress_p999_over_st,
    defined_state = b.defined_state,
    wall_stress_pa = g.wall_stress_pa}
  asperity.write_json(run.cache_file .. ".json", record)
  local f = assert(io.open(run.cache_file .. ".lua.tmp", "w"))
  f:write("return " .. genesis.serialise(record) .. "\n")
  f:close()
  os.rename(run.cache_file .. ".lua.tmp", run.cache_file .. ".lua")
  return w, record
end

-- The specimen of run.surface, from the cache or built (and cached): sets run.cache_file,
-- run.world, run.genesis_record, run.specimen_packed (built by this run) and run.specimen_seconds
-- (packing, bonding and relaxing; or loading) and returns true; with stop_after=packing, sets the short
-- record and returns false.
function M.specimen(run)
  local P = run.P
  local t0 = asperity.wall_time()
  run.cache_file = cache_file(P, run.surface)
  -- The record is written last: a specimen without one was cut short and is built again.
  local f = io.open(run.cache_file .. ".lua", "r")
  if f then
    f:close()
    if P.stop_after == "packing" then
      error(("stop_after=packing needs a packing, but the specimen is cached (%s): give another cache="):format(
        run.cache_file), 0)
    end
    run:log("reusing the cached specimen %s", run.cache_file)
    run.world = asperity.load(run.cache_file, {threads = P.threads, simd = P.simd})
    run.genesis_record = dofile(run.cache_file .. ".lua")
    run.specimen_packed, run.specimen_seconds = false, asperity.wall_time() - t0
    return true
  end
  run.world, run.genesis_record = build(run)
  if not run.world then return false end   -- stop_after = "packing"
  run.specimen_packed, run.specimen_seconds = true, asperity.wall_time() - t0
  if P.simd ~= "auto" then
    run.world = asperity.load(run.cache_file, {threads = P.threads, simd = P.simd})
  else
    run.world:set_threads(P.threads)
  end
  return true
end

return M
