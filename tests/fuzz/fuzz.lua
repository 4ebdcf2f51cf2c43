-- Fuzz driver of the Lua API: random sequences of calls with invalid, extreme and non-finite
-- arguments, each call in pcall. A call may fail (that is the point); what must never happen:
--   - a crash (signal, sanitizer report) or a hang: the process dies or times out;
--   - a world call that returns success while the world holds non-finite state ("silent NaN"):
--     this driver checks every world after each successful call and fails the run.
-- Besides plain calls, sequences save checkpoints and load damaged or truncated copies of them,
-- build degenerate meshes and write to unwritable paths.
--
--   asperity run tests/fuzz/fuzz.lua out=DIR [seeds=1-300] [calls=60]
-- prints one summary line; tests/fuzz/run.sh runs many seeds in bounded chunks.
local out = assert(params.out, "give out=DIRECTORY")
local first, last = tostring(params.seeds or "1-100"):match("^(%d+)%-(%d+)$")
if not first then first = tostring(params.seeds); last = first end
first, last = assert(tonumber(first), "seeds=A-B"), assert(tonumber(last), "seeds=A-B")
local calls_per_sequence = tonumber(params.calls or 60)
local verbose = params.verbose == true or params.verbose == "true"
asperity.mkdir(out)

local random = math.random
local function pick(list) return list[random(#list)] end
local function chance(p) return random() < p end

-- Values ------------------------------------------------------------------------------------

local bad_numbers = {0, -0.0, -1, 1e-300, -1e-300, 1e-320, 1e300, -1e300, 1.7e308, -1.7e308,
                     math.huge, -math.huge, 0 / 0, math.maxinteger, math.mininteger, 2 ^ 62, -2 ^ 62,
                     2 ^ 31, -2 ^ 31, 2 ^ 53 + 1, 0.5, 1e9, 1e-9}
local bad_integers = {0, -1, math.maxinteger, math.mininteger, 2 ^ 31, -2 ^ 31, 2 ^ 62, 1e300, 0 / 0,
                      0.5, 255, 256}
local junk_values = {"abc", "", true, false, {}, {1, 2}, {x = 1}, {0 / 0, 0, 0}, function() end}

local function junk()
  if chance(0.15) then return nil end
  return pick(junk_values)
end

-- A number: usually `typical()`, sometimes extreme or non-finite, rarely not a number at all.
local function num(typical)
  local r = random()
  if r < 0.75 then return typical() end
  if r < 0.95 then return pick(bad_numbers) end
  return junk()
end
local function integer(lo, hi)
  local r = random()
  if r < 0.8 then return random(lo, hi) end
  if r < 0.95 then return pick(bad_integers) end
  return junk()
end
local function small() return (random() - 0.5) * 0.02 end
local function radius() return 0.0005 + random() * 0.001 end
local function speed() return (random() - 0.5) * 0.01 end
local function vec(component)
  if chance(0.05) then return junk() end
  return {num(component), num(component), num(component)}
end

-- Paths: mostly inside out/, sometimes unwritable or not paths at all.
local function path(ext)
  local r = random()
  if r < 0.7 then return out .. "/f" .. random(1, 6) .. ext end
  return pick{out .. "/no/such/dir/x" .. ext, "", out, "/proc/no_such/x" .. ext, out .. "/", 42}
end

-- State of a sequence -------------------------------------------------------------------------

local S
local stats = {sequences = 0, calls = 0, failed = 0, silent = 0}
local silent_reports = {}

local function world() return #S.worlds > 0 and pick(S.worlds) or nil end
local function particle_id(w)
  local n = w:particle_count()
  if n > 0 and chance(0.85) then return random(1, n) end
  return integer(-2, n + 2)
end
local function ids(w)
  local n = w:particle_count()
  if chance(0.1) then return junk() end
  if chance(0.15) then return function(id) return id % 2 == 0 end end
  local list = {}
  for _ = 1, random(0, math.min(n, 6)) do list[#list + 1] = particle_id(w) end
  return list
end
local function group_id(w) return chance(0.85) and random(1, math.max(1, w:group_count())) or integer(-1, 3) end
local function wall_id(w) return chance(0.85) and random(1, math.max(1, w:wall_count())) or integer(-1, 3) end

local function material()
  if chance(0.5) then return nil end
  return {kn = num(function() return 10 ^ random(-2, 4) end), ks = num(function() return 10 ^ random(-3, 3) end),
          friction = num(function() return random() end)}
end

local function motion()
  if chance(0.2) then return junk() end
  local dofs = {"free", "fixed", "velocity", "servo"}
  local m = {}
  if chance(0.7) then
    m.translation = chance(0.5) and pick(dofs) or {pick(dofs), pick(dofs), pick(dofs)}
    if chance(0.05) then m.translation = pick{"flying", {"free"}, 3} end
  end
  if chance(0.4) then m.velocity = vec(speed) end
  if chance(0.4) then
    local servo = {}
    for _, k in ipairs{"target_force", "stiffness", "gain", "relaxation", "max_velocity", "integral_time"} do
      if chance(0.4) then servo[k] = num(function() return random() * 1e-3 end) end
    end
    m.servo = servo
  end
  if chance(0.3) then m.rotation = pick{"free", "fixed", "velocity", "servo", "spin"} end
  if chance(0.3) then m.angular_velocity = vec(speed) end
  if chance(0.3) then m.damping = num(function() return random() - 0.5 end) end
  return m
end

local function new_world()
  local settings = {}
  if chance(0.3) then settings.gravity = vec(function() return -9.81 * random() end) end
  if chance(0.2) then settings.material = material() end
  if chance(0.2) then settings.density = num(function() return 2500 end) end
  if chance(0.15) then settings.damping = num(function() return random() end) end
  if chance(0.1) then settings.rotation = chance(0.5) end
  if chance(0.1) then settings.dt_safety = num(function() return random() end) end
  if chance(0.1) then settings.skin = num(function() return random() * 1e-3 end) end
  if chance(0.1) then settings.threads = integer(0, 2) end
  if chance(0.05) then settings.dt_interval = integer(1, 200) end
  if chance(0.05) then settings.reorder_interval = integer(0, 20) end
  if chance(0.05) then settings.simd = pick{"auto", "scalar", "float", "avx9000", 3} end
  if chance(0.05) then settings.track_energy = chance(0.5) end
  if chance(0.05) then settings.lock_bonded_rotation = chance(0.5) end
  if chance(0.05) then settings.allow_dt_above_estimate = chance(0.5) end
  if chance(0.05) then settings.dt = num(function() return random() * 1e-3 end) end
  local w = asperity.world(settings)
  for _ = 1, random(0, 12) do
    w:add_particle({small(), small(), small()}, radius())
  end
  S.worlds[#S.worlds + 1] = w
  return w
end

local function new_map()
  local m = asperity.surface.generate{name = pick{"S1", "S5", "S8"}, n = random(5, 33), seed = random(1, 9),
                                      side = 0.01 + random() * 0.05}
  S.maps[#S.maps + 1] = m
  return m
end
local function map() return #S.maps > 0 and pick(S.maps) or new_map() end

local function corrupt(bytes)
  local r = random()
  if r < 0.3 then return bytes:sub(1, random(0, #bytes)) end                    -- truncated
  local b = {bytes:byte(1, -1)}
  for _ = 1, random(1, 8) do
    local at = r < 0.6 and random(1, math.min(#b, 600)) or random(1, #b)        -- header or body
    b[at] = random(0, 255)
  end
  local parts = {}
  for i = 1, #b, 4096 do parts[#parts + 1] = string.char(table.unpack(b, i, math.min(#b, i + 4095))) end
  return table.concat(parts)
end

-- Actions: each one call into the API (with arguments drawn above). --------------------------

local W = {}  -- world actions: function(w)
W.add_particle = function(w) return w:add_particle(vec(small), num(radius), chance(0.3) and num(function() return 2500 end) or nil) end
W.add_particles = function(w)
  local list, radii = {}, {}
  for _ = 1, random(0, 5) do list[#list + 1] = vec(small); radii[#radii + 1] = num(radius) end
  return w:add_particles(list, chance(0.5) and radii or num(radius))
end
W.set_position = function(w) return w:set_position(particle_id(w), vec(small)) end
W.set_velocity = function(w) return w:set_velocity(particle_id(w), vec(speed)) end
W.set_angular_velocity = function(w) return w:set_angular_velocity(particle_id(w), vec(speed)) end
W.set_force = function(w) return w:set_force(particle_id(w), vec(function() return (random() - 0.5) * 1e-4 end)) end
W.set_radius = function(w) return w:set_radius(particle_id(w), num(radius)) end
W.set_density = function(w) return w:set_density(particle_id(w), num(function() return 2500 end)) end
W.scale_radii = function(w) return w:scale_radii(num(function() return 0.9 + 0.2 * random() end)) end
W.set_rotation_locked = function(w) return w:set_rotation_locked(particle_id(w), chance(0.5)) end
W.getters = function(w)
  local id = particle_id(w)
  local getter = pick{"position", "velocity", "angular_velocity", "force", "torque", "radius", "mass", "group_of", "tag", "flags"}
  return w[getter](w, id)
end
W.bulk = function(w)
  local a = w[pick{"positions", "velocities", "forces", "radii"}](w)
  if chance(0.5) then return w[pick{"set_positions", "set_velocities"}](w, chance(0.8) and a or junk()) end
end
W.add_plane = function(w)
  return w:add_plane{point = vec(small), normal = chance(0.7) and {0, 0, 1} or vec(function() return random() - 0.5 end),
                     material = material()}
end
W.add_mesh = function(w)
  local v, t = {}, {}
  for _ = 1, random(0, 6) do v[#v + 1] = chance(0.3) and v[1] or vec(small) end
  for _ = 1, random(0, 4) do t[#t + 1] = {integer(1, #v), integer(1, #v), integer(1, #v)} end
  return w:add_mesh{vertices = v, triangles = t, material = material()}
end
W.wall = function(w)
  local f = pick{"set_wall_velocity", "wall_velocity", "wall_displacement", "wall_force", "remove_wall", "wall_count"}
  return w[f](w, wall_id(w), vec(speed))
end
W.add_group = function(w) return w:add_group(ids(w), motion()) end
W.group_motion = function(w)
  local f = pick{"set_group_motion", "set_group_velocity", "set_group_force", "group_motion", "group_force",
                 "group_impulse", "group_torque", "group_position", "group_velocity", "group_mass", "group_members"}
  local arg = f == "set_group_motion" and motion() or vec(speed)
  return w[f](w, group_id(w), arg)
end
W.set_inert = function(w) return w:set_inert(ids(w), chance(0.8)) end
W.labels = function(w)
  local r = random()
  if r < 0.4 then return w:set_tag(ids(w), integer(0, 3)) end
  if r < 0.7 then return w:set_flags(ids(w), integer(0, 255)) end
  return w:contact_summary(integer(0, 3), integer(0, 3), integer(0, 255))
end
W.install_bonds = function(w)
  local o = {}
  if chance(0.5) then o.beam_kn = num(function() return 10 ^ random(-2, 3) end) end
  if chance(0.3) then o.beam_ks = num(function() return 10 ^ random(-3, 2) end) end
  if chance(0.3) then o.radius_factor = num(function() return random() end) end
  if chance(0.5) then o.breakable = chance(0.5) end
  if chance(0.6) then o.tensile_strength = num(function() return 10 ^ random(-3, 3) end) end
  if chance(0.5) then o.tolerance = num(function() return random() * 1e-3 end) end
  if chance(0.2) then o.ids = ids(w) end
  if chance(0.2) then o.stress_free = chance(0.5) end
  return w:install_bonds(o)
end
W.bonds = function(w)
  local r = random()
  if r < 0.3 then return w:set_bond_strength{breakable = chance(0.5), tensile_strength = num(function() return 10 ^ random(-3, 3) end)} end
  if r < 0.4 then return w:remove_bonds() end
  if r < 0.7 then return w:bonds() end
  return w:break_events(integer(1, 3))
end
-- Step counts: small, or invalid; never a huge valid one (a run of 2^62 steps is a long run, not
-- a hang: Ctrl-C stops it).
local function steps()
  if chance(0.9) then return random(1, 40) end
  return pick{0, -1, math.mininteger, -2 ^ 62, 0.5, 1e300, 0 / 0, math.huge, "x", {}}
end
W.cycle = function(w) return w:cycle(steps()) end
W.run = function(w)
  local o = {steps = steps(), progress = false}
  if chance(0.3) then o.stop_when = pick{"equilibrium", function(x) return x:step() % 7 == 0 end, "never", 3} end
  if chance(0.2) and o.stop_when == "equilibrium" then o.ratio = num(function() return 1e-3 end) end
  if chance(0.3) then o.every = integer(1, 20) end
  if chance(0.1) then o.callback = function(x) x:set_velocity(1, {0 / 0, 0, 0}) end end
  return w:run(o)
end
W.time_step = function(w)
  local f = pick{"set_dt", "set_dt_safety", "set_skin", "set_friction", "critical_dt", "dt", "step", "time",
                 "set_threads", "simd", "stats", "rebuild_neighbors"}
  local arg
  if f == "set_dt" then arg = num(function() return chance(0.5) and 0 or w:critical_dt() * random() end)
  elseif f == "set_threads" then arg = integer(0, 2)
  else arg = num(function() return random() * 1e-3 end) end
  return w[f](w, arg)
end
W.measure = function(w)
  local f = pick{"energies", "unbalanced_force_ratio", "contacts", "contact_count", "max_overlap_ratio", "settings",
                 "energy_balance", "bond_count", "break_count", "particle_count", "inert_count"}
  if f == "energy_balance" then return w:energy_balance(chance(0.8) and w:energies() or junk()) end
  return w[f](w)
end
W.save_load = function(w)
  local p = path(".h5")
  w:save(p)
  local f = io.open(p, "rb")
  if not f then return end
  local bytes = f:read("a")
  f:close()
  if chance(0.6) then
    local damaged = out .. "/damaged.h5"
    local g = assert(io.open(damaged, "wb"))
    g:write(corrupt(bytes))
    g:close()
    p = damaged
  end
  local loaded = asperity.load(p, chance(0.2) and {threads = integer(0, 2)} or nil)
  S.worlds[#S.worlds + 1] = loaded
  loaded:cycle(random(1, 5))
end
-- Script code that runs inside an API call (predicates, run callbacks) and changes the world.
W.reentrant = function(w)
  local r = random()
  local touch = function(x)
    local k = random()
    if k < 0.3 then x:add_particle({small(), small(), small()}, radius())
    elseif k < 0.5 then x:remove_bonds()
    elseif k < 0.7 then x:set_radius(1, num(radius))
    elseif k < 0.85 then x:cycle(1)
    else error("boom") end
  end
  if r < 0.4 then return w:add_group(function(id) touch(w); return id % 2 == 1 end, motion()) end
  if r < 0.6 then return w:set_tag(function(id) touch(w); return true end, 1) end
  return w:run{steps = random(1, 30), every = random(1, 5), progress = false, callback = touch,
               stop_when = chance(0.3) and function(x) touch(x); return false end or nil}
end
W.read_back = function(w)
  local p = out .. "/f" .. random(1, 6) .. ".h5"
  if chance(0.5) then  -- a damaged copy of a file written before (surface, series, snapshot, checkpoint)
    local f = io.open(p, "rb")
    if f then
      local bytes = f:read("a")
      f:close()
      p = out .. "/damaged_read.h5"
      local g = assert(io.open(p, "wb"))
      g:write(corrupt(bytes))
      g:close()
    end
  end
  local r = random()
  if r < 0.3 then return asperity.h5_datasets(p) end
  if r < 0.6 then return asperity.read_h5(p, pick{"particles/x", "height", "x", "/", "", "settings/gravity"}) end
  if r < 0.8 then return asperity.h5_attribute(p, pick{"/", "height", "x"}, pick{"units", "spacing", "zz"}) end
  return asperity.surface.load(p)
end
W.snapshots = function(w)
  local s = asperity.snapshots{dir = chance(0.8) and out .. "/snaps" or path(""), contacts = chance(0.5)}
  return s:write(w, chance(0.3) and {note = pick{"x", 1, true}} or nil)
end

local A = {}  -- module actions: function()
A.world = function() return new_world() end
A.json = function()
  local t, cur = {}, nil
  cur = t
  for _ = 1, random(0, 80) do
    local nxt = chance(0.5) and {} or {num(small)}
    cur[pick{1, "k", 2}] = nxt
    cur = nxt
  end
  if chance(0.2) then cur.self = t end
  if chance(0.3) then cur.x = junk() end
  if chance(0.5) then return asperity.json(t, integer(0, 4)) end
  return asperity.write_json(path(".json"), t)
end
A.array = function()
  local a = chance(0.5) and asperity.array(integer(0, 20), integer(1, 4), num(small)) or asperity.array({num(small), num(small)})
  S.arrays[#S.arrays + 1] = a
  local rows, cols = a:size()
  local f = pick{"get", "set", "row", "col", "sum", "mean", "min", "max", "norms", "totable", "flat", "index", "newindex"}
  if f == "index" then return a[integer(1, rows)] end
  if f == "newindex" then a[integer(1, rows)] = cols == 3 and vec(small) or num(small); return end
  return a[f](a, integer(1, rows), integer(1, cols), num(small))
end
A.vec = function()
  local v = asperity.vec(num(small), num(small), num(small))
  return (v + v) * num(small), v:norm(), v:dot(vec(small)), v:cross(vec(small)), tostring(v / num(small))
end
A.series = function()
  local s = asperity.series{"a [m]", "b"}
  for _ = 1, random(0, 5) do s:record(num(small), num(small)) end
  if chance(0.3) then s:record{a = num(small), c = 1} end
  local r = random()
  if r < 0.3 then return s:column(pick{"a", "b", "c", 1, 5, 0}) end
  if r < 0.5 then return s:last(pick{"a", "zz"}) end
  if r < 0.7 then return s:write_h5(path(".h5")) end
  return s:write_csv(path(".csv"))
end
A.surface = function()
  local m = map()
  local nx, ny = m:size()
  local r = random()
  if r < 0.05 then return m:colatitude() end
  local dir = chance(0.7) and num(function() return random() * 6.3 end) or pick{"x", "y", "radial", "z"}
  local f = pick{"at", "structure_function", "variogram", "autocovariance", "psd", "slopes", "colatitude", "abbott",
                 "row", "column", "profile", "shifted", "amplitude", "mean_plane", "remove_mean_plane", "heights"}
  if f == "at" then return m:at(integer(1, nx), integer(1, ny)) end
  if f == "structure_function" or f == "variogram" or f == "autocovariance" then
    return m[f](m, dir, num(function() return random() * 0.01 end))
  end
  if f == "psd" then return m:psd{angle = chance(0.5) and num(small) or nil, half_width = chance(0.3) and num(small) or nil} end
  if f == "slopes" then return m:slopes(dir, integer(1, 30)) end
  if f == "colatitude" then return m:colatitude(dir, {step = chance(0.5) and num(function() return random() * 1e-3 end) or nil, bins = chance(0.5) and integer(1, 100) or nil}) end
  if f == "abbott" then return m:abbott(integer(2, 300)) end
  if f == "row" then return m:row(integer(1, ny)) end
  if f == "column" then return m:column(integer(1, nx)) end
  if f == "profile" then
    local side = nx * m:spacing()
    return m:profile(num(function() return random() * side end), num(function() return random() * side end), dir,
                     chance(0.5) and num(function() return m:spacing() * (0.5 + random()) end) or nil)
  end
  if f == "shifted" then S.maps[#S.maps + 1] = m:shifted(num(small)); return end
  return m[f](m)
end
A.surface_make = function()
  local r = random()
  if r < 0.3 then return new_map() end
  if r < 0.5 then
    return asperity.surface.generate{name = chance(0.8) and pick{"S1", "S4", "S9"} or nil, n = integer(3, 40),
                                     seed = integer(0, 9), side = num(function() return 0.05 end),
                                     H = chance(0.3) and num(function() return random() end) or nil,
                                     Lc = chance(0.3) and num(function() return 0.01 end) or nil,
                                     variance = chance(0.3) and num(function() return 1e-8 end) or nil}
  end
  if r < 0.7 then
    local h = {}
    for i = 1, random(0, 30) do h[i] = chance(0.9) and small() or num(small) end
    local m = asperity.surface.height_map{heights = h, spacing = num(function() return 1e-3 end), nx = integer(1, 6)}
    S.maps[#S.maps + 1] = m
    return m
  end
  if r < 0.85 then
    local m = map()
    local p = path(".h5")
    m:save(p)
    local loaded = asperity.surface.load(p, chance(0.3) and {spacing = num(function() return 1e-3 end)} or nil)
    S.maps[#S.maps + 1] = loaded
    return
  end
  local p = path(".csv")
  map():save_csv(p)
  local loaded = asperity.surface.load_grid(p, chance(0.3) and {spacing = num(function() return 1e-3 end)} or nil)
  S.maps[#S.maps + 1] = loaded
end
A.profilometer = function()
  local w = world()
  if not w or w:particle_count() == 0 then return end
  local m = map()
  local nx, ny = m:size()
  local grid = chance(0.5) and m or {nx = integer(1, 40), ny = integer(1, 40), spacing = num(function() return 1e-3 end)}
  local p = asperity.surface.profilometer{positions = w:positions(), radii = w:radii(), grid = grid,
                                          origin = chance(0.5) and {num(small), num(small)} or nil,
                                          side = pick{"lower", "upper", "upper", "lower", "middle"},
                                          ids = chance(0.2) and ids(w) or nil}
  S.maps[#S.maps + 1] = p.surface
  local r = random()
  if r < 0.2 and chance(0.5) then p.particle:set(integer(1, ny), integer(1, nx), num(function() return 1 end)) end
  if r < 0.5 then return asperity.surface.classify(p, m, chance(0.5) and {band = num(function() return 1e-3 end), shift = chance(0.5) and num(small) or nil} or nil) end
  if r < 0.7 then return asperity.surface.mean_plane(p, m, chance(0.3) and {levels = integer(1, 50)} or nil) end
  return p.surface:colatitude()
end
local function analysis_options()
  if chance(0.3) then return nil end
  local o = {}
  for _, k in ipairs{"max_lag", "structure_fit_min_lag", "structure_fit_max_lag", "psd_fit_min_frequency",
                     "psd_fit_max_frequency", "sector_half_width"} do
    if chance(0.15) then o[k] = num(function() return random() * 1e-3 end) end
  end
  for _, k in ipairs{"directions", "abbott_levels", "colatitude_bins", "slope_max_steps"} do
    if chance(0.15) then o[k] = integer(1, 12) end
  end
  if chance(0.1) then o.window = pick{"hann", "none", "kaiser"} end
  if chance(0.1) then o.remove_mean_plane = chance(0.5) end
  return o
end
A.analysis = function()
  local m = map()
  local r = random()
  if r < 0.4 then return m:analyze(analysis_options()) end
  if r < 0.7 then return m:polar(analysis_options()) end
  if r < 0.85 then return m:psd{angle = chance(0.5) and num(small) or nil, half_width = chance(0.5) and num(small) or nil,
                                window = chance(0.2) and pick{"hann", "x"} or nil} end
  local o = analysis_options() or {}
  o.seed = chance(0.8) and random(0, 5) or integer(0, 3)
  o.levels = chance(0.5) and {num(function() return random() end), num(function() return random() end)} or nil
  return asperity.surface.noise_study(m, o)
end
A.profile_analysis = function()
  local h = {}
  for i = 1, random(0, 40) do h[i] = chance(0.95) and small() or num(small) end
  if chance(0.5) then
    return asperity.surface.analyze_profile(h, num(function() return 1e-3 end))
  end
  local x, y = {}, {}
  for i = 1, #h do x[i] = chance(0.9) and i or num(small); y[i] = math.abs(h[i]) end
  return asperity.surface.fit_power_law(x, y, num(function() return 1 end), num(function() return 30 end))
end

-- Silent NaN: a world that holds non-finite values after a call that returned success.
local function finite(v) return v == v and v > -math.huge and v < math.huge end
local function world_problem(w)
  local n = w:particle_count()
  for _, a in ipairs{w:positions(), w:velocities()} do
    for i = 1, n do
      local x, y, z = a:row(i)
      if not (finite(x) and finite(y) and finite(z)) then return "particle " .. i .. " position/velocity" end
    end
  end
  for i = 1, n do
    local v = w:angular_velocity(i)
    if not (finite(v[1]) and finite(v[2]) and finite(v[3])) then return "particle " .. i .. " angular velocity" end
  end
  for g = 1, w:group_count() do
    for _, v in ipairs{w:group_position(g), w:group_velocity(g)} do
      if not (finite(v[1]) and finite(v[2]) and finite(v[3])) then return "group " .. g end
    end
  end
  for k = 1, w:wall_count() do
    local d = w:wall_displacement(k)
    if not (finite(d[1]) and finite(d[2]) and finite(d[3])) then return "wall " .. k .. " displacement" end
  end
  if not (finite(w:time()) and finite(w:dt())) then return "time or dt" end
end

local world_actions, module_actions = {}, {}
for name in pairs(W) do world_actions[#world_actions + 1] = name end
for name in pairs(A) do module_actions[#module_actions + 1] = name end
table.sort(world_actions)
table.sort(module_actions)

local function sequence(seed)
  math.randomseed(seed)
  S = {worlds = {}, maps = {}, arrays = {}, unhealthy = setmetatable({}, {__mode = "k"})}
  local log = {}
  for _ = 1, calls_per_sequence do
    local name, ok, err, w
    local module = #S.worlds == 0 or chance(0.25)
    name = module and pick(module_actions) or pick(world_actions)
    if verbose then io.stderr:write("  call " .. name .. "\n") end
    if module then
      ok, err = pcall(A[name])
    else
      w = world()
      ok, err = pcall(W[name], w)
    end
    stats.calls = stats.calls + 1
    log[#log + 1] = name .. (ok and "" or " (error)")
    if not ok then
      stats.failed = stats.failed + 1
      if verbose then print(seed, name, err) end
      if asperity.is_interrupted(err) then error(err) end
    end
    -- Every world is checked after every call (a callback or a load may touch another one). A
    -- world may hold non-finite values only after a step stopped with "simulation stopped" (the
    -- health check; the state is kept for inspection, and the next step stops again): then it is
    -- marked unhealthy until it is finite again. Anything else is a silent NaN: a call that
    -- returned success, or failed for another reason, and left non-finite state behind.
    local stopped = not ok and tostring(err):find("simulation stopped") ~= nil
    for k = #S.worlds, 1, -1 do
      local x = S.worlds[k]
      local problem = world_problem(x)
      if not problem then
        S.unhealthy[x] = nil
      elseif stopped then
        S.unhealthy[x] = true
      elseif not S.unhealthy[x] or (ok and x == w and (name == "cycle" or name == "run")) then
        stats.silent = stats.silent + 1
        silent_reports[#silent_reports + 1] = string.format("seed %d: after %s%s, world %d: non-finite %s (calls: %s)",
                                                            seed, name, ok and "" or " (error: " .. tostring(err) .. ")",
                                                            k, problem, table.concat(log, ", "))
        table.remove(S.worlds, k)
      end
    end
  end
  stats.sequences = stats.sequences + 1
end

for seed = first, last do
  io.stderr:write("fuzz seed " .. seed .. "\n")
  sequence(seed)
  if seed % 25 == 0 then collectgarbage() end
end
for _, r in ipairs(silent_reports) do print("SILENT NaN " .. r) end
print(string.format("fuzz: seeds %d-%d, sequences %d, calls %d (%d refused with an error), silent NaN %d",
                    first, last, stats.sequences, stats.calls, stats.failed, stats.silent))
if stats.silent > 0 then error("fuzz: " .. stats.silent .. " calls returned success with non-finite state") end
print("PASS")
