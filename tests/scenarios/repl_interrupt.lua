w = asperity.world(); w:add_particle({0, 0, 0}, 0.1)
local _ = os.execute("(sleep 1; kill -INT $PPID) &") w:cycle(1000000000000)
"alive after Ctrl-C"
error("interrupted, says a plain error")
w:step() > 0
