-- Two spheres collide head-on: record the contact force at every step and compare the
-- contact duration with the linear-spring result T = pi * sqrt(m_eff / kn).
--   build/asperity run scripts/examples/02_two_spheres.lua out=out/collision
local out = params.out or "out/collision"
asperity.mkdir(out)

-- No damping and no gravity: an elastic collision.
local kn = 1e3
local w = asperity.world{material = {kn = kn, ks = kn / 10}, damping = 0, threads = 1}
local a = w:add_particle({-0.012, 0, 0}, 0.01)     -- ids count from 1
local b = w:add_particle({0.012, 0, 0}, 0.01)
w:set_velocity(a, {0.05, 0, 0})
w:set_velocity(b, {-0.05, 0, 0})

local m_eff = w:mass(a) * w:mass(b) / (w:mass(a) + w:mass(b))
local T = math.pi * math.sqrt(m_eff / kn)
w:set_dt(T / 200)                                  -- fixed step: 200 per contact

-- One step at a time is fine from Lua: a call costs about what it costs from C++.
local s = asperity.series{"time [s]", "normal_force [N]", "overlap [m]"}
local first, last
for _ = 1, 2000 do
  w:cycle(1)
  local c = w:contacts()[1]                        -- nil when not touching
  if c then
    first = first or w:time()
    last = w:time()
  end
  s:record(w:time(), c and c.normal_force or 0, c and c.overlap or 0)
end

s:write(out .. "/contact")
s:plot{file = out .. "/contact_force.png", x = "time", y = "normal_force",
       title = "head-on collision of two spheres"}
print(("contact lasted %.4g s, linear spring: %.4g s; rebound speed %.4g m/s"):format(
  last - first + w:dt(), T, w:velocity(b).x))
