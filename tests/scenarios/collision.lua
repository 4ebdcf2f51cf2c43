-- Two equal spheres collide head-on with no damping, no gravity and no rotation. For the
-- linear contact spring the contact lasts half a period of the two-body oscillator,
--   T = pi * sqrt(m_eff / kn),  m_eff = m1 m2 / (m1 + m2),
-- the largest overlap is v_rel * sqrt(m_eff / kn), and with nothing dissipating they separate
-- with the speeds they came in with (model.md 2 and 4).
local kn, r, v0 = 1e3, 0.01, 0.05
local w = asperity.world{material = {kn = kn, ks = kn / 10, friction = 0.5}, damping = 0,
                         rotation = false}
local a = w:add_particle({-0.011, 0, 0}, r)
local b = w:add_particle({0.011, 0, 0}, r)
w:set_velocity(a, {v0, 0, 0})
w:set_velocity(b, {-v0, 0, 0})

local m = w:mass(a)
local m_eff = m * m / (m + m)
local T = math.pi * math.sqrt(m_eff / kn)
w:set_dt(T / 400)
local dt = w:dt()
assert(math.abs(dt - T / 400) < 1e-15, "the fixed dt is used")

local e0 = w:energies()
local steps_in_contact, max_overlap, worst_balance = 0, 0, 0
local seen = false
for _ = 1, 100000 do
  w:cycle(1)
  local cs = w:contacts()
  if #cs > 0 then
    seen = true
    steps_in_contact = steps_in_contact + 1
    local c = cs[1]
    assert(c.a == a and c.b == b, "contact between the two particles, ids from 1")
    assert(math.abs(c.normal.x - 1) < 1e-12, "normal points from a to b")
    assert(c.normal_force > 0)
    max_overlap = math.max(max_overlap, c.overlap)
    local e = w:energies()
    worst_balance = math.max(worst_balance, math.abs(e.kinetic + e.strain - e0.kinetic) / e0.kinetic)
  elseif seen then
    break
  end
end
assert(seen, "the spheres met")

local duration = steps_in_contact * dt
local expected_overlap = 2 * v0 * math.sqrt(m_eff / kn)
local va, vb = w:velocity(a), w:velocity(b)
print(("contact %.6g s (expected %.6g, dt %.3g), overlap %.6g (expected %.6g), rebound %.6g, %.6g m/s")
      :format(duration, T, dt, max_overlap, expected_overlap, va.x, vb.x))
assert(math.abs(duration - T) <= 2 * dt, "contact duration pi sqrt(m_eff/kn)")
assert(math.abs(max_overlap - expected_overlap) < 0.01 * expected_overlap, "largest overlap")
assert(math.abs(va.x + v0) < 1e-3 * v0 and math.abs(vb.x - v0) < 1e-3 * v0, "rebound speed")
assert(worst_balance < 0.01, "kinetic + strain energy conserved within 1 %: " .. worst_balance)
print("PASS")
