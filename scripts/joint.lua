-- A rock joint closed and sheared under constant normal load (scenarios.md 3-6, surfaces.md 3).
--
--   build/asperity run scripts/joint.lua                              -- the default small joint
--   build/asperity run scripts/joint.lua surface=S5 model=rigid stress=21 direction=y
--   build/asperity run scripts/joint.lua scale=thesis                 -- 10 cm x 10 cm
--
-- Steps: generate (or load) the surface; mould it as a triangle mesh between two boxes of plane
-- walls; pack both halves at once by radius expansion (the mould separates them); bond each half
-- (unbreakable while prepared); remove the walls, part the halves by `gap` and relax them; cache
-- the result on disk (keyed by everything that shaped it, so the three models and both
-- directions reuse it); analyse the DEM surfaces (profilometer, mean plane, surface vs porosity
-- particles); then, for the chosen model, lower the upper half as a whole to `approach_gap` and
-- bring it down at the closure velocity until one contact exists, close the joint at 6e-5 m/s to
-- the normal stress, and shear it under constant normal load.
--
-- Models [scenarios.md 4]: rigid (each half one rigid body; only particles that can touch the
-- other half are searched), elastic (unbreakable bonds), fracture (elliptic criterion with the
-- calibrated bond strength; refused if the genesis left more than 1 % of the bonds above it).
-- The halves are made by the REV's genesis (lib/genesis.lua), so they are the calibrated
-- material. Stresses are reported in model units and scaled to rock [3-37].
--
-- Writes into `out` (created once every check has passed): summary.json; closure.{h5,csv},
-- shear.{h5,csv} (stresses in model Pa and in MPa scaled to rock, closure and displacements in
-- mm; the stress scale and the parameters as attributes); snapshots joint.xdmf (XDMF time = shear
-- displacement, mm) at the displacements in `snapshots` and joint_closure.xdmf (closure, mm);
-- PNG plots: shear stress and dilatancy, normal stress and tau / sigma_n, closure curve, contact
-- count, broken bonds, energies, and maps of contact points and broken bonds over the elevation
-- at the peak and at the end. `--help` lists the parameters.
local mat = require("materials")
local radii_lib = require("radii")
local genesis = require("genesis")
local specimen = require("specimen")
local heightmap = require("heightmap")

local params_lib = require("params")
local R = mat.packing.mean_radius
local P = params_lib.parse{
  script = "joint.lua",
  path = "scripts/joint.lua",
  about = "a rock joint closed and sheared under constant normal load",
  {"surface", "S1", oneof = {"S1", "S2", "S3", "S4", "S5", "S6", "S7", "S8", "flat"},
   doc = "reference surface (surfaces.md table 4), or flat: a plane, the control case"},
  {"surface_file", "", file = true, doc = "an HDF5 height map instead (dataset `height`, attribute `spacing`)"},
  {"scale", "", oneof = {"", "thesis"}, doc = "thesis: size 0.1 m (about 110 000 particles) unless size is given"},
  {"size", 0.02, unit = "m", min = 4 * R, doc = "side of the square joint"},
  {"thickness", 0.006, unit = "m", min = 2 * R, doc = "each half beyond the mean plane"},
  {"spacing", 0.1 / 365, unit = "m", above = 0, doc = "surface grid spacing (the thesis grid)"},
  {"model", "elastic", oneof = {"rigid", "elastic", "fracture"},
   doc = "rigid bodies, unbreakable bonds, or the calibrated breakable bonds [scenarios.md 4]"},
  {"stress", 14, unit = "MPa", above = 0, doc = "normal stress, scaled to rock (model Pa x stress scale)"},
  {"direction", "x", oneof = {"x", "y"}, doc = "the upper half moves along -x or -y"},
  {"shear", 5, unit = "mm", above = 0, doc = "shear displacement"},
  {"residual_window", 0.5, unit = "mm", above = 0, doc = "the residual stress is the mean over the last this much of the shear"},
  {"velocity", 1.5e-5, unit = "m/s", above = 0, doc = "shear velocity (perf/runtime_vs_error.lua: within 1 % of a 2x slower run)"},
  {"ramp", 0.05, unit = "mm", min = 0,
   doc = "the shear velocity, and the upper half's approach, rise linearly from 0 over this displacement"},
  {"quasi_static_limit", 0.01, above = 0, doc = "warn when the kinetic energy exceeds this x normal load x mean radius"},
  {"overlap_limit", 0.5, above = 0, max = 1,
   doc = "warn when a contact overlaps this fraction of the smaller radius (the engine stops at overlap_stop)"},
  {"overlap_stop", 0, min = 0, max = 1.9,
   doc = "the engine stops the run at an overlap of this many smaller radii (0: 1, the rigid model 1.9)"},
  {"normal_control", "servo", oneof = {"servo", "load", "stiffness"},
   doc = "servo (model.md 7, with integral action), load: a constant force on a free platen, or stiffness: "
         .. "constant normal stiffness, sigma_0 + normal_stiffness x dilatancy"},
  {"normal_stiffness", 0, unit = "MPa/mm", min = 0, doc = "scaled to rock; of normal_control=stiffness (> 0 there, 0 otherwise)"},
  {"platen_damping", 0, below = 1, doc = "local damping of the dead-load platen (< 0: the world's)"},
  {"servo_relaxation", 0.4, above = 0, max = 1, doc = "servo gain: fraction of the force error corrected per step"},
  {"servo_integral_steps", 2, min = 0, doc = "integral time of the servo, in time steps (0: proportional only)"},
  {"servo_max_velocity", 100, above = 0, doc = "the servo's speed limit, in shear velocities"},
  {"closure_velocity", 6e-5, unit = "m/s", above = 0, doc = "closure velocity [thesis 4.2.2]"},
  {"closure_every", 0, type = "integer", min = 0,
   doc = "steps between closure records (0: 50, or 1 for the rigid model, which closes in a few dozen steps)"},
  {"approach_gap", 0.2e-3, unit = "m", min = 0, doc = "smallest gap left between the halves after lowering the upper one"},
  {"gap", 1e-3, unit = "m", min = 0, doc = "between the halves while they relax"},
  {"platen", 1.5e-3, unit = "m", above = 0, doc = "layer of each outer face that forms a platen"},
  {"box", "sides", oneof = {"sides", "none"},
   doc = "sides: the layer of the four side faces joins its half's platen (a shear box) up to box_clearance "
         .. "from the joint; none: the platens are the top and bottom layers only, the sides are free"},
  {"box_clearance", 1e-3, unit = "m", min = 0,
   doc = "the shear box's sides stop this far below (lower half) or above (upper half) the highest (lowest) "
         .. "point of their half's surface within this distance"},
  {"porosity", mat.genesis.porosity, above = 0, below = 1, doc = "thesis definition [3-35]: the particle count of the genesis"},
  {"genesis_stress", mat.genesis.stress, unit = "Pa", above = 0, doc = "isotropic stress installed before bonding (scenarios.md 1; model units)"},
  {"bond_gap", 0, unit = "m", min = 0, doc = "largest gap bonded (0: the engine's default, 1e-3 x mean radius)"},
  {"wall_friction", 0, min = 0, doc = "of the box walls and the mould during the genesis (scenarios.md 1: frictionless)"},
  {"seed", 1, type = "integer", min = 0, doc = "of the surface and the packing"},
  {"pack_steps", 300000, type = "integer", min = 1, doc = "most steps spent cycling the packing towards the ratio 1e-4"},
  {"record", 0.01, unit = "mm", above = 0, doc = "shear displacement between records"},
  {"dt_safety", 0, min = 0, max = 2,
   doc = "time step / critical estimate for closure and shear (0: 1.0 elastic and fracture, 0.8 rigid; above 1 only to study instability)"},
  {"skin", 0, unit = "m", min = 0, doc = "Verlet skin (0: 0.1 mean radius, the rigid model 0.4)"},
  {"snapshots", "0,1,2.5,5", list = "number", unit = "mm", min = 0,
   doc = "shear displacements of the particle snapshots, within 0 .. shear (\"\": none; by default those "
         .. "within a shorter shear and its end)"},
  {"band", 0, unit = "m", min = 0, doc = "surface vs porosity band (0: mean radius)"},
  {"out", "out/joint", nonempty = true, doc = "output folder (created when the run starts writing)"},
  {"cache", "", doc = "folder of cached specimens (\"\": $ASPERITY_CACHE, else ~/.cache/asperity, else out/cache)"},
  {"threads", 0, type = "integer", min = 0, doc = "0: automatic"},
  {"simd", "auto", oneof = {"auto", "float", "scalar", "sse4_2", "avx2", "avx512f"},
   doc = "kernels of closure and shear; float: the force laws in single precision"},
  {"progress", true, doc = "progress line on the terminal"},
  {"events_every", 0, type = "integer", min = 0,
   doc = "steps between energy samples for the event statistics (events.{h5,csv}); 0: none"},
  {"save", "", doc = "a path: the world's checkpoint when the shear ends"},
  {"stop_after", "", oneof = {"", "packing"}, doc = "packing: stop once the halves are packed, before bonding"},
  check = function(P, fail, given)
    if P.residual_window >= P.shear then
      fail("shear", ("must exceed the residual window (residual_window = %g mm): the residual is the "
                     .. "mean over the last residual_window of the shear"):format(P.residual_window))
    end
    if P.record >= P.shear then fail("record", ("must be < shear (%g mm)"):format(P.shear)) end
    if P.ramp >= P.shear then fail("ramp", ("must be < shear (%g mm)"):format(P.shear)) end
    if given.snapshots ~= nil then
      for _, s in ipairs(params_lib.split(P.snapshots, true)) do
        if s > P.shear then fail("snapshots", ("%g mm is beyond shear = %g mm"):format(s, P.shear)) end
      end
    else
      -- the default list follows a shorter shear: the displacements within it, and its end
      local kept = {}
      for _, s in ipairs(params_lib.split(P.snapshots, true)) do
        if s < P.shear then kept[#kept + 1] = ("%g"):format(s) end
      end
      kept[#kept + 1] = ("%g"):format(P.shear)
      P.snapshots = table.concat(kept, ",")
    end
    -- Constant normal stiffness: a stiffness is what makes it one (0 would be the servo's CNL).
    if P.normal_control == "stiffness" and not (P.normal_stiffness > 0) then
      fail("normal_stiffness", "must be > 0 with normal_control=stiffness")
    elseif P.normal_control ~= "stiffness" and P.normal_stiffness ~= 0 then
      fail("normal_stiffness", ("needs normal_control=stiffness (now %s)"):format(P.normal_control))
    end
    if P.platen >= P.thickness then fail("platen", ("must be < thickness (%g m)"):format(P.thickness)) end
    local size = (P.scale == "thesis" and params.size == nil) and 0.1 or P.size
    local cells = size / P.spacing
    if cells < 2 or cells > 32766 then
      fail("spacing", ("gives %.0f grid cells over size = %g m; must give 2 .. 32766"):format(cells, size))
    end
  end,
}
if not P then return end   -- help printed
if P.scale == "thesis" and params.size == nil then P.size = 0.1 end
if P.cache == "" then
  local home = os.getenv("HOME")
  P.cache = os.getenv("ASPERITY_CACHE") or (os.getenv("XDG_CACHE_HOME") and os.getenv("XDG_CACHE_HOME") .. "/asperity")
            or (home and home ~= "" and home .. "/.cache/asperity") or (P.out .. "/cache")
end
local t_start = asperity.wall_time()
asperity.mkdir(P.cache)
local function log(fmt, ...) io.stderr:write(("[joint] " .. fmt .. "\n"):format(...)) end

-- 1. The surface ---------------------------------------------------------------------------
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
local Lx, Ly = (nx - 1) * h, (ny - 1) * h                 -- the mesh spans (n - 1) spacings
local heights = {}
for j = 1, ny do for i = 1, nx do heights[#heights + 1] = map:at(i, j) end end
local function surface_z(x, y)                             -- the mould, bilinear in each cell
  local fi, fj = x / h, y / h
  local i, j = math.max(0, math.min(nx - 2, math.floor(fi))), math.max(0, math.min(ny - 2, math.floor(fj)))
  local u, v = fi - i, fj - j
  local function z(a, b) return heights[(j + b) * nx + (i + a) + 1] end
  return (1 - u) * (1 - v) * z(0, 0) + u * (1 - v) * z(1, 0) + (1 - u) * v * z(0, 1) + u * v * z(1, 1)
end
local zmin, zmax = math.huge, -math.huge
for _, z in ipairs(heights) do zmin, zmax = math.min(zmin, z), math.max(zmax, z) end
local T = P.thickness

-- 2. The specimen: the genesis of both halves, bonded, relaxed (cached) ----------------------
-- Both halves are made by the REV's genesis (lib/genesis.lua, scenarios.md 1) in one box split by
-- the mould, so the joint is made of the material the REV calibrates.
local key = ("%s_%s_n%d_h%.6g_T%.6g_p%.4g_s%d_g%.6g_k%d_gs%.4g_fc%d_l%d_b%.4g_%.4g_gap%.4g"):format(
  P.surface_file ~= "" and P.surface_file:gsub("[^%w]", "_") or P.surface, "v8", n, h, T,
  P.porosity, P.seed, P.gap, P.pack_steps, P.genesis_stress, mat.genesis.floater_contacts,
  mat.rev.rotation_lock_bonds, mat.rev.bond_shear_ratio, mat.rev.bond_radius_factor, P.bond_gap)
  .. (P.wall_friction ~= 0 and ("_f%.3g"):format(P.wall_friction) or "")
local cache_file = P.cache .. "/joint_" .. key .. ".h5"
local LOWER, UPPER, LOST, POROSITY = 1, 2, 3, 1   -- tags; POROSITY is a flag bit

local function build_specimen()
  local w = asperity.world{material = mat.contact, damping = mat.damping, density = mat.density,
                           threads = P.threads, rotation_lock_bonds = mat.rev.rotation_lock_bonds}
  -- Boxes: sides, floor of the lower half, roof of the upper one; the mould between them.
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
  local mesh = heightmap.mesh{heights = heights, nx = nx, ny = ny, dx = h, dy = h, origin = {0, 0, 0}}
  local mould = w:add_mesh{vertices = mesh.vertices, triangles = mesh.triangles, material = wm}
  -- Particle count from the thesis porosity definition [3-35, 3-36] over both halves.
  local volume = Lx * Ly * 2 * T
  local count = radii_lib.count_for_porosity{volume = volume, porosity = P.porosity,
                                             mean_radius = mat.packing.mean_radius}
  local r = radii_lib.truncated_gaussian{count = count, mean = mat.packing.mean_radius,
                                         sd = mat.packing.radius_sd, seed = P.seed, normalise_mean = true}
  log("genesis of %d particles in two halves of %.1f x %.1f mm (surface %s, %d x %d grid)", count,
      Lx * 1e3, Ly * 1e3, P.surface_file ~= "" and P.surface_file or P.surface, nx, ny)
  local lo, hi = {0, 0, -T}, {Lx, Ly, T}   -- the box of both halves
  local g = genesis.pack(w, {min = lo, max = hi, radii = r, seed = P.seed, box = box, volume = volume,
                             stress = P.genesis_stress, friction = mat.contact.friction,
                             min_contacts = mat.genesis.floater_contacts, floater_tag = LOST,
                             progress = P.progress, max_steps = P.pack_steps,
                             log = function(fmt, ...) log(fmt, ...) end,
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
                               local s = surface_z(x, y)
                               return z + rad < s - rad or z - rad > s + rad
                             end})
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
                             log = function(fmt, ...) log(fmt, ...) end,
                             before_relax = function(w)
    -- Particles of a half without a bond carry nothing and would drift off: made inert (neither
    -- integrated nor searched) and tagged LOST, like those squeezed out, so no half, platen or
    -- measure counts them.
    local bonded, across = {}, 0
    for _, bd in ipairs(w:bonds()) do
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
  log("%d particles left out (floaters %d; outside the box or without a bond %d)", g.floaters_removed + #lost,
      g.floaters_removed, #lost)
  w:save(cache_file)
  local record = {particles = w:particle_count(), lower = #lower, upper = #upper,
    left_out = g.floaters_removed + #lost, floaters_removed = g.floaters_removed, bonds = b.bonds,
    porosity_nominal = g.porosity_nominal, porosity_true = g.porosity_true, mean_radius = g.mean_radius,
    coordination = g.coordination, genesis_stress_pa = g.stress_pa, genesis_stress_target_pa = P.genesis_stress,
    genesis_stress_reached = g.stress_reached, radius_factor = g.radius_factor, genesis_steps = g.steps,
    genesis_seconds = g.seconds, relax_steps = b.relax_steps, relax_reached = b.relax_reached,
    bonds_broken_in_relaxation = b.broken_in_relaxation, bond_stress = b.bond_stress,
    bond_stress_max_over_st = b.bond_stress_max_over_st, defined_state = b.defined_state,
    wall_stress_pa = g.wall_stress_pa}
  asperity.write_json(cache_file .. ".json", record)
  local f = assert(io.open(cache_file .. ".lua.tmp", "w"))
  f:write("return " .. genesis.serialise(record) .. "\n")
  f:close()
  os.rename(cache_file .. ".lua.tmp", cache_file .. ".lua")
  return w, record
end

local world, specimen_record
-- The record is written last: a specimen without one was cut short and is built again.
local f = io.open(cache_file .. ".lua", "r")
if f then
  f:close()
  if P.stop_after == "packing" then
    error(("stop_after=packing needs a packing, but the specimen is cached (%s): give another cache="):format(cache_file), 0)
  end
  log("reusing the cached specimen %s", cache_file)
  world = asperity.load(cache_file, {threads = P.threads, simd = P.simd})
  specimen_record = dofile(cache_file .. ".lua")
else
  world, specimen_record = build_specimen()
  if not world then return specimen_record end   -- stop_after = "packing"
  if P.simd ~= "auto" then world = asperity.load(cache_file, {threads = P.threads, simd = P.simd}) end
end
-- Numerical settings of the test (perf/runtime_vs_error.lua chose them; 0 keeps the engine's).
local dt_safety = P.dt_safety > 0 and P.dt_safety or (P.model == "rigid" and 0 or 1.0)
if dt_safety > 0 then world:set_dt_safety(dt_safety) end
-- The skin: a bonded specimen moves by elastic strains between rebuilds, so a thin skin (0.1 mean
-- radius) rebuilds a few times more often than the packing's 0.4 and lists a quarter of the near
-- misses (the elastic step: 0.86 of its cost). The rigid model's bodies travel a skin in a few
-- hundred steps, and its step is mostly rebuilds: it keeps the packing's.
local skin = P.skin > 0 and P.skin or (P.model == "rigid" and 0 or 0.1 * mat.packing.mean_radius)
if skin > 0 then world:set_skin(skin) end
-- The rigid model's halves are two bodies: an asperity contact cannot relieve itself by straining
-- its half, and two surface spheres met head-on are pressed past each other (1.1 radii on the 3 cm
-- S1 joint at 14 MPa) until the upper half rides over them. That is the rigid model with soft
-- contacts (PFC has no stop), so its runs go on to just short of the centres meeting (2 radii);
-- the WARNING above overlap_limit still says so.
world:set_overlap_limit(P.overlap_stop > 0 and P.overlap_stop or (P.model == "rigid" and 1.9 or 1))
local N = world:particle_count()
local lower, upper = {}, {}
for id = 1, N do
  local t = world:tag(id)
  if t == LOWER then lower[#lower + 1] = id elseif t == UPPER then upper[#upper + 1] = id end
end

-- The upper half's mean height in the frame of the mould (the cached specimen holds it `gap`
-- higher): break depths are measured from the mean plane in that frame.
local function mean_height(ids)
  local ps, z = world:positions(), 0
  for _, id in ipairs(ids) do z = z + ps:get(id, 3) end
  return z / math.max(1, #ids)
end
local upper_mean_z_mould = mean_height(upper) - P.gap

-- 3. The DEM surfaces: profilometer, mean plane, surface vs porosity particles ---------------
local pos, rad = world:positions(), world:radii()
local prof_lower = asperity.surface.profilometer{positions = pos, radii = rad, grid = map,
                                                 side = "lower", ids = lower}
local prof_upper = asperity.surface.profilometer{positions = pos, radii = rad, grid = map,
                                                 side = "upper", ids = upper,
                                                 origin = {0, 0}}
local plane_lower = asperity.surface.mean_plane(prof_lower, map)
local cls = asperity.surface.classify(prof_lower, map, P.band > 0 and {band = P.band} or nil)
-- The upper half sits `gap` higher: its own mean plane (the shift) accounts for that.
local cls_up_shifted = asperity.surface.classify(prof_upper, map, P.band > 0 and {band = P.band} or nil)
local porosity_ids = {}
for _, id in ipairs(cls.porosity) do porosity_ids[#porosity_ids + 1] = id end
for _, id in ipairs(cls_up_shifted.porosity) do porosity_ids[#porosity_ids + 1] = id end
world:set_flags(porosity_ids, POROSITY)
log("DEM surface: mean plane dv = %.3g mm, %.0f %% of nodes coinciding; %.0f %% of the " ..
    "profilometer particles are on the expected surface", plane_lower.shift * 1e3,
    100 * plane_lower.coinciding_fraction, 100 * cls.retained_fraction)

-- Bring the upper half down as a whole (positions only, no dynamics) until the smallest vertical
-- gap between the two DEM surfaces is `approach_gap`; the assembly below closes the rest slowly.
-- Driving a bonded half at speed into the other instead would send a stress wave through the
-- specimen larger than the target stress of the soft model.
do
  local lo_s, up_s = prof_lower.surface, prof_upper.surface
  local gap_min = math.huge
  for j = 1, ny do
    for i = 1, nx do
      local d = up_s:at(i, j) - lo_s:at(i, j)
      if d == d then gap_min = math.min(gap_min, d) end
    end
  end
  if gap_min < math.huge and gap_min > P.approach_gap then
    local dz = gap_min - P.approach_gap
    for _, id in ipairs(upper) do
      local p = pos[id]
      world:set_position(id, {p[1], p[2], p[3] - dz})
    end
    pos = world:positions()
    prof_upper = asperity.surface.profilometer{positions = pos, radii = rad, grid = map,
                                               side = "upper", ids = upper, origin = {0, 0}}
    log("upper half lowered by %.3f mm (smallest gap %.3f mm)", dz * 1e3, P.approach_gap * 1e3)
  end
end

-- 4. The model, platens ----------------------------------------------------------------------
local area = Lx * Ly
-- The REV calibrated with the same bond installation as these halves (scripts/lib/materials.lua).
local rev = mat.rev
local stress_scale = mat.rock.young_modulus / rev.young_modulus        -- [3-37]
local target_stress = P.stress * 1e6 / stress_scale                   -- model units, Pa
local function mpa(sigma) return sigma * stress_scale / 1e6 end
-- Units of the stress columns in the HDF5 and CSV files: the model's own Pa, or MPa scaled to the
-- rock by stress_scale [3-37] (an attribute of every file, with the run's parameters).
local MODEL_PA, ROCK_MPA = "Pa (model)", "MPa (scaled to rock)"
local function label_series(series)
  series:set_attribute("stress_scale", stress_scale)
  series:set_attribute("stress_units", "columns in '" .. MODEL_PA .. "' are model stresses; columns in '" ..
                       ROCK_MPA .. "' are model stresses x stress_scale / 1e6")
  local names = {}
  for name in pairs(P) do names[#names + 1] = name end
  table.sort(names)
  for _, name in ipairs(names) do
    local v = P[name]
    series:set_attribute("parameter_" .. name, type(v) == "boolean" and tostring(v) or v)
  end
end
-- Outer faces of the specimen: the lowest point of the lower half, the highest of the upper.
local zlo, zhi = math.huge, -math.huge
for _, id in ipairs(lower) do zlo = math.min(zlo, pos[id][3]) end
for _, id in ipairs(upper) do zhi = math.max(zhi, pos[id][3]) end
-- The highest point of the lower half's surface (upper_side: the lowest of the upper half's) within
-- `within` of (x, y), from the profilometer.
local lo_s, up_s = prof_lower.surface, prof_upper.surface
local function local_extreme(s, x, y, within, upper_side)
  local best = upper_side and math.huge or -math.huge
  local i0, j0 = math.floor(x / h) + 1, math.floor(y / h) + 1
  local k = math.ceil(within / h)
  for j = math.max(1, j0 - k), math.min(ny, j0 + k) do
    for i = math.max(1, i0 - k), math.min(nx, i0 + k) do
      local z = s:at(i, j)
      if z == z then best = upper_side and math.min(best, z) or math.max(best, z) end
    end
  end
  return best
end
local bottom, top
local platen_particles   -- lower and upper platen members (not for the rigid model: the halves are the bodies)
if P.model == "rigid" then
  world:remove_bonds()
  bottom = world:add_group(lower, {translation = "fixed"})
  top = world:add_group(upper, {translation = {"fixed", "fixed", "velocity"}, velocity = {0, 0, 0}})
  -- Only particles within reach of the other half are simulated: the rest of each half is inert
  -- [model.md 6]. A particle deeper than two diameters below its half's surface (profilometer,
  -- over the neighbourhood it could slide under) can never be touched.
  local reach = 4 * mat.packing.mean_radius * 1.6
  local inert = {}
  for _, id in ipairs(lower) do
    local p = pos[id]
    if p[3] + rad[id] < local_extreme(lo_s, p[1], p[2], reach, false) - reach then inert[#inert + 1] = id end
  end
  for _, id in ipairs(upper) do
    local p = pos[id]
    if p[3] - rad[id] > local_extreme(up_s, p[1], p[2], reach, true) + reach then inert[#inert + 1] = id end
  end
  if #inert > 0 then world:set_inert(inert) end
  log("rigid model: %d of %d particles inert", #inert, N)
else
  if P.model == "elastic" then
    world:set_bond_strength{breakable = false}
  else
    -- The bonds must hold what the preparation locked into them, or the "fracture" model is an
    -- unbonded pile that collapses at the first step. Say so instead of shearing it.
    local st = rev.bond_tensile_strength
    local over, worst, all = 0, 0, world:bonds()
    for _, b in ipairs(all) do
      local need = mat.strength_to_hold(b.sigma, b.tau)
      if need > st then over = over + 1 end
      worst = math.max(worst, need)
    end
    if over > 0.01 * #all then
      error(("model=fracture: %d of %d bonds (%.0f %%) of the prepared specimen carry stresses that need " ..
             "a strength above the calibrated st = %.4g Pa (largest %.4g Pa): the packing locked more " ..
             "stress into the halves than the REV's genesis (scenarios.md 1). Run model=elastic or " ..
             "rigid, or lower genesis_stress."):format(over, #all, 100 * over / #all, st, worst), 0)
    end
    world:set_bond_strength{tensile_strength = st}
  end
  -- Platens: the layer of each outer face. With the shear box, the side faces' layers too: a half
  -- whose sides are free carries the shear through its bulk as shear stress, and at a peak of
  -- 1.2-1.6 sigma_n (reference.md 2) the principal tension, sigma_n/2 - sqrt((sigma_n/2)^2 + tau^2),
  -- exceeds the material's tensile strength (at 14 MPa, from tau = 11.7 MPa on): the halves fail in
  -- their bulk, not at the joint. A box carries the shear into the halves as side pressure. Its
  -- sides stop short of the joint so that the halves touch only through bonded material.
  local function on_side(p)
    return p[1] < P.platen or p[1] > Lx - P.platen or p[2] < P.platen or p[2] > Ly - P.platen
  end
  local c = P.box_clearance
  local bottom_ids, top_ids = {}, {}
  for _, id in ipairs(lower) do
    local p = pos[id]
    if p[3] < zlo + P.platen or (P.box == "sides" and on_side(p)
                                 and p[3] + rad[id] < local_extreme(lo_s, p[1], p[2], c, false) - c) then
      bottom_ids[#bottom_ids + 1] = id
    end
  end
  for _, id in ipairs(upper) do
    local p = pos[id]
    if p[3] > zhi - P.platen or (P.box == "sides" and on_side(p)
                                 and p[3] - rad[id] > local_extreme(up_s, p[1], p[2], c, true) + c) then
      top_ids[#top_ids + 1] = id
    end
  end
  platen_particles = {lower = #bottom_ids, upper = #top_ids}
  log("platens: %d particles below, %d above (%s)", #bottom_ids, #top_ids,
      P.box == "sides" and "bottom and top layers and the shear box's sides" or "bottom and top layers")
  bottom = world:add_group(bottom_ids, {translation = "fixed"})
  top = world:add_group(top_ids, {translation = {"fixed", "fixed", "velocity"}, velocity = {0, 0, 0}})
end

local bonds_at_start = world:bond_count()

-- Debris that leaves the specimen: a particle freed by breaks can be thrown out through the open
-- band between the halves and then flies on (specimen.take_out_escaped); its travel alone would
-- trigger a neighbour rebuild every few tens of steps (a 2 cm fracture joint: 16 000 rebuilds in
-- the shear instead of 3 000). A centre more than `escape_margin` outside the box the halves can
-- occupy is taken out like the floaters: it carries nothing and touches nothing.
local escaped_count = 0
local escape_margin = 4 * R
local escape_box   -- the box the halves can occupy, widened along -axis by the shear to come
local function set_escape_box(shear_reach)
  escape_box = {min = {-escape_margin, -escape_margin, zlo - escape_margin},
                max = {Lx + escape_margin, Ly + escape_margin, zhi + P.gap + escape_margin}}
  local axis_index = P.direction == "x" and 1 or 2
  escape_box.min[axis_index] = escape_box.min[axis_index] - shear_reach
end
local function remove_escaped()
  local out = specimen.take_out_escaped(world, escape_box, LOST)
  if #out == 0 then return end
  escaped_count = escaped_count + #out
  log("%d particle%s thrown out of the specimen: taken out (%d so far)", #out, #out == 1 and "" or "s", escaped_count)
end
-- Only broken material can escape.
local escape_every = (P.model == "fracture") and 2000 or 0
if escape_every > 0 then set_escape_box(0) end
-- Particle snapshots (HDF5 + XDMF) indexed by `label` (the shear or the closure displacement in
-- mm), with the keys of the integer fields; the particles left out of the specimen are not
-- written, so they are not drawn as debris between the halves.
local function joint_snapshots(name, label)
  local groups = P.model == "rigid" and ("%d: lower half (rigid), %d: upper half (rigid), -1: none")
                 or ("%d: lower platen, %d: upper platen, -1: none (bonded particles)")
  return asperity.snapshots{dir = P.out, name = name, time = label, exclude_tag = LOST,
                            keys = {group = groups:format(bottom, top),
                                    tag = ("%d: lower half, %d: upper half"):format(LOWER, UPPER)}}
end

-- 5. Assembly: bring the halves together until exactly one contact exists [4.2.1] ------------
local function between() return world:contact_summary(LOWER, UPPER, POROSITY) end
-- The upper half does not stop at the first contact, and its velocity rises from 0 over `ramp`
-- of travel: a platen set moving at the closure velocity in one step sends a wave through the
-- soft bonded half whose force, sqrt(k m) v, is of the order of a bond's strength.
local ramp_steps = P.ramp > 0 and math.max(1, math.ceil(2 * P.ramp * 1e-3 / P.closure_velocity / world:dt())) or 0
local moved_steps = 0
local function approach_velocity(w, steps_done)
  moved_steps = moved_steps + steps_done
  local f = moved_steps >= ramp_steps and 1 or moved_steps / ramp_steps
  w:set_group_velocity(top, {0, 0, -P.closure_velocity * f})
end
approach_velocity(world, ramp_steps > 0 and 1 or 0)
local steps = world:run{steps = 10000000, every = 1, progress = P.progress,
                        callback = function(w) if moved_steps < ramp_steps then approach_velocity(w, 1) end end,
                        stop_when = function(w) return w:contact_summary(LOWER, UPPER).count >= 1 end}
log("halves in contact after %d steps", steps)

-- 6. Closure at constant velocity to the normal stress [thesis 4.2.2] -----------------------
local z_contact = world:group_position(top)[3]
-- The output folder appears only now, once every refusal (parameters, the fracture model's
-- strength check) has had its say: a run that fails to start leaves no empty folder behind.
asperity.mkdir(P.out)
local function closure_mm() return 1e3 * (z_contact - world:group_position(top)[3]) end
local closure_snaps = joint_snapshots("joint_closure", "closure (mm)")
closure_snaps:write(world, {stage = "closure", closure_mm = 0, stress_scale = stress_scale}, 0)
local closure = asperity.series{"closure [mm]", "closure_corrected [mm]", "normal_stress [" .. MODEL_PA .. "]",
  "normal_stress_mpa [" .. ROCK_MPA .. "]", "contacts [1]", "contact_area [%]", "broken_bonds [1]", "time [s]"}
local height = zhi - zlo
-- Force of the particles on the upper platen (the group force less any applied dead load).
local applied_z = 0
local function platen_force()
  local f = world:group_force(top)
  return {f[1], f[2], f[3] - applied_z}
end
local function normal_stress() return platen_force()[3] / area end
-- The deepest overlap of any contact or bond over the smaller radius, read at every record. At the
-- study's loads single asperity contacts are pressed 0.3-0.45 of a radius deep (perf/README.md,
-- "Contacts soft for the load"); deeper ones mean the contacts are too soft for the load, and the
-- contact points and lever arms [3-11] lose their sense long before the engine's health check
-- stops the run at one radius.
local overlap_max, overlap_at = 0, "closure"
local function track_overlap(where)
  local r = world:max_overlap_ratio()
  if r > overlap_max then overlap_max, overlap_at = r, where end
end
local function record_closure()
  track_overlap("closure")
  local s = normal_stress()
  local c = between()
  local d = z_contact - world:group_position(top)[3]
  closure:record(1e3 * d, 1e3 * (d - s * height / rev.young_modulus), s, mpa(s), c.count,
                 100 * c.area / area, world:break_count(), world:time())
end
local closure_every = P.closure_every > 0 and P.closure_every or (P.model == "rigid" and 1 or 50)
record_closure()
world:run{steps = 10000000, every = 1, progress = P.progress,
          callback = function(w)
            if moved_steps < ramp_steps then approach_velocity(w, 1) end
            if w:step() % closure_every == 0 then record_closure() end
            if escape_every > 0 and w:step() % escape_every == 0 then remove_escaped() end
          end,
          stop_when = function() return normal_stress() >= target_stress end,
          fraction = function() return normal_stress() / target_stress end,
          show = function()
            return {closure_um = 1e6 * (z_contact - world:group_position(top)[3]),
                    sigma_mpa = mpa(normal_stress()), contacts = between().count}
          end}
record_closure()
log("closed to %.3g MPa in %.1f um", mpa(normal_stress()), 1e6 * (z_contact - world:group_position(top)[3]))
closure_snaps:write(world, {stage = "closure", closure_mm = closure_mm(), stress_scale = stress_scale}, closure_mm())
label_series(closure)
closure:write(P.out .. "/closure")

-- Normal stiffness: slope of stress against closure over the upper half of the loading.
local function fit(xs, ys)
  local n_, sx, sy, sxx, sxy = #xs, 0, 0, 0, 0
  if n_ < 2 then return 0/0 end
  for k = 1, n_ do sx, sy, sxx, sxy = sx + xs[k], sy + ys[k], sxx + xs[k] ^ 2, sxy + xs[k] * ys[k] end
  return (n_ * sxy - sx * sy) / (n_ * sxx - sx * sx)
end
local cd, cs = closure:column("closure"), closure:column("normal_stress_mpa")
local kx, ky = {}, {}
for k = 1, closure:rows() do
  if cs[k] >= 0.5 * P.stress then kx[#kx + 1] = cd[k]; ky[#ky + 1] = cs[k] end
end
local normal_stiffness = fit(kx, ky)   -- MPa/mm

-- 7. Shear under constant normal load [thesis 4.3.1] ---------------------------------------
local axis = P.direction == "x" and 1 or 2
local shear_velocity = {0, 0, 0}
shear_velocity[axis] = -P.velocity
-- Constant normal load. "load": the platen is free along z under a constant applied force, a dead
-- weight, undamped (local damping would bias the load it transmits by alpha times the mean force
-- noise): it follows any dilatancy at once and the load it transmits differs from the target only
-- by its inertia. "servo" (model.md 7): the platen's z velocity follows the force error, with
-- integral action (servo_integral_steps) so that a steady dilatancy rate leaves no lag.
-- "stiffness": the same servo, its target rising by normal_stiffness x the platen's rise (constant
-- normal stiffness, the engine's servo `stiffness`); it settles on sigma_0 like the CNL servo, and
-- the stiffness is switched on when the shear starts, so the dilatancy it acts on is the recorded one.
local servo_control = P.normal_control == "servo" or P.normal_control == "stiffness"
local modes = {"fixed", "fixed", servo_control and "servo" or "free"}
modes[axis] = "velocity"
-- MPa/mm scaled -> N/m of the platen: model Pa per m of rise, times the area.
local cns_stiffness = P.normal_control == "stiffness" and P.normal_stiffness * 1e6 / stress_scale * 1e3 * area or 0
if servo_control then
  world:set_group_motion(top, {translation = modes, velocity = shear_velocity,
                               servo = {target_force = target_stress * area, max_velocity = P.servo_max_velocity * P.velocity,
                                        relaxation = P.servo_relaxation,
                                        integral_time = P.servo_integral_steps * world:dt()}})
elseif P.normal_control == "load" then
  world:set_group_motion(top, {translation = modes, velocity = shear_velocity, damping = P.platen_damping})
  applied_z = -target_stress * area
  world:set_group_force(top, {0, 0, applied_z})
else
  error("normal_control must be servo, load or stiffness, got '" .. P.normal_control .. "'")
end
-- Let the platen settle on the target load before shearing.
do
  local hold = {table.unpack(modes)}
  hold[axis] = "fixed"
  local v0 = {0, 0, 0}
  world:set_group_motion(top, {translation = hold, velocity = v0})
  local n = world:run{steps = 200000, every = 100, progress = P.progress,
            stop_when = function(w)
              return math.abs(normal_stress() / target_stress - 1) < 0.002 and w:unbalanced_force_ratio() < 1e-3
            end}
  log("settled on the normal load in %d steps", n)
end
local shear = asperity.series{"displacement [mm]", "shear_stress [" .. MODEL_PA .. "]", "shear_stress_mpa [" .. ROCK_MPA .. "]",
  "normal_stress_mpa [" .. ROCK_MPA .. "]", "normal_stress_mean_mpa [" .. ROCK_MPA .. "]", "dilatancy [mm]", "contacts [1]", "contact_area [%]",
  "broken_bonds [1]", "porosity_shear_stress_mpa [" .. ROCK_MPA .. "]", "kinetic [J]", "strain [J]",
  "friction [J]", "damping [J]", "released [J]", "boundary_work [J]", "shear_work [J]",
  "dilatancy_work [J]", "time [s]"}
local c0 = world:group_position(top)
local e0 = world:energies()
local shear_work, dilatancy_work = 0, 0
local last_pos, last_force = c0, platen_force()
local snaps = joint_snapshots("joint", "shear displacement (mm)")
local snap_at = {}
for _, v in ipairs(params_lib.split(P.snapshots, true)) do snap_at[#snap_at + 1] = v end
table.sort(snap_at)
local next_snap = 1
-- The contact points between the halves at the highest shear stress so far: at the end, those of
-- the peak (for its contact map).
local peak_seen, peak_points = -math.huge, nil
local function points_between()
  local pts = {}
  for _, ct in ipairs(world:contacts()) do
    if world:tag(ct.a) ~= world:tag(ct.b) then pts[#pts + 1] = {ct.point[1], ct.point[2]} end
  end
  return pts
end
local function displacement() return (c0[axis] - world:group_position(top)[axis]) * 1e3 end
-- The normal stress averaged over each recording interval, as a load cell with a low-pass filter
-- reads it (the instantaneous value also carries the platen's inertia at each slip event of the
-- soft model): the change of the platen's impulse over the change of time, so nothing has to be
-- sampled every step.
local last_impulse, last_time = world:group_impulse(top)[3], world:time()
-- Quasi-static check: the specimen's kinetic energy against the work of the normal load over one
-- mean radius. A rate-independent (quasi-static) test keeps it small; a start-up impact or a
-- loading rate too high for the material shows up here long before the health checks.
local dynamic_ratio, dynamic_at = 0, 0
local energy_scale = target_stress * area * mat.packing.mean_radius
local shear_impulse = {}   -- platen impulse along the shear axis, one per record
local function record_shear()
  local p, f = world:group_position(top), platen_force()
  local impulse, now = world:group_impulse(top), world:time()
  local sn_mean = now > last_time and ((impulse[3] - last_impulse) / (now - last_time) - applied_z) / area or f[3] / area
  last_impulse, last_time = impulse[3], now
  -- Work of the agent on the specimen: the force it applies is minus the particles' force.
  shear_work = shear_work - 0.5 * (f[axis] + last_force[axis]) * (p[axis] - last_pos[axis])
  dilatancy_work = dilatancy_work - 0.5 * (f[3] + last_force[3]) * (p[3] - last_pos[3])
  last_pos, last_force = p, f
  local c = between()
  local tau = f[axis] / area   -- the lower half resists the upper one moving along -axis
  local e = world:energies()
  if e.kinetic / energy_scale > dynamic_ratio then dynamic_ratio, dynamic_at = e.kinetic / energy_scale, displacement() end
  track_overlap(("%.3f mm of shear"):format(displacement()))
  shear_impulse[#shear_impulse + 1] = impulse[axis]
  shear:record(displacement(), tau, mpa(tau), mpa(f[3] / area), mpa(sn_mean), (p[3] - c0[3]) * 1e3, c.count,
               100 * c.area / area, world:break_count(), mpa(c.flagged_force[axis] / area),
               e.kinetic, e.strain - e0.strain, e.friction - e0.friction, e.damping - e0.damping,
               e.released - e0.released, e.boundary_work - e0.boundary_work, shear_work,
               dilatancy_work, world:time())
  if mpa(tau) > peak_seen then
    peak_seen, peak_points = mpa(tau), {at = displacement(), step = world:step(), points = points_between()}
  end
  while next_snap <= #snap_at and displacement() >= snap_at[next_snap] - 1e-9 do
    snaps:write(world, {stage = "shear", shear_displacement_mm = displacement(), stress_scale = stress_scale}, displacement())
    next_snap = next_snap + 1
  end
end
record_shear()
local record_every = math.max(1, math.floor(P.record * 1e-3 / (P.velocity * world:dt()) + 0.5))
-- Event statistics (scenarios.md 8): the energies every `events_every` steps while shearing; the
-- breaks themselves come from world:break_events. The run then calls back every step, so the records
-- and the velocity ramp keep their steps (reading the energies still moves a chaotic run in its last
-- digits: scripts/README.md).
local events, sample_every, breaks_before = nil, record_every, world:break_count()
if P.events_every > 0 then
  sample_every = 1
  events = asperity.series{"step [1]", "displacement [mm]", "broken_bonds [1]", "kinetic [J]", "strain [J]",
                           "damping [J]", "friction [J]", "released [J]"}
end
local function record_events()
  local en = world:energies()
  events:record(world:step(), displacement(), world:break_count() - breaks_before, en.kinetic, en.strain,
                en.damping, en.friction, en.released)
end
if escape_every > 0 then set_escape_box(P.shear * 1e-3) end
local shear_t0, shear_s0, shear_r0 = asperity.wall_time(), world:step(), world:stats().rebuilds
-- The shear velocity rises linearly over `ramp` mm (time 2 ramp / v), in one stage per record.
local ramp_stages = P.ramp > 0 and math.max(1, math.ceil(2 * P.ramp * 1e-3 / P.velocity / world:dt() / record_every)) or 1
local function set_shear_velocity(stage)
  local v = {0, 0, 0}
  v[axis] = -P.velocity * math.min(1, stage / ramp_stages)
  world:set_group_motion(top, {translation = modes, velocity = v})
end
if cns_stiffness > 0 then world:set_group_motion(top, {servo = {stiffness = cns_stiffness}}) end
set_shear_velocity(1)
local stage = 1
if events then record_events() end
world:run{steps = 100000000, every = sample_every, progress = P.progress,
          callback = function()
            if events then
              local k = world:step() - shear_s0
              if k % P.events_every == 0 then record_events() end
              if k % record_every ~= 0 then return end
            end
            record_shear()
            if escape_every > 0 then remove_escaped() end
            if stage < ramp_stages then stage = stage + 1; set_shear_velocity(stage) end
          end,
          -- stop less than one record before the end; the last stretch is stepped singly below, so
          -- every run ends at `shear` exactly and the residual's window is always the same
          stop_when = function(w)
            return displacement() >= P.shear - 1e3 * P.velocity * w:dt() * (record_every + 1)
          end,
          fraction = function() return displacement() / P.shear end,
          show = function()
            return {disp_mm = displacement(), tau_mpa = mpa(platen_force()[axis] / area),
                    sigma_mpa = mpa(normal_stress())}
          end}
world:run{steps = 100000000, every = 1, stop_when = function() return displacement() >= P.shear end}
record_shear()
if P.save ~= "" then
  world:save(P.save)
  log("saved the world at %.3f mm of shear to %s", displacement(), P.save)
end
local shear_seconds, shear_steps = asperity.wall_time() - shear_t0, world:step() - shear_s0
local shear_rebuilds = world:stats().rebuilds - shear_r0
label_series(shear)
shear:write(P.out .. "/shear")
if events then events:write(P.out .. "/events") end
-- Every bond break while shearing (model.md 5), for the event statistics and maps.
if world:break_count() > breaks_before then
  local breaks = asperity.series{"step [1]", "time [s]", "x [m]", "y [m]", "z [m]", "mode [1]", "sigma [Pa]",
                                 "tau [Pa]", "released_energy [J]"}
  breaks:set_attribute("mode", "1 tension, 2 compression, 3 shear")
  local mode_code = {tension = 1, compression = 2, shear = 3}
  for _, ev in ipairs(world:break_events(breaks_before + 1)) do
    breaks:record(ev.step, ev.time, ev.position[1], ev.position[2], ev.position[3], mode_code[ev.mode] or 0,
                  ev.sigma, ev.tau, ev.released_energy)
  end
  breaks:write(P.out .. "/breaks")
end
log("sheared %.2f mm", displacement())

-- 8. Summary --------------------------------------------------------------------------------
local u, tau = shear:column("displacement"), shear:column("shear_stress_mpa")
local dil, sn = shear:column("dilatancy"), shear:column("normal_stress_mpa")
local cnt = shear:column("contacts")
local rows = shear:rows()
local peak, at = -math.huge, 1
for k = 1, rows do if tau[k] > peak then peak, at = tau[k], k end end
-- Residual: the mean shear stress over the last residual_window mm, from the platen's impulse (the exact time
-- mean, so it does not depend on the record interval; at constant velocity time and displacement
-- means agree).
local residual
do
  local time = shear:column("time")
  local first = rows
  while first > 1 and u[first - 1] >= u[rows] - P.residual_window do first = first - 1 end
  if first < rows and time[rows] > time[first] then
    residual = mpa((shear_impulse[rows] - shear_impulse[first]) / (time[rows] - time[first]) / area)
  else
    residual = tau[rows]
  end
end
if dynamic_ratio > P.quasi_static_limit then
  log("WARNING: not quasi-static: the kinetic energy reached %.3g x (normal load x mean radius) at %.3f mm "
      .. "(limit quasi_static_limit = %g); results depend on the loading rate: lower velocity (now %g m/s)",
      dynamic_ratio, dynamic_at, P.quasi_static_limit, P.velocity)
end
if overlap_max > P.overlap_limit then
  log("WARNING: a contact overlapped %.3g of its smaller radius (%s; limit overlap_limit = %g): the contacts "
      .. "are too soft for the load, and contact points and lever arms lose their sense; lower the normal "
      .. "stress (now %g MPa)", overlap_max, overlap_at, P.overlap_limit, P.stress)
end
-- Initial shear stiffness: slope over the first 30 % of the peak stress.
local sx, sy = {}, {}
for k = 1, at do if tau[k] <= 0.3 * peak then sx[#sx + 1] = u[k]; sy[#sy + 1] = tau[k] end end
local ks = fit(sx, sy)
local max_dil = -math.huge
for k = 1, rows do max_dil = math.max(max_dil, dil[k]) end
local function slope_at(k)
  local a, b = math.max(1, k - 5), math.min(rows, k + 5)
  return (dil[b] - dil[a]) / math.max(u[b] - u[a], 1e-12)
end
-- Contact decay N = N0 d^q after the maximum count.
local cmax, cat = -1, 1
for k = 1, rows do if cnt[k] > cmax then cmax, cat = cnt[k], k end end
local lx, ly = {}, {}
for k = cat, rows do
  if u[k] > 0 and cnt[k] > 0 then lx[#lx + 1] = math.log(u[k]); ly[#ly + 1] = math.log(cnt[k]) end
end
local q = fit(lx, ly)
local sn_mean = shear:column("normal_stress_mean_mpa")
local sn_dev, sn_dev_mean, devs = 0, 0, {}
-- The stress the control asks for: sigma_0, or with constant normal stiffness sigma_0 + K dilatancy
-- (for an interval mean, at the interval's mean dilatancy).
local K_cns = P.normal_control == "stiffness" and P.normal_stiffness or 0
for k = 1, rows do
  if u[k] > 0.05 then
    sn_dev = math.max(sn_dev, math.abs(sn[k] / (P.stress + K_cns * dil[k]) - 1))
    devs[#devs + 1] = math.abs(sn_mean[k] / (P.stress + K_cns * 0.5 * (dil[k] + dil[math.max(1, k - 1)])) - 1)
    sn_dev_mean = math.max(sn_dev_mean, devs[#devs])
  end
end
table.sort(devs)
local within = 0
for _, d in ipairs(devs) do if d <= 0.01 then within = within + 1 end end
local sn_dev_p95 = #devs > 0 and devs[math.max(1, math.ceil(0.95 * #devs))] or 0/0
local e = world:energies()
local input = e.boundary_work - e0.boundary_work
local function share(v) return input ~= 0 and v / input or 0/0 end
-- Where the bonds broke [scenarios.md 4: damage near the joint surfaces, not through the halves]:
-- depth below the mean plane (lower half) or above it (upper half, moved back by its mean
-- displacement since the genesis), 1 mm bins.
local broken_by_depth, broken_fraction = nil, nil
if world:break_count() > 0 or P.model == "fracture" then
  local shift = mean_height(upper) - upper_mean_z_mould
  local lower_bins, upper_bins = {}, {}
  local bins = math.max(1, math.ceil(T * 1e3))
  for k = 1, bins do lower_bins[k], upper_bins[k] = 0, 0 end
  for _, ev in ipairs(world:break_events()) do
    local z = ev.position[3]
    local upper_side = world:tag(ev.a) == UPPER
    local depth = upper_side and (z - shift) or -z
    local k = math.max(1, math.min(bins, math.floor(depth * 1e3) + 1))
    if upper_side then upper_bins[k] = upper_bins[k] + 1 else lower_bins[k] = lower_bins[k] + 1 end
  end
  local edges = {}
  for k = 1, bins do edges[k] = k end
  broken_by_depth = {depth_mm_upper_edges = edges, lower = lower_bins, upper = upper_bins}
  broken_fraction = world:break_count() / math.max(1, bonds_at_start)
end
local summary = {
  parameters = P,
  surface = {nx = nx, ny = ny, spacing = h, side_x = Lx, side_y = Ly},
  n_particles = #lower + #upper,
  kernels = world:simd(),                    -- the kernel set of closure and shear
  left_out_particles = N - #lower - #upper,
  n_lower = #lower,
  n_upper = #upper,
  inert_particles = world:inert_count(),
  escaped_particles = escaped_count,         -- debris thrown out of the specimen and taken out
  platen_particles = platen_particles,
  bonds = world:bond_count(),
  stress_scale = stress_scale,
  target_stress_pa = target_stress,
  stress_units = "*_mpa: MPa scaled to rock (model Pa x stress_scale / 1e6); *_pa: model Pa",
  -- The shear stress of the first record, before the platen moves: the lateral force the held
  -- platen carries once the closure is done (the normal load on inclined asperity contacts pushes
  -- the halves sideways). The shear curve starts from it.
  shear_stress_at_start_mpa = tau[1],
  closure_mm = closure:column("closure")[closure:rows()],
  peak_shear_stress_mpa = peak,
  peak_displacement_mm = u[at],
  residual_shear_stress_mpa = residual,
  -- the reference study's values for this surface, model and stress, where it has them
  reference = P.surface_file == "" and require("reference").joint(P.surface, P.model, P.stress) or nil,
  residual_window_mm = P.residual_window,    -- the residual: the mean over the last this much shear
  peak_friction = peak / P.stress,           -- tau / sigma_n at the peak
  residual_friction = residual / P.stress,
  kinetic_ratio_max = dynamic_ratio,         -- max Ek / (normal load x mean radius) while shearing
  kinetic_ratio_max_at_mm = dynamic_at,
  quasi_static = dynamic_ratio <= P.quasi_static_limit,
  overlap_ratio_max = overlap_max,           -- deepest overlap / smaller radius, over every record
  overlap_ratio_max_at = overlap_at,
  overlaps_small = overlap_max <= P.overlap_limit,
  initial_shear_stiffness_mpa_per_mm = ks,
  max_dilatancy_mm = max_dil,
  dilatancy_angle_at_peak_deg = math.deg(math.atan(slope_at(at))),
  normal_stiffness_mpa_per_mm = normal_stiffness,
  normal_stress_max_deviation = sn_dev_mean,          -- of the interval means (after 0.05 mm)
  normal_stress_max_deviation_instant = sn_dev,       -- of the values at the recorded steps
  normal_stress_deviation_p95 = sn_dev_p95,           -- 95th percentile of the interval-mean deviation
  normal_stress_within_1pct = #devs > 0 and within / #devs or 0/0,  -- fraction of records within 1 %
  broken_bonds = world:break_count(),
  broken_bond_fraction = broken_fraction,          -- of the bonds the halves held before closure
  broken_bonds_by_depth_mm = broken_by_depth,      -- counts per 1 mm of depth from the mean plane
  contact_decay_exponent = q,
  max_contacts = cmax,
  dem_surface = {mean_plane_shift_m = plane_lower.shift,
                 coinciding_fraction = plane_lower.coinciding_fraction,
                 surface_particle_fraction = cls.retained_fraction,
                 band_m = cls.band},
  energy_shares = {friction = share(e.friction - e0.friction), damping = share(e.damping - e0.damping),
                   strain = share(e.strain - e0.strain), kinetic = share(e.kinetic - e0.kinetic),
                   released = share(e.released - e0.released)},
  input_work_j = input,
  energy_balance_error = share(world:energy_balance(e0)),
  steps = world:step(),
  shear_steps = shear_steps,
  shear_rebuilds = shear_rebuilds,      -- neighbour-list rebuilds while shearing
  shear_seconds = shear_seconds,
  shear_microseconds_per_step = 1e6 * shear_seconds / math.max(shear_steps, 1),  -- cost of one step
  dt = world:dt(),
  wall_seconds = asperity.wall_time() - t_start,
  specimen_cache = cache_file,
  genesis = specimen_record,
}
asperity.write_json(P.out .. "/summary.json", summary)

-- 9. Plots ----------------------------------------------------------------------------------
local plotted, plot_error = pcall(function()
  local jf = require("joint_figures")
  local ref = require("reference")
  local surface_name = P.surface_file ~= "" and P.surface_file:match("[^/]*$") or P.surface
  local title = ("%s, %s model, %g MPa normal stress, shear along -%s (%d particles)"):format(
    surface_name, P.model, P.stress, P.direction, #lower + #upper)
  local res_from = u[rows] - P.residual_window
  jf.shear{file = P.out .. "/shear_stress.png", title = title, u = u, tau = tau, dilatancy = dil,
           peak = {at = u[at], value = peak}, residual = {value = residual, from = res_from, to = u[rows]},
           reference = P.surface_file == "" and ref.joint(P.surface, P.model, P.stress) or nil}
  local cns = P.normal_control == "stiffness"
  local asked
  if cns then
    asked = {}
    for k = 1, rows do asked[k] = P.stress + P.normal_stiffness * dil[k] end
  end
  jf.cnl{file = P.out .. "/normal_stress.png", title = title .. (cns and ": constant normal stiffness" or ": constant normal load"),
         u = u, tau = tau, sn = sn, sn_mean = sn_mean, target = P.stress, target_values = asked,
         target_label = cns and ("target %g MPa + %g MPa/mm x dilatancy"):format(P.stress, P.normal_stiffness) or nil,
         reference = not cns and ref.ratios(P.model, P.stress) or nil}
  jf.closure{file = P.out .. "/closure.png", title = title .. ": closure", closure = closure:column("closure"),
             sn = closure:column("normal_stress_mpa"), target = P.stress, stiffness = normal_stiffness}
  local peak_mark = {at = u[at], label = "peak"}
  jf.curves{file = P.out .. "/contacts.png", title = title, x = u, mark = peak_mark,
            ylabel = "contacts between the halves", curves = {{cnt}}, from_zero = true}
  jf.curves{file = P.out .. "/broken_bonds.png", title = title, x = u, mark = peak_mark,
            ylabel = "broken bonds", curves = {{shear:column("broken_bonds")}}, from_zero = true}
  local function col(name) return shear:column(name) end
  jf.curves{file = P.out .. "/energies.png", title = title .. ": energy since the shear began", x = u,
            ylabel = "energy (J, model units)",
            curves = {{col("boundary_work"), "work done by the platens"}, {col("friction"), "dissipated by friction"},
                      {col("damping"), "dissipated by damping"}, {col("strain"), "stored in contacts and bonds"},
                      {col("released"), "released by broken bonds"}, {col("kinetic"), "kinetic"}}}
end)
if not plotted then log("plots skipped: %s", tostring(plot_error)) end
-- Contact points and broken bonds over the elevation map, at the peak and at the end.
pcall(function()
  local jf = require("joint_figures")
  local events = world:break_events()
  local function broken_until(step)
    local pts = {}
    for _, ev in ipairs(events) do
      if not step or ev.step <= step then pts[#pts + 1] = {ev.position[1], ev.position[2]} end
    end
    return pts
  end
  local label = ("%s, %s model, %g MPa"):format(P.surface, P.model, P.stress)
  if peak_points then
    jf.contact_map{file = P.out .. "/contact_map_peak.png", nx = nx, ny = ny, h = h, heights = heights,
                   points = peak_points.points, broken = broken_until(peak_points.step),
                   title = ("%s: at the peak, %.2f mm of shear"):format(label, peak_points.at)}
  end
  jf.contact_map{file = P.out .. "/contact_map.png", nx = nx, ny = ny, h = h, heights = heights,
                 points = points_between(), broken = broken_until(nil),
                 title = ("%s: at the end, %.2f mm of shear"):format(label, displacement())}
end)

print(("%s %s %g MPa -%s: %d particles, peak %.2f MPa at %.2f mm, residual %.2f MPa, " ..
       "max dilatancy %.3f mm, %d broken bonds, %.0f s"):format(P.surface, P.model, P.stress,
  P.direction, summary.n_particles, peak, u[at], residual, max_dil, world:break_count(),
  summary.wall_seconds))
return summary   -- for scripts that run this one with dofile (tests, the study)
