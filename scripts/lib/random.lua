-- A seeded random stream of its own (SplitMix64 on Lua 5.4 integers), so that a script's draws
-- do not depend on, or disturb, math.random or any other module.
--
--   local rng = require("random").new(seed)
--   rng:uniform()          -- [0, 1)
--   rng:uniform(a, b)      -- [a, b)
--   rng:gaussian(mean, sd) -- Box-Muller
--
-- The same seed gives the same numbers on every machine (integer arithmetic wraps at 64 bits).
local M = {}
local Stream = {}
Stream.__index = Stream

function M.new(seed)
  assert(math.type(seed) == "integer" or (type(seed) == "number" and seed == math.floor(seed)),
         "random.new: the seed must be an integer, got " .. tostring(seed))
  return setmetatable({state = math.tointeger(seed) ~ 0x5DEECE66D}, Stream)
end

local function next64(s)   -- SplitMix64 (Steele, Lea & Flood 2014)
  s.state = s.state + 0x9E3779B97F4A7C15
  local z = s.state
  z = (z ~ (z >> 30)) * 0xBF58476D1CE4E5B9
  z = (z ~ (z >> 27)) * 0x94D049BB133111EB
  return z ~ (z >> 31)
end

function Stream:uniform(a, b)
  local u = (next64(self) >> 11) * (1.0 / 9007199254740992.0)  -- 53 bits -> [0, 1)
  if a then return a + (b - a) * u end
  return u
end

function Stream:gaussian(mean, sd)
  if self.spare then
    local z = self.spare
    self.spare = nil
    return (mean or 0) + (sd or 1) * z
  end
  local u1 = 1 - self:uniform()  -- (0, 1]
  local u2 = self:uniform()
  local r = math.sqrt(-2 * math.log(u1))
  self.spare = r * math.sin(2 * math.pi * u2)
  return (mean or 0) + (sd or 1) * r * math.cos(2 * math.pi * u2)
end

return M
