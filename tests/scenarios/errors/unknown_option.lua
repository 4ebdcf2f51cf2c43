local w = asperity.world{gravty = {0, 0, -9.81}}
