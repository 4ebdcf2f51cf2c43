-- Event statistics of bond breakage (scenarios.md 8) from the files joint.lua writes while
-- shearing: breaks.csv (every break, with its step and released energy) and events.csv (the
-- energies every `events_every` steps, the sampling interval below).
--
-- Definitions used throughout:
--   interval   one sampling interval of events.csv (joint.lua events_every, the study's 100 steps);
--              without events.csv, 100 steps counted from the first break
--   breaks     bonds broken in an interval (breaks per 100 steps: their mean, scaled to 100 steps)
--   event      a maximal run of consecutive intervals with at least one break; its size S is the
--              number of bonds broken in it, its energy E the strain energy they released
--   magnitude  M = log10 S (S in broken bonds); b-value: the Gutenberg-Richter slope of
--              log10 N(>= M) against M, i.e. N(>= S) ~ S^-b
--   b-value    maximum likelihood (Aki 1965): on the sizes, the Gutenberg-Richter law binned to
--              whole bonds (M.aki_b, sizes = true; Mc = log10(Smin - 1/2)); on the energies,
--              M_E = log10(E / 1 J), Aki's b = log10(e) / (mean(M_E) - Mc), Mc the smallest M_E,
--              standard error b / sqrt(n)
--   fluctuation of a term: its change over one interval (kinetic and strain: difference of the
--              stored energy; damping: the energy damped in the interval), divided by its standard
--              deviation over the run for the distributions
--   cross-correlation  r(lag) = Pearson correlation of breaks(t) with fluctuation(t + lag),
--              lag 0..20 intervals (positive: the energy after the breaks)
local M = {}

local LOG10E = 1 / math.log(10)

-- Maximum-likelihood b (Aki 1965). Options: magnitudes (true: the values are magnitudes, continuous:
-- b = log10(e) / (mean(M) - Mc), standard error b / sqrt(n)); sizes (true: integer sizes S >= 1,
-- M = log10 S: the same law binned to whole bonds, P(S = s) = F(s - 1/2) - F(s + 1/2) with
-- F(x) = (x / (Smin - 1/2))^-b, maximised over b, standard error from the curvature of the
-- log-likelihood; Aki's formula with a half-bin correction is biased by 15-25 % when Smin = 1);
-- neither: positive continuous values taken as 10^M. min: the completeness threshold in the
-- values' unit (default: the smallest). Returns b, its standard error, the events used, Mc.
function M.aki_b(values, o)
  o = o or {}
  local lo = o.min
  if not lo then
    lo = math.huge
    for _, v in ipairs(values) do lo = math.min(lo, v) end
  end
  local used = {}
  for _, v in ipairs(values) do if v >= lo then used[#used + 1] = v end end
  local n = #used
  if o.sizes then
    if n > 0 and lo < 1 then error(("aki_b: sizes must be >= 1, got a minimum of %g"):format(lo), 2) end
    local c = lo - 0.5
    local mc = n > 0 and math.log(c, 10) or 0/0
    if n < 2 then return 0/0, 0/0, n, mc end
    local all_min = true
    for _, v in ipairs(used) do all_min = all_min and v == lo end
    if all_min then return math.huge, 0/0, n, mc end   -- every event the smallest: b unbounded
    -- log L(b) = sum log(((s - 1/2)/c)^-b - ((s + 1/2)/c)^-b); concave in b.
    local function loglik(b)
      local L = 0
      for _, s in ipairs(used) do
        L = L + math.log(((s - 0.5) / c) ^ -b - ((s + 0.5) / c) ^ -b)
      end
      return L
    end
    local a, z = 1e-3, 20   -- golden-section search for the maximum
    local g = (math.sqrt(5) - 1) / 2
    local x1, x2 = z - g * (z - a), a + g * (z - a)
    local f1, f2 = loglik(x1), loglik(x2)
    for _ = 1, 200 do
      if f1 < f2 then a, x1, f1 = x1, x2, f2; x2 = a + g * (z - a); f2 = loglik(x2)
      else z, x2, f2 = x2, x1, f1; x1 = z - g * (z - a); f1 = loglik(x1) end
      if z - a < 1e-10 then break end
    end
    local b = 0.5 * (a + z)
    local h = 1e-4 * b
    local curvature = (loglik(b + h) - 2 * loglik(b) + loglik(b - h)) / (h * h)
    return b, curvature < 0 and 1 / math.sqrt(-curvature) or 0/0, n, mc
  end
  local mc, sum = nil, 0
  if o.magnitudes then
    mc = lo
    for _, v in ipairs(used) do sum = sum + v end
  else
    if n > 0 and not (lo > 0) then error(("aki_b: values must be > 0 (taken as 10^M), got %g"):format(lo), 2) end
    mc = n > 0 and math.log(lo, 10) or 0/0
    for _, v in ipairs(used) do sum = sum + math.log(v, 10) end
  end
  if n < 2 then return 0/0, 0/0, n, mc end
  local b = LOG10E / (sum / n - mc)
  return b, b / math.sqrt(n), n, mc
end

-- CSV with a "name [unit]" header into columns keyed by the name before the unit.
function M.read_csv(path)
  local f = io.open(path, "r")
  if not f then return nil end
  local header = f:read("l")
  local names = {}
  for field in (header or ""):gmatch("[^,]+") do names[#names + 1] = field:match("^%s*(%S+)") end
  local cols = {}
  for _, name in ipairs(names) do cols[name] = {} end
  for line in f:lines() do
    local k = 0
    for field in line:gmatch("[^,]+") do
      k = k + 1
      if names[k] then table.insert(cols[names[k]], tonumber(field) or 0/0) end
    end
  end
  f:close()
  return cols
end

local function mean_sd(v)
  local n, s = #v, 0
  if n == 0 then return 0/0, 0/0 end
  for _, x in ipairs(v) do s = s + x end
  local m, q = s / n, 0
  for _, x in ipairs(v) do q = q + (x - m) ^ 2 end
  return m, n > 1 and math.sqrt(q / (n - 1)) or 0/0
end
M.mean_sd = mean_sd

-- Pearson correlation of a(t) with b(t + lag), over the overlap.
function M.cross_correlation(a, b, max_lag)
  local r = {}
  for lag = 0, max_lag do
    local n = math.min(#a, #b - lag)
    if n < 3 then r[lag + 1] = 0/0 else
      local sa, sb = 0, 0
      for t = 1, n do sa, sb = sa + a[t], sb + b[t + lag] end
      local ma, mb = sa / n, sb / n
      local sab, saa, sbb = 0, 0, 0
      for t = 1, n do
        local da, db = a[t] - ma, b[t + lag] - mb
        sab, saa, sbb = sab + da * db, saa + da * da, sbb + db * db
      end
      r[lag + 1] = (saa > 0 and sbb > 0) and sab / math.sqrt(saa * sbb) or 0/0
    end
  end
  return r
end

-- One run's folder -> its statistics (nil if it has neither file: nothing broke and nothing was
-- sampled; a run sampled without a break counts its intervals, all empty).
function M.analyse_run(folder)
  local breaks = M.read_csv(folder .. "/breaks.csv")
  local ev = M.read_csv(folder .. "/events.csv")
  if not breaks and not ev then return nil end
  breaks = breaks or {step = {}, released_energy = {}}
  local r = {folder = folder}
  local steps, energies = breaks.step, breaks.released_energy
  if breaks.kind then  -- the parallel bonds' breaks only (the thesis's events); 2: a contact bond's
    steps, energies = {}, {}
    for i, k in ipairs(breaks.kind) do
      if k == 1 then steps[#steps + 1], energies[#energies + 1] = breaks.step[i], breaks.released_energy[i] end
    end
  end
  -- The intervals and the break count of each.
  local edges, counts = {}, {}
  if ev and #ev.step >= 2 then
    edges = ev.step
    r.interval = ev.step[2] - ev.step[1]
  else
    r.interval = 100
    local first, last = math.huge, -math.huge
    for _, s in ipairs(steps) do first, last = math.min(first, s), math.max(last, s) end
    for s = first - 1, last + r.interval, r.interval do edges[#edges + 1] = s end
  end
  for k = 1, #edges - 1 do counts[k] = 0 end
  local energy_in = {}
  for k = 1, #edges - 1 do energy_in[k] = 0 end
  for i, s in ipairs(steps) do
    -- Interval k holds the breaks of the steps in (edges[k], edges[k + 1]].
    local lo, hi = 1, #edges - 1
    if s > edges[1] and s <= edges[#edges] then
      while lo < hi do
        local mid = (lo + hi) // 2
        if s <= edges[mid + 1] then hi = mid else lo = mid + 1 end
      end
      counts[lo] = counts[lo] + 1
      energy_in[lo] = energy_in[lo] + (energies[i] or 0)
    end
  end
  r.counts = counts
  r.breaks = #steps
  r.intervals = #counts
  local total = 0
  for _, c in ipairs(counts) do total = total + c end
  r.breaks_per_100_steps = #counts > 0 and total / #counts * 100 / r.interval or 0/0
  -- Events: runs of consecutive intervals with breaks.
  local sizes, event_energy = {}, {}
  local k = 1
  while k <= #counts do
    if counts[k] > 0 then
      local s, e = 0, 0
      while k <= #counts and counts[k] > 0 do s, e = s + counts[k], e + energy_in[k]; k = k + 1 end
      sizes[#sizes + 1], event_energy[#event_energy + 1] = s, e
    else
      k = k + 1
    end
  end
  r.sizes, r.event_energy = sizes, event_energy
  r.b, r.b_error, r.b_events = M.aki_b(sizes, {sizes = true})
  local mags = {}
  for _, e in ipairs(event_energy) do if e > 0 then mags[#mags + 1] = math.log(e, 10) end end
  r.b_energy, r.b_energy_error, r.b_energy_events = M.aki_b(mags, {magnitudes = true})
  -- Energy fluctuations and their cross-correlation with the breaks.
  if ev and #ev.step >= 3 then
    r.fluctuations, r.xcorr = {}, {}
    for _, term in ipairs{"kinetic", "strain", "damping"} do
      local d = {}
      for t = 2, #ev.step do d[t - 1] = ev[term][t] - ev[term][t - 1] end
      r.fluctuations[term] = d
      r.xcorr[term] = M.cross_correlation(counts, d, 20)
    end
  end
  return r
end

-- Cumulative counts N(>= S) of integer sizes, for a log-log plot.
function M.ccdf(sizes)
  local sorted = {table.unpack(sizes)}
  table.sort(sorted)
  local xs, ns = {}, {}
  for i, s in ipairs(sorted) do
    if i == #sorted or sorted[i + 1] ~= s then
      local first = i
      while first > 1 and sorted[first - 1] == s do first = first - 1 end
      xs[#xs + 1], ns[#ns + 1] = s, #sorted - first + 1
    end
  end
  return xs, ns
end

-- Normalised values (divided by their standard deviation after removing the mean) binned into a
-- density: centres and probability densities.
function M.density(values, bins, range)
  local m, sd = mean_sd(values)
  local c, d = {}, {}
  if not (sd > 0) then return c, d end
  local width = 2 * range / bins
  local counts = {}
  for k = 1, bins do counts[k] = 0 end
  for _, v in ipairs(values) do
    local z = (v - m) / sd
    local k = math.floor((z + range) / width) + 1
    if k >= 1 and k <= bins then counts[k] = counts[k] + 1 end
  end
  for k = 1, bins do
    c[k] = -range + (k - 0.5) * width
    d[k] = counts[k] / (#values * width)
  end
  return c, d
end

return M
