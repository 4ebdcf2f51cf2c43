local w = asperity.world{material = {kn = 1e4}, dt = 0.05}
w:add_particle({0, 0, 0}, 0.01)
w:add_particle({0.019, 0, 0}, 0.01)
w:cycle(100)
