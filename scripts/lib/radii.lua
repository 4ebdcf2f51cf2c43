-- Radius distributions and the particle count of a porosity [thesis 3.3, 3-34..3-36].
--
--   local radii = require("radii")
--   local r = radii.truncated_gaussian{count = 935, mean = 0.5e-3, sd = 0.1e-3, cut = 3, seed = 1}
--   local n = radii.count_for_porosity{volume = 1e-6, porosity = 0.51, mean_radius = 0.5e-3} -- 935
--   local nominal, true_n = radii.porosity(r, 1e-6)
local M = {}

local function check(o, known, fn)
  for k in pairs(o) do
    if not known[k] then error(fn .. ": unknown option '" .. tostring(k) .. "'", 3) end
  end
end

-- `count` radii from a Gaussian truncated at mean +- cut * sd (redrawn until inside), from
-- their own seeded stream (random.lua). The thesis: mean 0.5 mm, sd 0.1 mm, cut 3, a dispersion
-- (Rmax - Rmin) / <R> of 120 % [3-34]. normalise_mean = true scales the sample to the exact mean
-- (then the thesis's nominal porosity of the N particles is exactly the one asked for, up to the
-- rounding of N).
function M.truncated_gaussian(o)
  check(o, {count = true, mean = true, sd = true, cut = true, seed = true, rng = true, normalise_mean = true},
        "radii.truncated_gaussian")
  assert(o.count and o.mean and o.sd, "radii.truncated_gaussian: count, mean and sd are required")
  local rng = o.rng or require("random").new(o.seed or 1)
  local cut = o.cut or 3
  local lo, hi = o.mean - cut * o.sd, o.mean + cut * o.sd
  assert(lo > 0, "radii.truncated_gaussian: mean - cut * sd must be > 0")
  local r = {}
  for i = 1, o.count do
    local x
    repeat x = rng:gaussian(o.mean, o.sd) until x >= lo and x <= hi
    r[i] = x
  end
  if o.normalise_mean then   -- scale the sample so that its mean is exactly `mean`
    local sum = 0
    for i = 1, #r do sum = sum + r[i] end
    local f = o.mean * #r / sum
    for i = 1, #r do r[i] = r[i] * f end
  end
  return r
end

-- The thesis's porosity definition [3-35, 3-36]: n = 1 - N (4/3 pi <R>^3) / V, with the mean
-- radius cubed (not the mean of the cubes), so N = (1 - n) V / (4/3 pi <R>^3), rounded down
-- (a 1 cm cube at n = 0.51 with <R> = 0.5 mm: 935).
function M.count_for_porosity(o)
  check(o, {volume = true, porosity = true, mean_radius = true}, "radii.count_for_porosity")
  return math.floor((1 - o.porosity) * o.volume / (4 / 3 * math.pi * o.mean_radius ^ 3))
end

-- Porosities of a set of radii in a volume: the thesis's nominal one (with the sample's own mean
-- radius, [3-35]) and the true one (1 - sum of the sphere volumes / V), which is lower because
-- <R^3> > <R>^3.
function M.porosity(r, volume)
  local n, sum, sum3 = 0, 0, 0
  local get = type(r) == "table" and function(i) return r[i] end or function(i) return r:get(i) end
  for i = 1, #r do
    local x = get(i)
    n, sum, sum3 = n + 1, sum + x, sum3 + x ^ 3
  end
  local mean = sum / n
  return 1 - n * 4 / 3 * math.pi * mean ^ 3 / volume, 1 - 4 / 3 * math.pi * sum3 / volume, mean
end

-- Summary statistics: mean, sd, min, max and the dispersion (max - min) / mean.
function M.stats(r)
  local n, s, s2, lo, hi = #r, 0, 0, math.huge, -math.huge
  for i = 1, n do
    local x = r[i]
    s, s2 = s + x, s2 + x * x
    lo, hi = math.min(lo, x), math.max(hi, x)
  end
  local mean = s / n
  return {mean = mean, sd = math.sqrt(math.max(0, s2 / n - mean * mean)), min = lo, max = hi,
          dispersion = (hi - lo) / mean}
end

return M
