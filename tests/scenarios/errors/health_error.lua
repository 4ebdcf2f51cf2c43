-- A time step far above the critical one (allowed on purpose): the run blows up, and the engine
-- stops it with the step, particle and quantity in the message.
local w = asperity.world{material = {kn = 1e4}, dt = 0.05, allow_dt_above_estimate = true}
w:add_particle({0, 0, 0}, 0.01)
w:add_particle({0.019, 0, 0}, 0.01)
w:cycle(100)
