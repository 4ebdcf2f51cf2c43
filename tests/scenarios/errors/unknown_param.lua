local P = require("params").defaults{n = 10}
