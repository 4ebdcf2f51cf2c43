local w = asperity.world()
w:run{steps = "many"}
