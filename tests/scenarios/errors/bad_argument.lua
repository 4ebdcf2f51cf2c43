local w = asperity.world()
w:add_particle({0, 0, 0}, "big")
