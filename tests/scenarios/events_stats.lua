-- The event statistics of the study (scripts/lib/events.lua): the b-value estimators recover a
-- known b from synthetic Gutenberg-Richter samples (magnitudes, and event sizes in whole bonds
-- with Smin 1 and 5) within three standard errors, with standard errors near b / sqrt(n); the
-- interval counts, events and cross-correlations of one run are what a hand count gives.
local ev = require("events")
local out = assert(params.out, "give out=DIRECTORY")
asperity.mkdir(out)
math.randomseed(20261127)
local n = 3000
for _, b in ipairs{0.7, 1.0, 1.4} do
  local mags, sizes1, sizes5 = {}, {}, {}
  for i = 1, n do
    mags[i] = 1.5 - math.log(1 - math.random(), 10) / b                              -- Mc = 1.5
    sizes1[i] = math.floor(0.5 * (1 - math.random()) ^ (-1 / b) + 0.5)                 -- Smin = 1
    sizes5[i] = math.floor(4.5 * (1 - math.random()) ^ (-1 / b) + 0.5)                 -- Smin = 5
  end
  for name, case in pairs{magnitudes = {mags, {magnitudes = true, min = 1.5}}, sizes_from_1 = {sizes1, {sizes = true}},
                          sizes_from_5 = {sizes5, {sizes = true}}} do
    local est, err, used = ev.aki_b(case[1], case[2])
    print(("b = %.2f, %s: %.4f +- %.4f (%d events)"):format(b, name, est, err, used))
    assert(used == n, name .. ": every event is above the threshold")
    assert(math.abs(est - b) < 3 * err, ("%s: b %.4f against %.2f (error %.4f)"):format(name, est, b, err))
    assert(math.abs(err / (b / math.sqrt(n)) - 1) < 0.3, ("%s: standard error %.4f, b/sqrt(n) %.4f"):format(name, err, b / math.sqrt(n)))
  end
end
-- A threshold leaves the smaller events out.
local _, _, used = ev.aki_b({1, 1, 2, 3, 8}, {sizes = true, min = 2})
assert(used == 3, "min = 2 keeps 3 of 5 sizes")

-- One run by hand: samples every 100 steps from step 1000; breaks at steps 1001, 1050 (interval 1),
-- 1150 (interval 2), 1350, 1351, 1352 (interval 4).
local dir = out .. "/run"
asperity.mkdir(dir)
local f = assert(io.open(dir .. "/events.csv", "w"))
f:write("step [1],displacement [mm],broken_bonds [1],kinetic [J],strain [J],damping [J],friction [J],released [J]\n")
local breaks_by_sample = {0, 2, 3, 3, 6, 6, 6}
for k = 1, 7 do
  -- The kinetic energy rises by the breaks of the interval (so its fluctuation is the count).
  f:write(("%d,0,%d,%g,1,%g,0,0\n"):format(1000 + 100 * (k - 1), breaks_by_sample[k], breaks_by_sample[k], k))
end
f:close()
f = assert(io.open(dir .. "/breaks.csv", "w"))
f:write("step [1],time [s],x [m],y [m],z [m],mode [1],sigma [Pa],tau [Pa],released_energy [J]\n")
for _, s in ipairs{1001, 1050, 1150, 1350, 1351, 1352} do f:write(("%d,0,0,0,0,1,0,0,0.5\n"):format(s)) end
f:close()
local r = ev.analyse_run(dir)
local want = {2, 1, 0, 3, 0, 0}
for k = 1, 6 do assert(r.counts[k] == want[k], ("interval %d: %d breaks, want %d"):format(k, r.counts[k], want[k])) end
assert(math.abs(r.breaks_per_100_steps - 1) < 1e-12, "6 breaks in 6 intervals of 100 steps")
assert(#r.sizes == 2 and r.sizes[1] == 3 and r.sizes[2] == 3, "events: intervals 1-2 (3 breaks) and 4 (3 breaks)")
assert(math.abs(r.event_energy[1] - 1.5) < 1e-12, "an event's energy is the sum of its breaks'")
assert(math.abs(r.xcorr.kinetic[1] - 1) < 1e-12, "lag 0: the kinetic fluctuation equals the count")
assert(r.xcorr.strain[1] ~= r.xcorr.strain[1], "a constant term has no correlation (NaN)")
-- A run sampled without a single break: its intervals count, all empty; no event, no b.
local quiet = out .. "/quiet"
asperity.mkdir(quiet)
f = assert(io.open(quiet .. "/events.csv", "w"))
f:write("step [1],displacement [mm],broken_bonds [1],kinetic [J],strain [J],damping [J],friction [J],released [J]\n")
for k = 1, 5 do f:write(("%d,0,0,%g,1,%g,0,0\n"):format(100 * k, k, k)) end
f:close()
local q = ev.analyse_run(quiet)
assert(q and q.breaks == 0 and q.intervals == 4 and q.breaks_per_100_steps == 0 and #q.sizes == 0 and q.b ~= q.b,
       "a run without breaks")
assert(ev.analyse_run(out .. "/nothing_here") == nil, "a folder with neither file")
print("PASS")
