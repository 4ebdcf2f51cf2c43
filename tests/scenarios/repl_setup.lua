-- Loaded by `asperity repl repl_setup.lua n=3`: a world the session goes on with.
w = asperity.world()
for i = 1, params.n do w:add_particle({i, 0, 0}, 0.1) end
