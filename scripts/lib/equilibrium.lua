-- Cycling to equilibrium by PFC's ratio: mean unbalanced force (over the particles that move on
-- their own) / mean contact force (over touching contacts and intact bonds).
--
--   local eq = require("equilibrium")
--   eq.ratio(world)                                  -- the ratio now
--   local steps, reached = eq.run(world, {ratio = 1e-4, steps = 1e6, every = 200})
--
-- world:unbalanced_force_ratio() (and world:run{stop_when = "equilibrium"}) counts only unbonded
-- contacts and wall contacts in the denominator; once every contact is bonded and the walls are
-- gone it has none and returns infinity. This module counts bonds too: |normal force| of each
-- bond (contact bond + parallel bond, tension or compression). Without bonds it is the engine's
-- ratio. Gravity is not included (the REV and joint scenes have none).
local M = {}

-- Particles of rigid groups do not count as unbalanced (their forces are taken by the group).
local function free_mask(world)
  local n = world:particle_count()
  local grouped = {}
  for g = 1, world:group_count() do
    for _, id in ipairs(world:group_members(g)) do grouped[id] = true end
  end
  return grouped, n
end

function M.ratio(world, cache)
  if world:bond_count() == 0 then return world:unbalanced_force_ratio() end
  local grouped, n
  if cache and cache.n == world:particle_count() and cache.groups == world:group_count() then
    grouped, n = cache.grouped, cache.n
  else
    grouped, n = free_mask(world)
    if cache then cache.grouped, cache.n, cache.groups = grouped, n, world:group_count() end
  end
  local norms = world:forces():norms()
  local unbalanced, bodies = 0, 0
  for id = 1, n do
    if not grouped[id] then
      unbalanced = unbalanced + norms:get(id)
      bodies = bodies + 1
    end
  end
  local contact, count = 0, 0
  for _, b in ipairs(world:bonds()) do
    contact, count = contact + math.abs(b.normal_force), count + 1
  end
  for _, c in ipairs(world:contacts()) do
    contact, count = contact + c.normal_force, count + 1
  end
  if bodies == 0 then return 0 end
  if count == 0 or contact == 0 then return math.huge end
  return (unbalanced / bodies) / (contact / count)
end

-- Cycle until M.ratio(world) <= ratio (checked every `every` steps) or `steps` steps.
-- Returns steps done, whether the ratio was reached, and the last ratio.
function M.run(world, o)
  o = o or {}
  local target, every = o.ratio or 1e-4, o.every or 200
  local cache, last = {}, math.huge
  local steps, why = world:run{steps = o.steps or 1000000, every = every, progress = o.progress,
    stop_when = function(w)
      last = M.ratio(w, cache)
      return last <= target
    end,
    show = function() return {ratio = last} end}
  return steps, why == "stop_when", last
end

return M
