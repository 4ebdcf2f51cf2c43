-- Constant normal stiffness (joint.lua normal_control=stiffness): on a tiny joint (8 mm, ~200
-- particles) the normal stress follows sigma_0 + K x dilatancy while the joint dilates, and the
-- same joint under constant normal load does not (so the check can tell the two apart).
local out = assert(params.out, "give out=DIRECTORY")
local function joint(p)
  local given = {size = 0.008, thickness = 0.003, shear = 1, pack_steps = 50000, progress = false,
                 surface = "S1", model = "elastic", cache = out .. "/cache"}
  for k, v in pairs(p) do given[k] = v end
  params = given
  return dofile(asperity.scripts_dir .. "/joint.lua")
end
local function rows(path)
  local f = assert(io.open(path))
  local header = f:read("l")
  local cols = {}
  for name in header:gmatch("[^,]+") do cols[#cols + 1] = name:match("^(%S+)") end
  local t = {}
  for line in f:lines() do
    local r, k = {}, 0
    for v in line:gmatch("[^,]+") do k = k + 1; r[cols[k]] = tonumber(v) end
    t[#t + 1] = r
  end
  f:close()
  return t
end

local K, sigma0 = 20, 14   -- MPa/mm, MPa
local cns = joint{normal_control = "stiffness", normal_stiffness = K, stress = sigma0, out = out .. "/cns"}
local cnl = joint{stress = sigma0, out = out .. "/cnl"}
assert(cns.max_dilatancy_mm > 0.2, ("the joint must dilate for the test to mean something (%.3g mm)"):format(cns.max_dilatancy_mm))

-- The interval-mean normal stress against sigma_0 + K x the interval's mean dilatancy.
local function follows(path, stiffness)
  local r = rows(path)
  local within, n, worst = 0, 0, 0
  for k = 2, #r do
    if r[k].displacement > 0.05 then
      local target = sigma0 + stiffness * 0.5 * (r[k].dilatancy + r[k - 1].dilatancy)
      local dev = math.abs(r[k].normal_stress_mean_mpa / target - 1)
      n, worst = n + 1, math.max(worst, dev)
      if dev <= 0.02 then within = within + 1 end
    end
  end
  return within / n, worst, r[#r]
end
local frac, worst, last = follows(out .. "/cns/shear.csv", K)
print(("CNS: %.3f of the records within 2 %% of sigma_0 + K dilatancy (worst %.3g); at the end %.2f MPa, dilatancy %.3f mm")
      :format(frac, worst, last.normal_stress_mean_mpa, last.dilatancy))
assert(frac >= 0.95, ("CNS: only %.3f of the records follow sigma_0 + K dilatancy within 2 %%"):format(frac))
assert(last.normal_stress_mean_mpa > sigma0 + 0.5 * K * last.dilatancy,
       ("CNS: the normal stress %.3g MPa did not rise with the dilatancy %.3g mm"):format(last.normal_stress_mean_mpa, last.dilatancy))
assert(cns.normal_stress_deviation_p95 <= 0.02, "the summary measures the deviation from sigma_0 + K dilatancy")
-- Under constant normal load the same comparison fails: the stress stays at sigma_0.
local frac_cnl = follows(out .. "/cnl/shear.csv", K)
assert(frac_cnl < 0.5, ("CNL: %.3f of the records look like CNS; the check does not discriminate"):format(frac_cnl))
assert(cnl.normal_stress_deviation_p95 <= 0.01, "CNL still holds sigma_0")
print("PASS")
