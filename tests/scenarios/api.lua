-- A tour of the bound API: everything a script does, checked from Lua.
local w = asperity.world{gravity = {0, 0, -9.81}, material = {kn = 1e3, ks = 1e2, friction = 0.3},
                         density = 2000, damping = 0.5, threads = 1}
assert(w:settings().material.kn == 1e3 and w:settings().density == 2000)

-- particles, one by one and in bulk
local first = w:add_particle({0, 0, 0.05}, 0.01)
assert(first == 1 and w:particle_count() == 1)
local f2, l2 = w:add_particles({{0.03, 0, 0.05}, {0.06, 0, 0.05}}, 0.01)
assert(f2 == 2 and l2 == 3)
local f3, l3 = w:add_particles(asperity.array({0.09, 0, 0.05, 0.12, 0, 0.05}), {0.01, 0.012})
assert(f3 == 4 and l3 == 5 and w:radius(5) == 0.012)
assert(math.abs(w:mass(1) - 2000 * 4 / 3 * math.pi * 1e-6) < 1e-12, "density from the settings")
w:set_density(1, 4000)
assert(w:density(1) == 4000 and math.abs(w:mass(1) - 4000 * 4 / 3 * math.pi * 1e-6) < 1e-12, "mass follows the density")
w:set_density(1, 2000)

-- vectors
local p = w:position(2)
assert(p.x == 0.03 and p[1] == 0.03 and tostring(p) == "{0.03, 0, 0.05}")
assert((p + asperity.vec(1, 1, 1)).z == 1.05 and (2 * p).x == 0.06 and (p - p):norm() == 0)

-- arrays
local pos = w:positions()
assert(#pos == 5 and select(2, pos:size()) == 3 and pos[2].x == 0.03)
local x, y, z = pos:row(3)
assert(x == 0.06 and y == 0 and z == 0.05)
assert(pos:col(1):max() == 0.12 and math.abs(pos:col(1):sum() - 0.30) < 1e-12)
assert(#w:radii() == 5 and w:radii()[5] == 0.012)
local a = asperity.array(3, 1, 7)
a[2] = 1
assert(a:sum() == 15 and a:min() == 1)

-- walls
local floor = w:add_plane{point = {0, 0, 0}, normal = {0, 0, 1}}
assert(floor == 1 and w:wall_count() == 1)
local mesh = require("heightmap").mesh{heights = {0, 0, 0, 0}, nx = 2, ny = 2, dx = 1, origin = {-0.5, -0.5, -1}}
local m = w:add_mesh{vertices = mesh.vertices, triangles = mesh.triangles, material = {friction = 0.1}}
assert(m == 2)
w:set_wall_velocity(m, {0, 0, -0.1})
assert(w:wall_velocity(m).z == -0.1)

-- groups, by ids and by predicate
local g1 = w:add_group({4, 5}, {translation = "fixed"})
assert(g1 == 1 and w:group_of(4) == 1 and w:group_of(1) == nil)
local g2 = w:add_group(function(id, pos, r) return id <= 2 end)
assert(g2 == 2 and #w:group_members(g2) == 2)
w:set_inert({2})
assert(#w:group_members(g2) == 2, "an inert member is still a member")
w:set_group_velocity(g2, {0.01, 0, 0})
local motion = w:group_motion(g2)
assert(motion.translation[1] == "velocity" and motion.velocity.x == 0.01)
w:set_group_motion(g2, {translation = {"velocity", "fixed", "free"}})
assert(w:group_motion(g2).translation[3] == "free")
assert(w:group_motion(g2).damping < 0, "default: the world's local damping")
w:set_group_motion(g2, {translation = {"velocity", "fixed", "servo"}, damping = 0,
                        servo = {target_force = 1e-6, integral_time = 0.01}})
assert(w:group_motion(g2).damping == 0 and w:group_motion(g2).servo[3].integral_time == 0.01)
-- The fields not given are the servo's defaults, which scripts read rather than write again.
local servo_defaults = asperity.servo_defaults()
assert(w:group_motion(g2).servo[3].relaxation == servo_defaults.relaxation and servo_defaults.relaxation > 0)
assert(w:group_motion(g2).servo[3].max_velocity == servo_defaults.max_velocity and servo_defaults.target_force == 0)
local ok, err = pcall(w.set_group_motion, w, g2, {servo = {integral_time = -1}})
assert(not ok and tostring(err):find("integral_time"), tostring(err))
ok, err = pcall(w.set_group_motion, w, g2, {damping = 1.5})
assert(not ok and tostring(err):find("damping"), tostring(err))
w:set_group_motion(g2, {translation = {"velocity", "fixed", "free"}, damping = -1})

-- labels
w:set_tag(function(id) return id >= 4 end, 7)
assert(w:tag(4) == 7 and w:tag(1) == 0)
w:set_flags({1}, 3)
assert(w:flags(1) == 3)
local summary = w:contact_summary(0, 7)
assert(summary.count >= 0 and summary.force.x ~= nil)

-- running
local calls = 0
local steps, reason = w:run{steps = 500, every = 50, callback = function() calls = calls + 1 end,
                            progress = false}
assert(steps == 500 and reason == "steps" and calls == 10, "run: " .. steps .. " " .. reason .. " " .. calls)
local n, why = w:run{steps = 1000, every = 10, stop_when = function(w) return w:step() >= 520 end}
assert(n == 20 and why == "stop_when", n .. " " .. why)
local sampled = {}
n = w:run{steps = 70, every = 50, sample_every = 20, sample = function(w) sampled[#sampled + 1] = w:step() end}
assert(n == 70 and #sampled == 3 and sampled[1] == 540 and sampled[3] == 580, "samples at " .. table.concat(sampled, " "))
assert(w:cycle(5) == 5 and w:step() == 595)
do  -- asperity.remove_all: a folder and what it holds; nothing there is not an error
  local dir = os.tmpname()
  os.remove(dir)
  asperity.mkdir(dir .. "/sub")
  local f = io.open(dir .. "/sub/file", "w"); f:write("x"); f:close()
  assert(asperity.remove_all(dir) == 3 and not io.open(dir .. "/sub/file"), "remove_all")
  assert(asperity.remove_all(dir) == 0)
  local ok, err = pcall(asperity.remove_all, "/")
  assert(not ok and err:find("refusing to remove '/'", 1, true), err)
end
do  -- a run resumed with steps_done: the cap and the cadences count on from there (checks at 40,
    -- 50 of the run; samples at 48, 60), so 595 + 17 steps end a run of 60 begun 43 steps earlier
  local checks, samples = {}, {}
  n = w:run{steps = 60, every = 10, steps_done = 43, callback = function(w) checks[#checks + 1] = w:step() end,
            sample_every = 12, sample = function(w) samples[#samples + 1] = w:step() end}
  assert(n == 60 and w:step() == 612, ("steps_done: %d steps, at %d"):format(n, w:step()))
  assert(table.concat(checks, " ") == "602 612", "checks at " .. table.concat(checks, " "))
  assert(table.concat(samples, " ") == "600 612", "samples at " .. table.concat(samples, " "))
  local ok, err = pcall(function() return w:run{steps = 10, steps_done = 10} end)
  assert(not ok and err:find("option 'steps_done' (10) must be below steps (10)", 1, true), err)
  ok, err = pcall(function() return w:run{steps = 10, steps_done = -1} end)
  assert(not ok and err:find("option 'steps_done' must be >= 0", 1, true), err)
end
assert(w:dt() > 0 and w:time() > 0 and w:critical_dt() > 0)
assert(type(w:simd()) == "string" and w:stats().rebuilds >= 1)
local e = w:energies()
assert(e.kinetic >= 0 and e.gravity_work ~= nil)
assert(type(w:energy_balance(e)) == "number")
assert(w:group_force(g1).z ~= nil and w:group_mass(g1) > 0)
do  -- the impulse grows by group_force x dt each step
  local j0, f = w:group_impulse(g1), nil
  w:cycle(1)
  f = w:group_force(g1)
  local j1 = w:group_impulse(g1)
  assert(math.abs((j1.z - j0.z) - f.z * w:dt()) <= 1e-12 * math.abs(f.z * w:dt()) + 1e-300,
         "group_impulse: " .. (j1.z - j0.z) .. " vs " .. f.z * w:dt())
end

-- bulk writes (group members move with their group, so a world without groups)
local free = asperity.world()
free:add_particles({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, 0.1)
local v = asperity.array(3, 3)
v[2] = {0, 0.5, 0}
free:set_velocities(v)
assert(free:velocity(2).y == 0.5 and free:velocity(3):norm() == 0)
free:set_positions(free:positions())

-- help and documentation
assert(asperity.doc(w.cycle):find("world:cycle", 1, true))
assert(asperity.doc(w):find("World", 1, true))

-- errors are Lua errors with useful messages
local ok, err = pcall(function() return w:add_particle({0, 0}, 0.01) end)
assert(not ok and err:find("bad argument #1 to 'add_particle'", 1, true), err)
ok, err = pcall(function() return w:run{steps = 10, stop_when = "forever"} end)
assert(not ok and err:find("must be a function(world) or \"equilibrium\"", 1, true), err)
ok, err = pcall(function() return w:run{steps = 10, sample = print} end)
assert(not ok and err:find("option 'sample' needs sample_every = (steps between samples, >= 1)", 1, true), err)
ok, err = pcall(function() return w:run{steps = 10, sample_every = 5} end)
assert(not ok and err:find("option 'sample_every' needs sample = (a function(world))", 1, true), err)
ok, err = pcall(function() return w:position(99) end)
assert(not ok and err:find("no particle 99 (valid: 1..5)", 1, true), err)
ok, err = pcall(function() return w:run{steps = 10, every = 5, callback = function() error("inner") end} end)
assert(not ok and err:find("api.lua:%d+: inner"), err)
print("PASS")

-- The process's memory: resident now and its peak, in bytes; 64 MB held raise both by about that.
do
  local before = asperity.memory()
  assert(before.resident > 0 and before.peak >= before.resident, "memory: resident and peak")
  local held = string.rep("x", 64 * 2^20)
  local now = asperity.memory()
  assert(now.resident >= before.resident + 60 * 2^20 and now.peak >= now.resident,
         ("memory: %d -> %d bytes resident with 64 MB held"):format(before.resident, now.resident))
  assert(#held == 64 * 2^20)
end
