-- world:run's progress when stderr is not a terminal (a log; run with ASPERITY_PROGRESS_EVERY set
-- small): a run ended by its stop condition shows no percent or ETA from its step cap, a run of a
-- known number of steps does. The test's regular expressions read the lines (show = which run).
local w = asperity.world{gravity = {0, 0, 0}, material = {kn = 1e3, ks = 1e2, friction = 0.3}, density = 2000,
                         damping = 0.5, threads = 1}
for i = 0, 999 do w:add_particle({(i % 10) * 0.0199, (i // 10 % 10) * 0.0199, (i // 100) * 0.0199}, 0.01) end
local t0 = asperity.wall_time()
local capped = w:run{steps = 100000000, every = 50, show = function() return "capped run" end,
                     stop_when = function() return asperity.wall_time() - t0 > 0.4 end}
local rate = capped / (asperity.wall_time() - t0)
w:run{steps = math.max(100, math.floor(0.4 * rate)), show = function() return "bounded run" end}
print("PASS")
