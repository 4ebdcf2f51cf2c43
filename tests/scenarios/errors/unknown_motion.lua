local w = asperity.world()
w:add_particle({0, 0, 0}, 0.01)
w:add_group({1}, {translation = "flying"})
