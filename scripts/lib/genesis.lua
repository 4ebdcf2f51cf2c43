-- Specimen genesis: a bonded assembly that starts in a defined state [scenarios.md 1], the same
-- procedure for the REV and for each half of a joint, so that the REV calibrates the material
-- the joint is made of (the bonded-particle route of Potyondy & Cundall 2004).
--
--   local genesis = require("genesis")
--   local packed = genesis.pack(world, {min = lo, max = hi, radii = r, seed = 1, box = box,
--                                       walls = {mould}, stress = 1e-3, friction = 0.5})
--   local bonded = genesis.bond(world, {sets = {ids}, material = mat.bond(), walls = all_walls,
--                                       tensile_strength = st})
--
-- pack:
--   1. compaction without friction (particles and region walls): centres placed at random at a
--      tenth of the radii, radii grown in stages (pack.expand). A frictionless assembly jams
--      denser than a frictional one and at a reproducible density, so the state below does not
--      depend on where a frictional packing happened to lock.
--   2. a low isotropic stress installed by scaling all radii by one factor (bracketed, then
--      bisected; pack.install_stress) until the mean stress on the box walls is `stress`.
--   3. floaters (fewer than `min_contacts` ball-ball contacts: rattlers of the jammed assembly,
--      which carry nothing and would get no bond that holds them) are taken out of the specimen:
--      made inert, fixed, and tagged `floater_tag` if given.
--   4. the particles' friction restored (world:set_friction); the walls stay frictionless.
-- bond:
--   5. bonds installed in each id set on its own (model.md 5: contacts keep their forces, beams
--      start at zero), the walls removed, the assembly cycled to equilibrium.
--   6. the bond stresses left are reported against the bond strength: scenarios.md 1 asks that
--      none needs more than st / 3 to hold and that none breaks.
local pack = require("pack")
local radii_lib = require("radii")
local eq = require("equilibrium")
local mat = require("materials")

local M = {}

local function check(o, known, fn)
  for k in pairs(o) do
    if not known[k] then error(("%s: unknown option '%s'"):format(fn, tostring(k)), 3) end
  end
end

-- Ball-ball contacts per particle id (touching pairs only).
function M.contact_counts(world)
  local counts = {}
  for _, c in ipairs(world:contacts()) do
    counts[c.a] = (counts[c.a] or 0) + 1
    counts[c.b] = (counts[c.b] or 0) + 1
  end
  return counts
end

function M.pack(world, o)
  check(o, {min = true, max = true, inside = true, radii = true, seed = true, box = true, walls = true,
            volume = true, stress = true, tolerance = true, friction = true, ratio = true,
            min_contacts = true, floater_tag = true, progress = true, stages = true, stage_steps = true,
            max_steps = true, log = true}, "genesis.pack")
  assert(o.min and o.max and o.radii and o.box, "genesis.pack: min, max, radii and box are required")
  assert(o.stress and o.stress > 0, "genesis.pack: stress (Pa, > 0) is required")
  local log = o.log or function() end
  local t0 = asperity.wall_time()
  local ratio = o.ratio or 1e-4
  -- 1. Frictionless compaction.
  world:set_friction(0)
  local expanded = pack.expand(world, {min = o.min, max = o.max, inside = o.inside, radii = o.radii,
                                       seed = o.seed, walls = o.box, volume = o.volume, ratio = ratio,
                                       progress = o.progress, stages = o.stages, stage_steps = o.stage_steps,
                                       max_steps = o.max_steps})
  local first, last = expanded.first, expanded.last
  local stress0 = pack.mean_box_wall_stress(world, o.box, o.min, o.max)
  log("compacted %d particles without friction in %d steps: wall stress %.3g Pa, coordination %.2f",
      last - first + 1, expanded.steps, stress0, expanded.coordination)
  -- 2. The isotropic stress, by one radius factor.
  local s = pack.install_stress(world, {first = first, last = last, walls = o.box, min = o.min, max = o.max,
                                        target = o.stress, tolerance = o.tolerance or 0.1, ratio = ratio,
                                        max_steps = o.max_steps, iterations = 40})
  log("stress installed: radii x %.5f, wall stress %.4g Pa (target %.4g) after %d iterations, %d steps",
      s.factor, s.stress, o.stress, s.iterations, s.steps)
  -- 3. Floaters out.
  local counts = M.contact_counts(world)
  local min_contacts = o.min_contacts or 3
  local floaters, kept = {}, {}
  for id = first, last do
    if (counts[id] or 0) < min_contacts then floaters[#floaters + 1] = id else kept[#kept + 1] = id end
  end
  if #floaters > 0 then
    if o.floater_tag then world:set_tag(floaters, o.floater_tag) end
    world:add_group(floaters, {translation = "fixed"})   -- inert particles must belong to a rigid body
    world:set_inert(floaters)
  end
  -- 4. Friction back.
  world:set_friction(o.friction or mat.contact.friction)
  local rr = {}
  local all = world:radii()
  for i, id in ipairs(kept) do rr[i] = all:get(id) end
  local volume = o.volume or (o.max[1] - o.min[1]) * (o.max[2] - o.min[2]) * (o.max[3] - o.min[3])
  local nominal, true_n, mean = radii_lib.porosity(rr, volume)
  local contacts = 0
  for _, id in ipairs(kept) do contacts = contacts + (counts[id] or 0) end
  local res = {
    particles = last - first + 1, kept = kept, floaters = floaters, floaters_removed = #floaters,
    first = first, last = last,
    compaction_steps = expanded.steps, stress_steps = s.steps, steps = expanded.steps + s.steps,
    radius_factor = s.factor, stress_pa = s.stress, stress_target_pa = o.stress, stress_reached = s.reached,
    wall_stress_pa = pack.box_wall_stresses(world, o.box, o.min, o.max),
    coordination = contacts / math.max(1, #kept),
    porosity_nominal = nominal, porosity_true = true_n, mean_radius = mean,
    seconds = asperity.wall_time() - t0,
  }
  log("genesis state: %d particles (%d floaters out), coordination %.2f, porosity %.3f (thesis definition) / %.3f (true), mean radius %.4g mm",
      #kept, #floaters, res.coordination, nominal, true_n, mean * 1e3)
  return res
end

-- Bond stresses of every intact bond, with the strength each needs to hold under the elliptic
-- criterion [3-46..3-49], summarised against `tensile_strength` (st).
function M.bond_stresses(world, tensile_strength, csv)
  local sig, tau, need = {}, {}, {}
  local f = csv and assert(io.open(csv, "w"))
  if f then f:write("a,b,sigma [Pa],tau [Pa],strength_to_hold [Pa]\n") end
  for _, b in ipairs(world:bonds()) do
    local s = mat.strength_to_hold(b.sigma, b.tau)
    sig[#sig + 1], tau[#tau + 1], need[#need + 1] = b.sigma, b.tau, s
    if f then f:write(("%d,%d,%.10g,%.10g,%.10g\n"):format(b.a, b.b, b.sigma, b.tau, s)) end
  end
  if f then f:close() end
  local function quantile(v, q)
    if #v == 0 then return 0 end
    local c = {}
    for i = 1, #v do c[i] = v[i] end
    table.sort(c)
    return c[math.max(1, math.ceil(q * #c))]
  end
  local ms = 0
  for i = 1, #sig do ms = ms + sig[i] end
  local st = tensile_strength
  local stats = {bonds = #sig, sigma_max_pa = quantile(sig, 1), sigma_min_pa = quantile(sig, 1 / math.max(1, #sig)),
                 sigma_p99_pa = quantile(sig, 0.99), sigma_mean_pa = #sig > 0 and ms / #sig or 0,
                 tau_max_pa = quantile(tau, 1),
                 strength_to_hold_max_pa = quantile(need, 1), strength_to_hold_p99_pa = quantile(need, 0.99),
                 strength_to_hold_p90_pa = quantile(need, 0.90)}
  if st then
    stats.max_over_st = stats.strength_to_hold_max_pa / st
    stats.p99_over_st = stats.strength_to_hold_p99_pa / st
    local above = 0
    for i = 1, #need do if need[i] > st / 3 then above = above + 1 end end
    stats.above_third_of_st = above
  end
  return stats, sig, need
end

-- 5-6. Bond each id set on its own, remove the walls, cycle to equilibrium; report.
function M.bond(world, o)
  check(o, {sets = true, material = true, walls = true, ratio = true, steps = true, tensile_strength = true,
            csv = true, progress = true, before_relax = true, log = true}, "genesis.bond")
  local log = o.log or function() end
  local t0 = asperity.wall_time()
  local bonds = 0
  for _, ids in ipairs(o.sets) do
    local m = {}
    for k, v in pairs(o.material) do m[k] = v end
    m.ids = ids
    bonds = bonds + world:install_bonds(m)
  end
  for _, id in ipairs(o.walls or {}) do world:remove_wall(id) end
  if o.before_relax then o.before_relax(world) end
  local steps, reached, ratio = eq.run(world, {ratio = o.ratio or 1e-4, steps = o.steps or 1000000,
                                               progress = o.progress})
  local st = o.tensile_strength or o.material.tensile_strength
  local stats = M.bond_stresses(world, st, o.csv)
  local res = {bonds = bonds, relax_steps = steps, relax_reached = reached, relax_ratio = ratio,
               broken_in_relaxation = world:break_count(), bond_stress = stats,
               bond_stress_max_over_st = stats.max_over_st, seconds = asperity.wall_time() - t0}
  log("bonded: %d bonds, walls removed, relaxed in %d steps (ratio %.2g); %d broken; strength to hold max %.3g Pa%s",
      bonds, steps, ratio, res.broken_in_relaxation, stats.strength_to_hold_max_pa,
      st and (" = %.3f st"):format(stats.max_over_st) or "")
  return res
end

-- A Lua source for a table of numbers, strings, booleans and nested tables (a genesis record kept
-- beside a cached specimen; read back with dofile).
function M.serialise(v)
  local t = type(v)
  if t == "number" then
    if v ~= v then return "0/0" elseif v == math.huge then return "math.huge" elseif v == -math.huge then return "-math.huge" end
    return math.type(v) == "integer" and tostring(v) or ("%.17g"):format(v)
  elseif t == "string" then return ("%q"):format(v)
  elseif t == "boolean" then return tostring(v)
  elseif t == "table" then
    local parts, n = {}, #v
    for i = 1, n do parts[#parts + 1] = M.serialise(v[i]) end
    local keys = {}
    for k in pairs(v) do
      if not (math.type(k) == "integer" and k >= 1 and k <= n) then keys[#keys + 1] = k end
    end
    table.sort(keys, function(a, b) return tostring(a) < tostring(b) end)
    for _, k in ipairs(keys) do
      local kk = type(k) == "string" and k:match("^[%a_][%w_]*$") and k or ("[" .. M.serialise(k) .. "]")
      parts[#parts + 1] = kk .. " = " .. M.serialise(v[k])
    end
    return "{" .. table.concat(parts, ", ") .. "}"
  end
  error("genesis.serialise: cannot write a " .. t)
end

return M
