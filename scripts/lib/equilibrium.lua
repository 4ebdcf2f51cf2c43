-- Cycling to equilibrium by PFC's ratio: mean unbalanced force (over the particles that move on
-- their own) / mean contact force (over touching contacts and intact bonds).
--
--   local eq = require("equilibrium")
--   eq.ratio(world)                                  -- the ratio now
--   local steps, reached = eq.run(world, {ratio = 1e-4, steps = 1e6, every = 200})
--
-- The ratio is the engine's (world:unbalanced_force_ratio(), which counts intact bonds in the
-- denominator and leaves out the members of rigid groups, inert particles among them).
local M = {}

function M.ratio(world) return world:unbalanced_force_ratio() end

-- Cycle until M.ratio(world) <= ratio (checked every `every` steps) or `steps` steps.
-- Returns steps done, whether the ratio was reached, and the last ratio.
function M.run(world, o)
  o = o or {}
  local target, every = o.ratio or 1e-4, o.every or 200
  local last = math.huge
  local steps, why = world:run{steps = o.steps or 1000000, every = every, progress = o.progress,
    stop_when = function(w)
      last = M.ratio(w)
      return last <= target
    end,
    show = function() return {ratio = last} end}
  return steps, why == "stop_when", last
end

return M
