-- The report of a study (scripts/study.lua): from its rows (one per run, with every scalar of the
-- run's summary) and the runs' series, it writes into the study folder
--   study_cases.csv          mean and scatter (sample SD) over seeds of each case's main results
--   trends.json, trends.md   each expected behaviour of scenarios.md 7: shown, partly, not shown or
--                            untestable on the runs present, with the numbers behind the verdict
--   plots/*.png              the comparison figures (gnuplot), reference.md's values beside ours
--   events/                  the event statistics of the fracture runs (scenarios.md 8, lib/events.lua)
--
--   require("study_report").write{dir = DIR, rows = rows, log = function(fmt, ...) end,
--                                 elapsed = {seconds =, invocations =, jobs =, threads =} or nil}
local fig = require("figures")
local ev = require("events")

local M = {}

-- The reference study's joints (reference.md 2, thesis Tables 4-1/4-2; lib/reference.lua): peak
-- and residual shear stress (MPa) and initial shear stiffness K0 (MPa/mm) per surface and model.
local reference = require("reference")
M.REFERENCE_STRESS = reference.normal_stress_mpa
local function thesis(surface, model) return reference.joint(surface, model, M.REFERENCE_STRESS) end
-- Surface statistics (surfaces.md 4) for the reference's points on the H, Lc, s2 axes.
local SURFACE = {S1 = {0.75, 16, 0.547}, S2 = {0.75, 16, 0.328}, S3 = {0.75, 20, 0.547}, S4 = {0.75, 20, 0.328},
                 S5 = {0.52, 16, 0.547}, S6 = {0.52, 16, 0.328}, S7 = {0.52, 20, 0.547}, S8 = {0.52, 20, 0.328}}
-- Pairs of surfaces that differ in one statistic only, the first with the lower value.
local PAIRS = {
  s2 = {{"S2", "S1"}, {"S4", "S3"}, {"S6", "S5"}, {"S8", "S7"}},
  Lc = {{"S1", "S3"}, {"S2", "S4"}, {"S5", "S7"}, {"S6", "S8"}},
  H = {{"S5", "S1"}, {"S6", "S2"}, {"S7", "S3"}, {"S8", "S4"}},
}
local MODELS = {"rigid", "elastic", "fracture"}
local COLOR = {rigid = "#d02020", elastic = "#2050d0", fracture = "#20a040"}

local write_atomic = require("shell").write_atomic
local function finite(v) return type(v) == "number" and v == v and math.abs(v) < math.huge end
local function mean_sd(v) return ev.mean_sd(v) end
local function key(r, skip)
  local parts = {}
  for _, f in ipairs{"surface", "stress_mpa", "direction", "model", "seed"} do
    if f ~= skip then parts[#parts + 1] = tostring(r[f]) end
  end
  return table.concat(parts, "|")
end
local function fmt(v, digits)
  if not finite(v) then return tostring(v) end
  return ("%." .. (digits or 3) .. "g"):format(v)
end

-- Post-peak undulation: the total rise of the shear stress after its peak, over the peak (0 for a
-- curve that only falls; each undulation adds its rise).
local function undulation(curve)
  local tau = curve and curve.shear_stress_mpa
  if not tau or #tau < 3 then return 0/0 end
  local peak, at = -math.huge, 1
  for k, v in ipairs(tau) do if v > peak then peak, at = v, k end end
  local rise = 0
  for k = at + 1, #tau do rise = rise + math.max(0, tau[k] - tau[k - 1]) end
  return peak > 0 and rise / peak or 0/0
end

-- Trends ------------------------------------------------------------------------------------------
local function verdict(agree, n)
  if n == 0 then return "untestable" end
  if agree == n then return "shown" end
  if agree > n / 2 then return "partly" end
  return "not shown"
end

-- Comparisons of `field` between rows that differ only in `vary`, from the `low` to the `high`
-- value of it; `expect` "up" (the field grows with it) or "down". An equal value agrees with
-- neither; when every pair is equal the factor changed nothing in these runs: untestable.
local function compare(index, rows, field, vary, pairs_list, expect, filter)
  local list, agree, ties = {}, 0, 0
  for _, a in ipairs(rows) do
    if (not filter or filter(a)) and finite(a[field]) then
      for _, pr in ipairs(pairs_list) do
        if a[vary] == pr[1] then
          local probe = {}
          for k, v in pairs(a) do probe[k] = v end
          probe[vary] = pr[2]
          local b = index[key(probe)]
          if b and finite(b[field]) then
            local same = b[field] == a[field]
            local ok = not same and (expect == "up") == (b[field] > a[field])
            if ok then agree = agree + 1 end
            if same then ties = ties + 1 end
            list[#list + 1] = {low = a.name, high = b.name, low_value = a[field], high_value = b[field],
                               -- a base a thousand times below the other value (a fracture run's
                               -- dilatancy of 0.000 mm) gives no meaningful ratio: left out of the mean
                               relative_change = math.abs(a[field]) > 1e-3 * math.abs(b[field])
                                                 and (b[field] - a[field]) / math.abs(a[field]) or 0/0,
                               agrees = ok}
          end
        end
      end
    end
  end
  local changes = {}
  for _, c in ipairs(list) do if finite(c.relative_change) then changes[#changes + 1] = c.relative_change end end
  local m, sd = mean_sd(changes)
  local r = {verdict = verdict(agree, #list), agree = agree, comparisons = #list, mean_relative_change = m,
             sd_relative_change = sd, vanishing_bases = #list - #changes, ties = ties, pairs = list}
  if ties > 0 and ties == #list then
    r.verdict, r.reason = "untestable", "every pair compared gave the same value: the factor changed nothing in these runs"
  end
  return r
end

local function surface_pairs(kind)
  local t = {}
  for _, p in ipairs(PAIRS[kind]) do t[#t + 1] = p end
  return t
end

function M.trends(rows, curves)
  local done, index = {}, {}
  for _, r in ipairs(rows) do
    if r.status == "finished" then
      done[#done + 1] = r
      index[key(r)] = r
      r.undulation = undulation(curves[r.name])
    end
  end
  local stresses, seen = {}, {}
  for _, r in ipairs(done) do
    if not seen[r.stress_mpa] then seen[r.stress_mpa] = true; stresses[#stresses + 1] = r.stress_mpa end
  end
  table.sort(stresses)
  local stress_pairs = {}
  for k = 1, #stresses - 1 do stress_pairs[#stress_pairs + 1] = {stresses[k], stresses[k + 1]} end
  local T = {}
  local function add(id, text, result, note)
    result.id, result.behaviour, result.note = id, text, note
    if result.comparisons == 0 and not result.reason then result.reason = note end
    T[#T + 1] = result
  end
  local untestable_surface = function(kind)
    local names = {}
    for _, p in ipairs(PAIRS[kind]) do names[#names + 1] = p[1] .. "/" .. p[2] end
    return "needs surfaces that differ only in " .. kind .. " (" .. table.concat(names, ", ") ..
           ") at the same stress, direction, model and seed"
  end
  add("peak_grows_with_variance", "peak shear stress grows with the height variance",
      compare(index, done, "peak_shear_stress_mpa", "surface", surface_pairs("s2"), "up"), untestable_surface("s2"))
  add("dilatancy_grows_with_variance", "dilatancy grows with the height variance",
      compare(index, done, "max_dilatancy_mm", "surface", surface_pairs("s2"), "up"), untestable_surface("s2"))
  -- On a joint of side L <= 2 Lc the spectrum's roll-off (chi = 1 / (2 Lc), surfaces.md 2) lies below
  -- its lowest frequency 1 / L: the surfaces that differ only in Lc are the same surface.
  local function unresolved_lc(r)
    if r.comparisons > 0 and r.ties == r.comparisons then
      r.reason = "the surfaces that differ only in Lc gave identical runs: on a joint of side L <= 2 Lc the " ..
                 "roll-off 1 / (2 Lc) lies below the lowest frequency 1 / L, so they are the same surface (the " ..
                 "study's Lc of 16 and 20 mm need joints over 4 cm)"
    end
    return r
  end
  add("peak_falls_with_correlation_length", "peak shear stress falls with the correlation length",
      unresolved_lc(compare(index, done, "peak_shear_stress_mpa", "surface", surface_pairs("Lc"), "down")), untestable_surface("Lc"))
  add("dilatancy_falls_with_correlation_length", "dilatancy falls with the correlation length",
      unresolved_lc(compare(index, done, "max_dilatancy_mm", "surface", surface_pairs("Lc"), "down")), untestable_surface("Lc"))
  add("peak_grows_as_hurst_falls", "peak shear stress grows as H falls",
      compare(index, done, "peak_shear_stress_mpa", "surface", surface_pairs("H"), "down"), untestable_surface("H"))
  add("dilatancy_grows_as_hurst_falls", "dilatancy grows as H falls",
      compare(index, done, "max_dilatancy_mm", "surface", surface_pairs("H"), "down"), untestable_surface("H"))
  -- H the strongest: the mean size of the relative change of the peak per statistic (a statistic
  -- whose pairs all gave the same runs, such as Lc on small joints, is left out: not resolved).
  do
    local size = {}
    for _, kind in ipairs{"H", "s2", "Lc"} do
      local c = compare(index, done, "peak_shear_stress_mpa", "surface", surface_pairs(kind), "up")
      local s, n = 0, 0
      for _, p in ipairs(c.pairs) do if finite(p.relative_change) then s, n = s + math.abs(p.relative_change), n + 1 end end
      size[kind] = n > 0 and c.ties < #c.pairs and s / n or nil
    end
    local r = {comparisons = 0, agree = 0, mean_abs_relative_change = size}
    if size.H and (size.s2 or size.Lc) then
      r.comparisons = (size.s2 and 1 or 0) + (size.Lc and 1 or 0)
      r.agree = ((size.s2 and size.H > size.s2) and 1 or 0) + ((size.Lc and size.H > size.Lc) and 1 or 0)
      r.verdict = verdict(r.agree, r.comparisons)
    else
      r.verdict = "untestable"
      r.reason = "needs pairs differing in H and in s2 or Lc"
    end
    add("hurst_strongest", "H has the strongest effect on the peak", r)
  end
  -- Residual nearly independent of the surface: its scatter across surfaces (coefficient of
  -- variation) below the peak's, in each group of the same stress, direction, model and seed.
  do
    local groups = {}
    for _, r in ipairs(done) do
      local k = key(r, "surface")
      groups[k] = groups[k] or {}
      table.insert(groups[k], r)
    end
    local n, agree, cv_res, cv_peak, list = 0, 0, {}, {}, {}
    for k, g in pairs(groups) do
      if #g >= 2 then
        local res, pk = {}, {}
        for _, r in ipairs(g) do
          if finite(r.residual_shear_stress_mpa) and finite(r.peak_shear_stress_mpa) then
            res[#res + 1], pk[#pk + 1] = r.residual_shear_stress_mpa, r.peak_shear_stress_mpa
          end
        end
        if #res >= 2 then
          local mr, sr = mean_sd(res)
          local mp, sp = mean_sd(pk)
          local a, b = sr / math.abs(mr), sp / math.abs(mp)
          n = n + 1
          if a < b then agree = agree + 1 end
          cv_res[#cv_res + 1], cv_peak[#cv_peak + 1] = a, b
          list[#list + 1] = {group = k, surfaces = #res, cv_residual = a, cv_peak = b}
        end
      end
    end
    add("residual_independent_of_surface", "the residual stress is nearly the same for all surfaces",
        {verdict = verdict(agree, n), agree = agree, comparisons = n, mean_cv_residual = (mean_sd(cv_res)),
         mean_cv_peak = (mean_sd(cv_peak)), groups = list},
        "needs two or more surfaces at the same stress, direction, model and seed")
  end
  -- x and y alike: the relative difference of the peak between directions, below 15 % (our
  -- tolerance: the spec asks for similar curves and gives none).
  do
    local c = compare(index, done, "peak_shear_stress_mpa", "direction", {{"x", "y"}}, "up")
    local agree = 0
    for _, p in ipairs(c.pairs) do
      p.agrees = math.abs(p.high_value - p.low_value) / (0.5 * math.abs(p.high_value + p.low_value)) < 0.15
      if p.agrees then agree = agree + 1 end
    end
    c.agree, c.verdict, c.tolerance = agree, verdict(agree, c.comparisons), 0.15
    add("directions_alike", "x and y give similar curves (peak within 15 %)", c, "needs both directions of a case")
  end
  for _, q in ipairs{{"peak_shear_stress_mpa", "up", "peak"}, {"residual_shear_stress_mpa", "up", "residual"},
                     {"initial_shear_stiffness_mpa_per_mm", "up", "initial shear stiffness"},
                     {"max_dilatancy_mm", "down", "dilatancy"}} do
    add("stress_" .. q[3]:gsub(" ", "_"), "higher normal stress gives " .. (q[2] == "up" and "higher " or "lower ") .. q[3],
        compare(index, done, q[1], "stress_mpa", stress_pairs, q[2]), "needs two normal stresses of a case")
  end
  add("elastic_above_rigid_peak", "elastic peaks above rigid",
      compare(index, done, "peak_shear_stress_mpa", "model", {{"rigid", "elastic"}}, "up"), "needs rigid and elastic runs of a case")
  add("elastic_above_rigid_residual", "elastic residual above rigid",
      compare(index, done, "residual_shear_stress_mpa", "model", {{"rigid", "elastic"}}, "up"), "needs rigid and elastic runs of a case")
  do
    local lo = compare(index, done, "peak_shear_stress_mpa", "model", {{"rigid", "fracture"}}, "up")
    local hi = compare(index, done, "peak_shear_stress_mpa", "model", {{"fracture", "elastic"}}, "up")
    add("fracture_between", "elastic-fracture peaks between rigid and elastic",
        {verdict = verdict(lo.agree + hi.agree, lo.comparisons + hi.comparisons), agree = lo.agree + hi.agree,
         comparisons = lo.comparisons + hi.comparisons, above_rigid = lo, below_elastic = hi},
        "needs fracture runs beside rigid or elastic ones")
  end
  do
    local c = compare(index, done, "undulation", "model", {{"fracture", "elastic"}, {"fracture", "rigid"}}, "up")
    add("fracture_removes_undulations",
        "fracture removes the post-peak undulations (total post-peak rise / peak below elastic's and rigid's)", c,
        "needs fracture runs beside elastic or rigid ones")
  end
  do
    local a = compare(index, done, "max_dilatancy_mm", "model", {{"elastic", "rigid"}}, "up")
    local b = compare(index, done, "max_dilatancy_mm", "model", {{"fracture", "elastic"}}, "up")
    add("dilatancy_by_model", "dilatancy is largest for rigid, smallest for elastic-fracture",
        {verdict = verdict(a.agree + b.agree, a.comparisons + b.comparisons), agree = a.agree + b.agree,
         comparisons = a.comparisons + b.comparisons, rigid_above_elastic = a, elastic_above_fracture = b},
        "needs two models of a case")
  end
  do
    local n, agree, qs = 0, 0, {}
    for _, r in ipairs(done) do
      local c = curves[r.name] and curves[r.name].contacts
      if c and #c >= 3 then
        local cmax, at = -1, 1
        for k, v in ipairs(c) do if v > cmax then cmax, at = v, k end end
        local ok = at > 1 and c[#c] < cmax and finite(r.contact_decay_exponent) and r.contact_decay_exponent < 0
        n = n + 1
        if ok then agree = agree + 1 end
        if finite(r.contact_decay_exponent) then qs[#qs + 1] = r.contact_decay_exponent end
      end
    end
    local m, sd = mean_sd(qs)
    add("contacts_rise_then_decay", "the contact count rises, then decays as a power law (q < 0)",
        {verdict = verdict(agree, n), agree = agree, comparisons = n, mean_q = m, sd_q = sd}, "needs finished runs")
  end
  do
    local rough = {}
    for _, p in ipairs(PAIRS.s2) do rough[#rough + 1] = p end
    for _, p in ipairs(PAIRS.H) do rough[#rough + 1] = {p[2], p[1]} end   -- lower H: rougher
    for _, p in ipairs(PAIRS.Lc) do rough[#rough + 1] = {p[2], p[1]} end  -- shorter Lc: rougher
    add("breaks_grow_with_roughness", "broken-bond counts grow faster for rougher surfaces (fracture)",
        compare(index, done, "broken_bonds", "surface", rough, "up", function(r) return r.model == "fracture" end),
        "needs fracture runs of surfaces differing in one statistic")
  end
  do
    local shares, n, agree = {}, 0, 0
    for _, r in ipairs(done) do
      if finite(r.energy_shares_friction) then
        n = n + 1
        shares[#shares + 1] = r.energy_shares_friction
        if r.energy_shares_friction > 0.5 then agree = agree + 1 end
      end
    end
    local m, sd = mean_sd(shares)
    add("friction_takes_most", "friction takes most of the input energy (thesis: about 80 %)",
        {verdict = verdict(agree, n), agree = agree, comparisons = n, mean_share = m, sd_share = sd, reference_share = 0.8},
        "needs finished runs")
  end
  return T
end

local function trends_markdown(T, rows)
  local finished = 0
  for _, r in ipairs(rows) do if r.status == "finished" then finished = finished + 1 end end
  local lines = {"# Expected behaviours (scenarios.md 7) on this study", "",
                 ("%d of %d runs finished. A verdict counts the comparisons of runs that differ in one " ..
                  "factor only (same seed): shown (all agree), partly (most), not shown, or untestable on " ..
                  "the runs present. Signs, not values; the numbers are means over the comparisons. A relative " ..
                  "change goes from the run with the lower value of the factor to the one with the higher (H, Lc, " ..
                  "s2, normal stress), from x to y, and between models from the one expected lower to the one " ..
                  "expected higher (e.g. rigid to elastic)."):format(finished, #rows),
                 "", "| behaviour | verdict | agree / comparisons | numbers |", "|---|---|---|---|"}
  for _, t in ipairs(T) do
    local numbers = {}
    if finite(t.mean_relative_change) then
      numbers[#numbers + 1] = ("mean relative change %+.1f %% (SD %.1f %%)"):format(100 * t.mean_relative_change,
        100 * (finite(t.sd_relative_change) and t.sd_relative_change or 0))
    end
    if (t.vanishing_bases or 0) > 0 then
      numbers[#numbers + 1] = ("%d with a vanishing base left out of the mean"):format(t.vanishing_bases)
    end
    if (t.ties or 0) > 0 then numbers[#numbers + 1] = ("%d of them equal (agree with neither)"):format(t.ties) end
    if t.mean_abs_relative_change then
      for _, k in ipairs{"H", "s2", "Lc"} do
        if t.mean_abs_relative_change[k] then
          numbers[#numbers + 1] = ("|change| by %s %.1f %%"):format(k, 100 * t.mean_abs_relative_change[k])
        end
      end
    end
    if finite(t.mean_cv_residual) then
      numbers[#numbers + 1] = ("CV across surfaces: residual %.3f, peak %.3f"):format(t.mean_cv_residual, t.mean_cv_peak)
    end
    if finite(t.mean_q) then numbers[#numbers + 1] = ("mean q %.3f (SD %s)"):format(t.mean_q, fmt(t.sd_q)) end
    if finite(t.mean_share) then
      numbers[#numbers + 1] = ("mean friction share %.3f (SD %s; thesis ~0.8)"):format(t.mean_share, fmt(t.sd_share))
    end
    for _, part in ipairs{{"above_rigid", "above rigid"}, {"below_elastic", "below elastic"},
                          {"rigid_above_elastic", "rigid above elastic"}, {"elastic_above_fracture", "elastic above fracture"}} do
      local sub = t[part[1]]
      if sub and sub.comparisons > 0 then
        local change = finite(sub.mean_relative_change) and ("mean change %+.1f %%"):format(100 * sub.mean_relative_change)
                       or "no mean change"
        if (sub.vanishing_bases or 0) > 0 then
          change = change .. (", %d with a vanishing base left out"):format(sub.vanishing_bases)
        end
        numbers[#numbers + 1] = ("%s %d / %d (%s)"):format(part[2], sub.agree, sub.comparisons, change)
      end
    end
    if t.verdict == "untestable" and t.reason then numbers[#numbers + 1] = t.reason end
    lines[#lines + 1] = ("| %s | %s | %d / %d | %s |"):format(t.behaviour, t.verdict, t.agree or 0, t.comparisons or 0,
                                                           table.concat(numbers, "; "))
  end
  -- The scatter over realisations, where a case ran with several seeds.
  local cases = M.cases(rows)
  local rel = {peak_shear_stress_mpa = {}, residual_shear_stress_mpa = {}, max_dilatancy_mm = {}}
  local multi = 0
  for _, c in ipairs(cases) do
    if c.seeds >= 2 then
      multi = multi + 1
      for f, list in pairs(rel) do
        local m, sd = c[f .. "_mean"], c[f .. "_sd"]
        if finite(m) and finite(sd) and m ~= 0 then list[#list + 1] = sd / math.abs(m) end
      end
    end
  end
  lines[#lines + 1] = ""
  lines[#lines + 1] = "## Scatter over surface realisations (seeds)"
  lines[#lines + 1] = ""
  if multi == 0 then
    lines[#lines + 1] = "Every case ran with one seed: no scatter (give seeds=1,2,3)."
  else
    lines[#lines + 1] = ("%d cases ran with two or more seeds (study_cases.csv has each case's mean and SD). " ..
                         "Mean over those cases of SD / mean:"):format(multi)
    lines[#lines + 1] = ""
    for _, f in ipairs{"peak_shear_stress_mpa", "residual_shear_stress_mpa", "max_dilatancy_mm"} do
      local m = mean_sd(rel[f])
      lines[#lines + 1] = ("- %s: %s"):format(f, finite(m) and ("%.1f %%"):format(100 * m) or "n/a")
    end
  end
  return table.concat(lines, "\n") .. "\n"
end

-- Against the reference (reference.md 2): per surface of the thesis's tables and model, the mean
-- over the directions and seeds of the runs at its normal stress, beside the thesis's values.
local function reference_markdown(rows)
  local stress = M.REFERENCE_STRESS
  local sides, by = {}, {}
  for _, r in ipairs(rows) do
    if r.status == "finished" and math.abs(r.stress_mpa - stress) < 1e-9 then
      local k = r.surface .. " " .. r.model
      by[k] = by[k] or {}
      table.insert(by[k], r)
      if finite(r.size) then sides[("%g"):format(r.size * 100)] = true end
    end
  end
  local lines = {"", ("## Against the reference (reference.md 2, %g MPa)"):format(stress), ""}
  local side_list = {}
  for k in pairs(sides) do side_list[#side_list + 1] = k end
  table.sort(side_list)
  lines[#lines + 1] = ("The thesis's values (Tables 4-1 / 4-2: 10 cm joints, the mean of x and y) beside this study's, " ..
                       "the mean over the directions and seeds of its runs (joints of %s cm). Relative differences " ..
                       "from the thesis's value; peak / sigma_n is the ratio that transfers between specimens " ..
                       "(reference.md 2)%s."):format(#side_list > 0 and table.concat(side_list, ", ") or "unknown side",
                       (#side_list > 0 and tonumber(side_list[1]) < 10) and
                       "; scenarios.md 3 gives the offset of a 5 cm joint from a 10 cm one" or "")
  lines[#lines + 1] = ""
  lines[#lines + 1] = "| surface | model | runs | peak MPa: ours / thesis | residual MPa | K0 MPa/mm | peak / sigma_n |"
  lines[#lines + 1] = "|---|---|---|---|---|---|---|"
  local diffs = {}
  local function cell(ours, ref, field, model)
    local f = field == "k0" and "%.1f" or "%.2f"
    if not finite(ours) then return ("n/a / " .. f):format(ref) end
    local d = (ours - ref) / ref
    diffs[model] = diffs[model] or {}
    diffs[model][field] = diffs[model][field] or {}
    table.insert(diffs[model][field], d)
    return (f .. " / " .. f .. " (%+.0f %%)"):format(ours, ref, 100 * d)
  end
  local any = false
  for _, surface in ipairs(reference.surfaces) do
    for _, model in ipairs(MODELS) do
      local ref = thesis(surface, model)
      local runs = by[surface .. " " .. model] or {}
      local function avg(f)
        local v = {}
        for _, r in ipairs(runs) do if finite(r[f]) then v[#v + 1] = r[f] end end
        return #v > 0 and (mean_sd(v)) or nil
      end
      if #runs > 0 then
        any = true
        local peak = avg("peak_shear_stress_mpa")
        lines[#lines + 1] = ("| %s | %s | %d | %s | %s | %s | %.3f / %.3f |"):format(surface, model, #runs,
          cell(peak, ref.peak, "peak", model), cell(avg("residual_shear_stress_mpa"), ref.residual, "residual", model),
          cell(avg("initial_shear_stiffness_mpa_per_mm"), ref.k0, "k0", model),
          finite(peak) and peak / stress or 0 / 0, ref.peak / stress)
      else
        lines[#lines + 1] = ("| %s | %s | 0 | not run / %.2f | not run / %.2f | not run / %.1f | |"):format(surface, model,
          ref.peak, ref.residual, ref.k0)
      end
    end
  end
  if not any then
    lines[#lines + 1] = ""
    lines[#lines + 1] = ("No run of S1, S4, S5 or S8 at %g MPa: nothing to compare."):format(stress)
    return table.concat(lines, "\n") .. "\n"
  end
  lines[#lines + 1] = ""
  for _, model in ipairs(MODELS) do
    local d = diffs[model]
    if d then
      local parts = {}
      for _, f in ipairs{{"peak", "peak"}, {"residual", "residual"}, {"k0", "K0"}} do
        if d[f[1]] then
          parts[#parts + 1] = ("%s %+.1f %%"):format(f[2], 100 * (mean_sd(d[f[1]])))
        end
      end
      lines[#lines + 1] = ("- %s, mean difference over the surfaces run: %s"):format(model, table.concat(parts, ", "))
    end
  end
  return table.concat(lines, "\n") .. "\n"
end

-- What the study cost: per model the runs' wall times (every attempt of a resumed run; a run that
-- packed its specimen includes the packing), the packings, and the runner's elapsed time where the
-- runner recorded it (out/.study/elapsed.json; not for a Slurm study, whose tasks run apart).
-- A duration for people: "42 s", "3 min 07 s", "2 h 05 min" ("?" when not known).
function M.duration(seconds)
  if not finite(seconds) then return "?" end
  seconds = math.max(0, math.floor(seconds + 0.5))
  if seconds < 60 then return seconds .. " s" end
  if seconds < 3600 then return ("%d min %02d s"):format(seconds // 60, seconds % 60) end
  return ("%d h %02d min"):format(seconds // 3600, seconds % 3600 // 60)
end
function M.run_time(rows)
  local by, total, packed, pack_seconds = {}, 0, 0, 0
  for _, r in ipairs(rows) do
    if r.status == "finished" and finite(r.wall_seconds) then
      local m = by[r.model] or {runs = 0, seconds = 0, longest = 0, resumed = 0, memory = 0}
      by[r.model] = m
      m.runs, m.seconds = m.runs + 1, m.seconds + r.wall_seconds
      m.longest = math.max(m.longest, r.wall_seconds)
      if finite(r.resumes) and r.resumes > 0 then m.resumed = m.resumed + 1 end
      if finite(r.peak_memory_bytes) then m.memory = math.max(m.memory, r.peak_memory_bytes) end
      total = total + r.wall_seconds
      if (r.specimen_packed == true or r.specimen_packed == "true") and finite(r.specimen_seconds) then
        packed, pack_seconds = packed + 1, pack_seconds + r.specimen_seconds
      end
    end
  end
  return {models = by, total_seconds = total, packings = packed, packing_seconds = pack_seconds}
end
local function run_time_markdown(rows, elapsed)
  local duration = M.duration
  local T = M.run_time(rows)
  local lines = {"", "## Run time", ""}
  if T.total_seconds == 0 then
    lines[#lines + 1] = "No finished run records its wall time."
    return table.concat(lines, "\n") .. "\n"
  end
  if elapsed and finite(elapsed.seconds) then
    -- elapsed.json keeps the jobs and threads of the last invocation only
    local several = (elapsed.invocations or 1) > 1
    lines[#lines + 1] = ("The runner ran for **%s** in all (%d invocation%s, %s%d job%s of %d thread%s at a time; " ..
                         "the pauses between invocations not counted)."):format(duration(elapsed.seconds), elapsed.invocations or 1,
                         several and "s" or "", several and "the last " or "", elapsed.jobs or 0, elapsed.jobs == 1 and "" or "s",
                         elapsed.threads or 0, elapsed.threads == 1 and "" or "s")
  else
    lines[#lines + 1] = "The runner's elapsed time is not recorded for this folder (a Slurm study's tasks run apart; a folder " ..
                         "from before the runner recorded it); the runs' own times follow."
  end
  lines[#lines + 1] = ""
  lines[#lines + 1] = ("The runs' wall times add up to %s (a resumed run counts every attempt); %d specimen%s packed, %s of it " ..
                       "(inside the times of the runs that packed them)."):format(duration(T.total_seconds), T.packings,
                       T.packings == 1 and " was" or "s were", duration(T.packing_seconds))
  lines[#lines + 1] = ""
  lines[#lines + 1] = "| model | runs | wall time in sum | mean per run | longest | resumed | peak memory |"
  lines[#lines + 1] = "|---|---|---|---|---|---|---|"
  for _, model in ipairs(MODELS) do
    local m = T.models[model]
    if m then
      lines[#lines + 1] = ("| %s | %d | %s | %s | %s | %d | %s |"):format(model, m.runs, duration(m.seconds),
        duration(m.seconds / m.runs), duration(m.longest), m.resumed,
        m.memory > 0 and ("%.0f MB"):format(m.memory / 1e6) or "n/a")
    end
  end
  return table.concat(lines, "\n") .. "\n"
end

-- The figures inline (Markdown images, paths relative to the study folder), so that trends.md
-- reads as one page on a code host.
local SECTIONS = {{"strength", "Peak and residual against the surface statistics"},
                  {"stiffness", "Initial shear stiffness"}, {"energy", "Energy at the end of the shear"},
                  {"models", "The three models, per surface and normal stress"},
                  {"curves", "S1 to S8, per model, normal stress and direction"},
                  {"events", "Event statistics of the fracture runs (events/)"}}
local function figures_markdown(figures)
  if #figures == 0 then return "" end
  local lines = {"", "## Figures"}
  for _, sec in ipairs(SECTIONS) do
    local here = {}
    for _, f in ipairs(figures) do if f.section == sec[1] then here[#here + 1] = f end end
    table.sort(here, function(a, b) return a.file < b.file end)
    if #here > 0 then
      lines[#lines + 1] = ""
      lines[#lines + 1] = "### " .. sec[2]
      lines[#lines + 1] = ""
      for _, f in ipairs(here) do
        lines[#lines + 1] = ("![%s](%s)"):format((f.title or f.file):gsub("[%[%]]", ""), f.file)
      end
    end
  end
  return table.concat(lines, "\n") .. "\n"
end

-- Mean and scatter over seeds --------------------------------------------------------------------
local CASE_FIELDS = {"peak_shear_stress_mpa", "peak_displacement_mm", "residual_shear_stress_mpa",
                     "initial_shear_stiffness_mpa_per_mm", "max_dilatancy_mm", "normal_stiffness_mpa_per_mm",
                     "broken_bonds", "contact_decay_exponent", "energy_shares_friction",
                     -- the fracture model's criteria (M.fracture_criteria)
                     "closure_mm", "broken_bonds_in_closure", "broken_bonds_near_share", "broken_bond_fraction"}
function M.cases(rows)
  local groups, order = {}, {}
  for _, r in ipairs(rows) do
    if r.status == "finished" then
      local k = key(r, "seed")
      if not groups[k] then groups[k] = {}; order[#order + 1] = k end
      table.insert(groups[k], r)
    end
  end
  local cols = {"surface", "stress_mpa", "direction", "model", "seeds"}
  for _, f in ipairs(CASE_FIELDS) do cols[#cols + 1] = f .. "_mean"; cols[#cols + 1] = f .. "_sd" end
  local lines = {table.concat(cols, ",")}
  local cases = {}
  for _, k in ipairs(order) do
    local g = groups[k]
    local c = {surface = g[1].surface, stress_mpa = g[1].stress_mpa, direction = g[1].direction, model = g[1].model,
               seeds = #g}
    local fields = {c.surface, ("%g"):format(c.stress_mpa), c.direction, c.model, tostring(#g)}
    for _, f in ipairs(CASE_FIELDS) do
      local v = {}
      for _, r in ipairs(g) do if finite(r[f]) then v[#v + 1] = r[f] end end
      local m, sd = mean_sd(v)
      c[f .. "_mean"], c[f .. "_sd"] = m, sd
      fields[#fields + 1] = finite(m) and ("%.6g"):format(m) or ""
      fields[#fields + 1] = finite(sd) and ("%.6g"):format(sd) or ""
    end
    cases[#cases + 1] = c
    lines[#lines + 1] = table.concat(fields, ",")
  end
  return cases, table.concat(lines, "\n") .. "\n"
end

-- The fracture model against scenarios.md 4 -------------------------------------------------------
-- Per case (surface, stress, direction) the means over seeds of its fracture runs beside its rigid
-- and elastic runs: the peak and the residual between rigid and elastic (up to 3 % above the
-- higher), K0 within 10 % of the elastic model's, a closure larger than the elastic model's with
-- bonds breaking in it, at least 80 % of the broken bonds within 3 mm of the mean plane and at most
-- 10 % of the bonds broken. The spec judges a material on the mean of 3 realisations.
M.FRACTURE_ABOVE_HIGHER = 0.03
M.FRACTURE_K0_TOLERANCE = 0.10
local joint_report = require("joint.report")
M.FRACTURE_CRITERIA = {
  {id = "peak", text = "peak between rigid and elastic (up to 3 % above the higher)"},
  {id = "residual", text = "residual between rigid and elastic (likewise)"},
  {id = "k0", text = "K0 within 10 % of the elastic model's"},
  {id = "closure", text = "closure larger than the elastic model's, bonds breaking in it"},
  {id = "near", text = "at least 80 % of the broken bonds within 3 mm of the mean plane"},
  {id = "broken", text = "at most 10 % of the bonds broken"},
}

function M.fracture_criteria(rows)
  -- The means over seeds are M.cases's, per case and model.
  local all, by_model = M.cases(rows), {}
  for _, c in ipairs(all) do by_model[key(c, "seed")] = c end
  local function between(f, rigid, elastic)
    if not (finite(f) and finite(rigid) and finite(elastic)) then return nil end
    local lo, hi = math.min(rigid, elastic), math.max(rigid, elastic)
    return f >= lo and f <= (1 + M.FRACTURE_ABOVE_HIGHER) * hi
  end
  local cases, met_all = {}, 0
  for _, F in ipairs(all) do
    if F.model ~= "fracture" then goto next end
    local function other(model)
      local probe = {surface = F.surface, stress_mpa = F.stress_mpa, direction = F.direction, model = model}
      return by_model[key(probe, "seed")] or {seeds = 0}
    end
    local R, E = other("rigid"), other("elastic")
    local c = {surface = F.surface, stress_mpa = F.stress_mpa, direction = F.direction, seeds = F.seeds,
               rigid_runs = R.seeds, elastic_runs = E.seeds, values = {}, met = {}}
    local v = c.values
    local function mean(case, f) return case[f .. "_mean"] or 0/0 end
    for _, f in ipairs{"peak_shear_stress_mpa", "residual_shear_stress_mpa", "initial_shear_stiffness_mpa_per_mm",
                       "closure_mm"} do
      v[f] = {fracture = mean(F, f), rigid = mean(R, f), elastic = mean(E, f)}
    end
    for _, f in ipairs{"broken_bonds_in_closure", "broken_bonds_near_share", "broken_bond_fraction"} do v[f] = mean(F, f) end
    local peak, res = v.peak_shear_stress_mpa, v.residual_shear_stress_mpa
    local k0, cl = v.initial_shear_stiffness_mpa_per_mm, v.closure_mm
    c.met.peak = between(peak.fracture, peak.rigid, peak.elastic)
    c.met.residual = between(res.fracture, res.rigid, res.elastic)
    if finite(k0.fracture) and finite(k0.elastic) then
      c.met.k0 = math.abs(k0.fracture - k0.elastic) <= M.FRACTURE_K0_TOLERANCE * math.abs(k0.elastic)
    end
    if finite(cl.fracture) and finite(cl.elastic) and finite(v.broken_bonds_in_closure) then
      c.met.closure = cl.fracture > cl.elastic and v.broken_bonds_in_closure > 0
    end
    if finite(v.broken_bonds_near_share) then
      c.met.near = v.broken_bonds_near_share >= joint_report.NEAR_SHARE_MIN
    end
    if finite(v.broken_bond_fraction) then
      c.met.broken = v.broken_bond_fraction <= joint_report.BROKEN_FRACTION_MAX
    end
    local n, judged = 0, 0
    for _, crit in ipairs(M.FRACTURE_CRITERIA) do
      if c.met[crit.id] ~= nil then
        judged = judged + 1
        if c.met[crit.id] then n = n + 1 end
      end
    end
    c.criteria_met, c.criteria_judged = n, judged
    c.meets = judged == #M.FRACTURE_CRITERIA and n == judged
    if c.meets then met_all = met_all + 1 end
    cases[#cases + 1] = c
    ::next::
  end
  return {criteria = M.FRACTURE_CRITERIA, cases = cases, cases_meeting_all = met_all}
end

local function fracture_markdown(FC)
  local lines = {"", "## The fracture model against scenarios.md 4", ""}
  if #FC.cases == 0 then
    lines[#lines + 1] = "No finished fracture run: nothing to judge."
    return table.concat(lines, "\n") .. "\n"
  end
  local few = 0
  for _, c in ipairs(FC.cases) do if c.seeds < 3 then few = few + 1 end end
  lines[#lines + 1] = ("Each case's fracture runs (the mean over their seeds) against its rigid and elastic runs. " ..
                       "**%d of %d cases meet all six criteria**%s. A cell: the fracture value, then rigid .. elastic " ..
                       "or the criterion's bound; n/a where the runs to compare with are missing."):format(
                       FC.cases_meeting_all, #FC.cases,
                       few > 0 and (" (the spec judges the mean of 3 realisations: %d ran fewer seeds)"):format(few) or "")
  lines[#lines + 1] = ""
  lines[#lines + 1] = "| case | seeds | peak MPa | residual MPa | K0 MPa/mm | closure um (breaks) | within 3 mm | broken | met |"
  lines[#lines + 1] = "|---|---|---|---|---|---|---|---|---|"
  local function mark(ok) return ok == nil and "n/a" or (ok and "yes" or "**no**") end
  for _, c in ipairs(FC.cases) do
    local v = c.values
    local function range(t, digits)
      local f = "%." .. digits .. "f"
      return (f .. " (" .. f .. " .. " .. f .. ")"):format(t.fracture, t.rigid, t.elastic)
    end
    lines[#lines + 1] = ("| %s %g MPa %s | %d | %s %s | %s %s | %.1f (E %.1f) %s | %.1f (E %.1f; %.0f) %s | %.1f %% %s | %.1f %% %s | %d / %d |"):format(
      c.surface, c.stress_mpa, c.direction, c.seeds,
      range(v.peak_shear_stress_mpa, 2), mark(c.met.peak), range(v.residual_shear_stress_mpa, 2), mark(c.met.residual),
      v.initial_shear_stiffness_mpa_per_mm.fracture, v.initial_shear_stiffness_mpa_per_mm.elastic, mark(c.met.k0),
      1e3 * v.closure_mm.fracture, 1e3 * v.closure_mm.elastic, v.broken_bonds_in_closure, mark(c.met.closure),
      100 * v.broken_bonds_near_share, mark(c.met.near), 100 * v.broken_bond_fraction, mark(c.met.broken),
      c.criteria_met, c.criteria_judged)
  end
  return table.concat(lines, "\n") .. "\n"
end

-- Plots ------------------------------------------------------------------------------------------
local function plots(dir, rows, curves, log)
  local pdir = dir .. "/plots"
  asperity.mkdir(pdir)
  local done = {}
  for _, r in ipairs(rows) do if r.status == "finished" and curves[r.name] then done[#done + 1] = r end end
  if #done == 0 then return {} end
  local first_seed = math.huge
  for _, r in ipairs(done) do first_seed = math.min(first_seed, r.seed) end
  local figures, section = {}, nil
  local function draw(o)
    if fig.curves(o) then
      figures[#figures + 1] = {file = "plots/" .. o.file:match("([^/]+)$"), title = o.title, section = section}
    end
  end
  local function sel(pred)
    local t = {}
    for _, r in ipairs(done) do if r.seed == first_seed and pred(r) then t[#t + 1] = r end end
    return t
  end
  -- Curves of S1..S8 per model, stress and direction (the first seed).
  section = "curves"
  local cases = {}
  for _, r in ipairs(done) do
    local k = ("%s_%g_%s"):format(r.model, r.stress_mpa, r.direction)
    if not cases[k] then cases[k] = {model = r.model, stress = r.stress_mpa, direction = r.direction} end
  end
  for name, c in pairs(cases) do
    local runs = sel(function(r) return r.model == c.model and r.stress_mpa == c.stress and r.direction == c.direction end)
    table.sort(runs, function(a, b) return a.surface < b.surface end)
    for _, q in ipairs{{"shear", "shear_stress_mpa", "shear stress [MPa]"}, {"dilatancy", "dilatancy", "dilatancy [mm]"},
                       {"contacts", "contacts", "contacts between the halves"},
                       {"broken_bonds", "broken_bonds", "broken bonds"}} do
      if not (q[1] == "broken_bonds" and c.model ~= "fracture") then
        local series = {}
        for _, r in ipairs(runs) do
          series[#series + 1] = {title = r.surface, x = curves[r.name].displacement, y = curves[r.name][q[2]]}
        end
        draw{file = ("%s/%s_%s.png"):format(pdir, q[1], name), xlabel = "shear displacement [mm]", ylabel = q[3],
             title = ("%s, %g MPa, along -%s, seed %d"):format(c.model, c.stress, c.direction, first_seed), series = series}
      end
    end
  end
  -- Per surface and stress: the three models (colour) in both directions (x solid, y dashed).
  section = "models"
  local per = {}
  for _, r in ipairs(done) do per[("%s_%g"):format(r.surface, r.stress_mpa)] = {r.surface, r.stress_mpa} end
  for name, sc in pairs(per) do
    for _, q in ipairs{{"models", "shear_stress_mpa", "shear stress [MPa]"}, {"models_dilatancy", "dilatancy", "dilatancy [mm]"}} do
      local series = {}
      for _, m in ipairs(MODELS) do
        for _, d in ipairs{"x", "y"} do
          for _, r in ipairs(sel(function(r) return r.surface == sc[1] and r.stress_mpa == sc[2] and r.model == m and r.direction == d end)) do
            series[#series + 1] = {title = m .. " " .. d, x = curves[r.name].displacement, y = curves[r.name][q[2]],
                                   color = COLOR[m], dash = d == "y" and 2 or nil}
          end
        end
      end
      draw{file = ("%s/%s_%s.png"):format(pdir, q[1], name), xlabel = "shear displacement [mm]", ylabel = q[3],
           title = ("%s, %g MPa: rigid / elastic / fracture, x (solid) and y (dashed)"):format(sc[1], sc[2]), series = series}
    end
  end
  -- Peak (filled) and residual (open) against H, Lc, s2, per stress; the reference's at 14 MPa in black.
  section = "strength"
  local stresses = {}
  for _, r in ipairs(done) do stresses[r.stress_mpa] = true end
  for stress in pairs(stresses) do
    for axis, p in ipairs{{"H", "H"}, {"Lc", "Lc [mm]", "Lc_mm"}, {"s2", "s2 [mm^2]", "s2_mm2"}} do
      local series = {}
      for _, m in ipairs(MODELS) do
        for _, which in ipairs{{"peak", "peak_shear_stress_mpa", 7}, {"residual", "residual_shear_stress_mpa", 6}} do
          local xs, ys = {}, {}
          for _, r in ipairs(done) do
            if r.model == m and r.stress_mpa == stress then xs[#xs + 1] = r[p[3] or p[1]]; ys[#ys + 1] = r[which[2]] end
          end
          series[#series + 1] = {title = m .. " " .. which[1], x = xs, y = ys, style = "points", point = which[3],
                                 color = COLOR[m], size = 1.5}
        end
      end
      -- At another stress the thesis's values as ratios to the normal stress (reference.md 2: these
      -- transfer better than the MPa), in grey.
      local scale = stress / M.REFERENCE_STRESS
      for _, which in ipairs{{"peak", 5}, {"residual", 4}} do
        local xs, ys = {}, {}
        for _, s in ipairs(reference.surfaces) do
          for _, m in ipairs(MODELS) do xs[#xs + 1] = SURFACE[s][axis]; ys[#ys + 1] = thesis(s, m)[which[1]] * scale end
        end
        series[#series + 1] = {title = ("thesis %s (all models)%s"):format(which[1],
                                 scale == 1 and "" or (", x %g/%g"):format(stress, M.REFERENCE_STRESS)),
                               x = xs, y = ys, style = "points", point = which[2],
                               color = scale == 1 and "#000000" or "#808080", size = 1.2}
      end
      draw{file = ("%s/strength_vs_%s_%g.png"):format(pdir, p[1], stress), xlabel = p[2], ylabel = "shear stress [MPa]",
           title = ("peak (filled) and residual (open) at %g MPa"):format(stress), series = series,
           key = "outside bottom center horizontal maxrows 3", height = 700, extra = "set offsets graph 0.05, graph 0.05, graph 0.05, 0\n"}
    end
  end
  -- Initial shear stiffness against the normal stress.
  section = "stiffness"
  do
    local series = {}
    for _, m in ipairs(MODELS) do
      local xs, ys = {}, {}
      for _, r in ipairs(done) do
        if r.model == m then xs[#xs + 1] = r.stress_mpa; ys[#ys + 1] = r.initial_shear_stiffness_mpa_per_mm end
      end
      series[#series + 1] = {title = m, x = xs, y = ys, style = "points", color = COLOR[m], size = 1.5}
      local rx, ry = {}, {}
      for _, s in ipairs(reference.surfaces) do rx[#rx + 1] = M.REFERENCE_STRESS; ry[#ry + 1] = thesis(s, m).k0 end
      series[#series + 1] = {title = "thesis " .. m, x = rx, y = ry, style = "points", point = 4, color = COLOR[m], size = 2}
    end
    local lo, hi = M.REFERENCE_STRESS, M.REFERENCE_STRESS
    for _, r in ipairs(done) do lo, hi = math.min(lo, r.stress_mpa), math.max(hi, r.stress_mpa) end
    draw{file = pdir .. "/shear_stiffness_vs_stress.png", xlabel = "normal stress [MPa]",
         ylabel = "initial shear stiffness [MPa/mm]", title = "initial shear stiffness (thesis: S1, S4, S5, S8 at 14 MPa)",
         series = series, xrange = ("%g:%g"):format(lo - 0.1 * (hi - lo) - 1, hi + 0.1 * (hi - lo) + 1)}
  end
  -- Energy shares at the end of the shear per surface (mean over the runs of a surface), per model.
  section = "energy"
  for _, m in ipairs(MODELS) do
    local series = {}
    for _, term in ipairs{"friction", "damping", "strain", "kinetic", "released"} do
      local xs, ys = {}, {}
      for k = 1, 8 do
        local v = {}
        for _, r in ipairs(done) do
          if r.model == m and r.surface == "S" .. k and finite(r["energy_shares_" .. term]) then v[#v + 1] = r["energy_shares_" .. term] end
        end
        if #v > 0 then xs[#xs + 1] = k; ys[#ys + 1] = (mean_sd(v)) end
      end
      series[#series + 1] = {title = term, x = xs, y = ys, style = "linespoints"}
    end
    draw{file = ("%s/energy_shares_%s.png"):format(pdir, m), xlabel = "surface (S1..S8)", ylabel = "share of the input work",
         title = m .. ": energy terms at the end of the shear (thesis: friction ~0.8)", series = series,
         extra = "set xtics 1\n"}
  end
  return figures
end

-- Event statistics -------------------------------------------------------------------------------
local function events(dir, rows, log)
  local edir = dir .. "/events"
  local results, missing = {}, {}
  for _, r in ipairs(rows) do
    if r.status == "finished" and r.model == "fracture" then
      local a = ev.analyse_run(dir .. "/" .. r.name)
      if a then a.name = r.name; results[#results + 1] = a else missing[#missing + 1] = r.name end
    end
  end
  if #results == 0 then
    return {runs = 0, note = #missing > 0 and "fracture runs without breaks.csv or events.csv (no bond broke, no samples)"
                                          or "no finished fracture run"}
  end
  asperity.mkdir(edir)
  local summary = {"run,breaks,intervals,interval_steps,breaks_per_100_steps,events,b,b_error,b_energy,b_energy_error"}
  local pooled_sizes, pooled_mags, size_series = {}, {}, {}
  local xsum, xweight = {kinetic = {}, strain = {}, damping = {}}, {kinetic = {}, strain = {}, damping = {}}
  local pooled_fluct = {kinetic = {}, strain = {}, damping = {}}
  local sampled, pooled_breaks, pooled_intervals = 0, 0, 0
  for _, a in ipairs(results) do
    summary[#summary + 1] = ("%s,%d,%d,%d,%.6g,%d,%.6g,%.6g,%.6g,%.6g"):format(a.name, a.breaks, a.intervals, a.interval,
      a.breaks_per_100_steps, #a.sizes, a.b, a.b_error, a.b_energy, a.b_energy_error)
    local lines = {"interval,breaks"}
    local ks = {}
    for k, c in ipairs(a.counts) do lines[#lines + 1] = k .. "," .. c; ks[k] = k end
    write_atomic(("%s/%s_breaks.csv"):format(edir, a.name), table.concat(lines, "\n") .. "\n")
    fig.curves{file = ("%s/%s_breaks.png"):format(edir, a.name), xlabel = ("interval (%d steps) of the shear"):format(a.interval),
               ylabel = "bonds broken in the interval", series = {{title = "", x = ks, y = a.counts, style = "impulses"}},
               title = ("%s: %d breaks, %.3g per 100 steps, %d events, b = %.2f +- %.2f"):format(a.name, a.breaks,
                 a.breaks_per_100_steps, #a.sizes, a.b, a.b_error)}
    pooled_breaks, pooled_intervals = pooled_breaks + a.breaks, pooled_intervals + a.intervals * a.interval / 100
    local xs, ns = ev.ccdf(a.sizes)
    lines = {"size,events_at_least"}
    for k = 1, #xs do lines[#lines + 1] = xs[k] .. "," .. ns[k] end
    write_atomic(("%s/%s_sizes.csv"):format(edir, a.name), table.concat(lines, "\n") .. "\n")
    size_series[#size_series + 1] = {title = "", x = xs, y = ns, style = "linespoints", point = 7, size = 0.6, width = 1}
    for _, s in ipairs(a.sizes) do pooled_sizes[#pooled_sizes + 1] = s end
    for _, e in ipairs(a.event_energy) do if e > 0 then pooled_mags[#pooled_mags + 1] = math.log(e, 10) end end
    if a.xcorr then
      sampled = sampled + 1
      lines = {"lag,kinetic,strain,damping"}
      for lag = 0, 20 do
        lines[#lines + 1] = ("%d,%.6g,%.6g,%.6g"):format(lag, a.xcorr.kinetic[lag + 1], a.xcorr.strain[lag + 1], a.xcorr.damping[lag + 1])
      end
      write_atomic(("%s/%s_xcorr.csv"):format(edir, a.name), table.concat(lines, "\n") .. "\n")
      lines = {"interval,kinetic,strain,damping"}
      for k = 1, #a.fluctuations.kinetic do
        lines[#lines + 1] = ("%d,%.6g,%.6g,%.6g"):format(k, a.fluctuations.kinetic[k], a.fluctuations.strain[k], a.fluctuations.damping[k])
      end
      write_atomic(("%s/%s_fluctuations.csv"):format(edir, a.name), table.concat(lines, "\n") .. "\n")
      local xs_, ds = {}, {}
      local lags = {}
      for lag = 0, 20 do lags[lag + 1] = lag end
      for _, term in ipairs{"kinetic", "strain", "damping"} do
        local c, d = ev.density(a.fluctuations[term], 40, 8)
        ds[#ds + 1] = {title = term, x = c, y = d, style = "linespoints"}
        xs_[#xs_ + 1] = {title = term, x = lags, y = a.xcorr[term], style = "linespoints"}
      end
      fig.curves{file = ("%s/%s_xcorr.png"):format(edir, a.name), xlabel = "lag [intervals]",
                 ylabel = "correlation with the break count", title = a.name .. ": breaks(t) against fluctuation(t + lag)",
                 series = xs_}
      fig.curves{file = ("%s/%s_fluctuations.png"):format(edir, a.name), logy = true, xlabel = "fluctuation / its SD",
                 ylabel = "probability density", title = a.name .. ": energy change per interval", series = ds}
      -- Pooled: each run's fluctuations in units of its own SD; correlations weighted by length.
      local w = #a.counts
      for term, r in pairs(a.xcorr) do
        for lag = 1, 21 do
          if finite(r[lag]) then
            xsum[term][lag] = (xsum[term][lag] or 0) + w * r[lag]
            xweight[term][lag] = (xweight[term][lag] or 0) + w
          end
        end
        local m, sd = mean_sd(a.fluctuations[term])
        if sd > 0 then for _, v in ipairs(a.fluctuations[term]) do table.insert(pooled_fluct[term], (v - m) / sd) end end
      end
    end
  end
  local pb, pe, pn = ev.aki_b(pooled_sizes, {sizes = true})
  local pbe, pee = ev.aki_b(pooled_mags, {magnitudes = true})
  summary[#summary + 1] = ("pooled,%d,,,%.6g,%d,%.6g,%.6g,%.6g,%.6g"):format(pooled_breaks,
    pooled_intervals > 0 and pooled_breaks / pooled_intervals or 0/0, #pooled_sizes, pb, pe, pbe, pee)
  write_atomic(edir .. "/summary.csv", table.concat(summary, "\n") .. "\n")
  local xs, ns = ev.ccdf(pooled_sizes)
  size_series[#size_series + 1] = {title = ("pooled: b = %.2f +- %.2f (%d events)"):format(pb, pe, pn), x = xs, y = ns,
                                   style = "linespoints", color = "#000000", point = 5, width = 3}
  -- The pooled figures drawn, for trends.md (paths relative to the study folder).
  local drawn = {}
  local function pooled(name, o)
    o.file = ("%s/%s.png"):format(edir, name)
    if fig.curves(o) then drawn[#drawn + 1] = {file = ("events/%s.png"):format(name), title = o.title, section = "events"} end
  end
  pooled("sizes", {logx = true, logy = true, xlabel = "event size S [broken bonds]",
                   ylabel = "events with size >= S", title = "break events (M = log10 S): each fracture run (thin), pooled (black)",
                   series = size_series, key = "top right"})
  local out = {runs = #results, sampled_runs = sampled, pooled_events = #pooled_sizes, pooled_b = pb, pooled_b_error = pe,
               pooled_breaks = pooled_breaks,
               pooled_breaks_per_100_steps = pooled_intervals > 0 and pooled_breaks / pooled_intervals or 0/0,
               pooled_b_energy = pbe, pooled_b_energy_error = pee,
               magnitude = "M = log10 S, S the bonds broken in one event (consecutive intervals with breaks); " ..
                           "b by maximum likelihood (lib/events.lua); b_energy on M_E = log10(E / 1 J)",
               per_run = {}}
  for _, a in ipairs(results) do
    out.per_run[#out.per_run + 1] = {run = a.name, breaks = a.breaks, breaks_per_100_steps = a.breaks_per_100_steps,
                                     interval_steps = a.interval, events = #a.sizes, b = a.b, b_error = a.b_error,
                                     b_energy = a.b_energy, b_energy_error = a.b_energy_error, energies_sampled = a.xcorr ~= nil}
  end
  if sampled > 0 then
    local lines = {"lag,kinetic,strain,damping"}
    local series = {}
    for _, term in ipairs{"kinetic", "strain", "damping"} do
      local lx, ly = {}, {}
      for lag = 0, 20 do lx[#lx + 1] = lag; ly[#ly + 1] = (xsum[term][lag + 1] or 0/0) / (xweight[term][lag + 1] or 0/0) end
      series[#series + 1] = {title = term, x = lx, y = ly, style = "linespoints"}
    end
    for lag = 0, 20 do
      lines[#lines + 1] = ("%d,%.6g,%.6g,%.6g"):format(lag, series[1].y[lag + 1], series[2].y[lag + 1], series[3].y[lag + 1])
    end
    write_atomic(edir .. "/xcorr.csv", table.concat(lines, "\n") .. "\n")
    pooled("xcorr", {xlabel = "lag [intervals]", ylabel = "correlation with the break count",
                     title = "breaks(t) against energy fluctuation(t + lag), pooled", series = series})
    local dseries = {}
    lines = {"z,kinetic,strain,damping"}
    local dens = {}
    for k, term in ipairs{"kinetic", "strain", "damping"} do
      local c, d = ev.density(pooled_fluct[term], 40, 8)
      dens[k] = {c, d}
      dseries[#dseries + 1] = {title = term, x = c, y = d, style = "linespoints"}
    end
    for i = 1, #(dens[1][1]) do
      lines[#lines + 1] = ("%.4g,%.6g,%.6g,%.6g"):format(dens[1][1][i], dens[1][2][i], dens[2][2][i] or 0/0, dens[3][2][i] or 0/0)
    end
    write_atomic(edir .. "/fluctuations.csv", table.concat(lines, "\n") .. "\n")
    pooled("fluctuations", {logy = true, xlabel = "fluctuation / its SD",
                            ylabel = "probability density", title = "energy change per interval, pooled", series = dseries})
  else
    out.note = "energies not sampled (joint.lua events_every=0): no fluctuations or cross-correlations"
  end
  write_atomic(edir .. "/events.json", asperity.json(out))
  return out, drawn
end

-- Everything ---------------------------------------------------------------------------------------
function M.write(o)
  local dir, rows = o.dir, o.rows
  local log = o.log or function() end
  local curves = {}
  for _, r in ipairs(rows) do
    if r.status == "finished" then curves[r.name] = ev.read_csv(dir .. "/" .. r.name .. "/shear.csv") end
  end
  local _, cases_csv = M.cases(rows)
  write_atomic(dir .. "/study_cases.csv", cases_csv)
  local T = M.trends(rows, curves)
  local FC = M.fracture_criteria(rows)
  write_atomic(dir .. "/trends.json", asperity.json({trends = T, fracture_criteria = FC}))
  local figures = plots(dir, rows, curves, log)
  local n = #figures
  local e, pooled = events(dir, rows, log)
  for _, f in ipairs(pooled or {}) do figures[#figures + 1] = f end
  write_atomic(dir .. "/trends.md", trends_markdown(T, rows) .. fracture_markdown(FC) .. reference_markdown(rows)
                                    .. run_time_markdown(rows, o.elapsed)
                                    .. figures_markdown(figures))
  local shown = 0
  for _, t in ipairs(T) do if t.verdict == "shown" then shown = shown + 1 end end
  log("report: trends.md (%d of %d behaviours shown; %d of %d cases of the fracture model meet scenarios.md 4), " ..
      "%d plots in plots/, events of %d fracture runs%s", shown, #T, FC.cases_meeting_all, #FC.cases, n, e.runs,
      e.pooled_b and (": pooled b = %.2f +- %.2f"):format(e.pooled_b, e.pooled_b_error) or "")
end

return M
