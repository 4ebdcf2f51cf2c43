local w = asperity.world()
w:add_particle({0, 0, 0}, 0.1)
os.execute("(sleep 1; kill -INT $PPID) &")
w:cycle(1000000000000)
