-- Writes past a file-size limit (run under `ulimit -f`, see CMakeLists.txt): each failed write
-- raises an error naming the file and leaves the previous file as it was; the run then ends
-- normally (no crash at exit).
local out = assert(params.out, "give out=DIRECTORY")

local function refuses(pattern, f, ...)
  local ok, err = pcall(f, ...)
  assert(not ok, "expected an error matching '" .. pattern .. "', the call succeeded")
  assert(tostring(err):find(pattern), "error '" .. tostring(err) .. "' does not match '" .. pattern .. "'")
end

local small = asperity.world{}
small:add_particle({0, 0, 0}, 0.001)
small:add_particle({0.003, 0, 0}, 0.001)
local path = out .. "/world.h5"
small:save(path)

-- Far larger than the limit: the write fails; the small checkpoint is still there and loads.
local big = asperity.world{}
local xyz, r = {}, {}
for i = 0, 39999 do
  xyz[#xyz + 1] = {(i % 200) * 0.003, (i // 200) * 0.003, 0}
  r[#r + 1] = 0.001
end
big:add_particles(xyz, r)
refuses("cannot write '.*world.h5': write: File too large", big.save, big, path)
assert(asperity.load(path):particle_count() == 2, "the previous checkpoint is untouched")

-- The other writers: JSON, series (HDF5 and CSV), snapshots, surfaces.
local json = out .. "/summary.json"
asperity.write_json(json, {ok = true})
local huge = {}
for i = 1, 200000 do huge[i] = i + 0.5 end
refuses("cannot write '.*summary.json'", asperity.write_json, json, huge)
assert(io.open(json):read("a"):find('"ok": true'), "the previous JSON is untouched")

local s = asperity.series{"x [m]"}
for i = 1, 200000 do s:record(i * 1e-3) end
refuses("cannot write '.*series.h5'", s.write_h5, s, out .. "/series.h5")
refuses("cannot write '.*series.csv'", s.write_csv, s, out .. "/series.csv")

local snaps = asperity.snapshots{dir = out .. "/snaps"}
refuses("cannot write", snaps.write, snaps, big)

local m = asperity.surface.generate{name = "S5", n = 513, seed = 1}
refuses("cannot write '.*surface.h5'", m.save, m, out .. "/surface.h5")
refuses("cannot write '.*surface.csv'", m.save_csv, m, out .. "/surface.csv")

-- Plots (gnuplot writes the PNG; an image cut short is an error, not a file), when gnuplot is here.
if os.execute("command -v gnuplot >/dev/null 2>&1") then
  local x = {}
  for i = 1, 100000 do x[i] = i end
  refuses("plot", asperity.plot, {file = out .. "/plot.png", x = x, y = x, points = true,
                                                width = 4000, height = 4000})
end

-- The small world can still be written (the failures left nothing open behind them).
small:save(out .. "/again.h5")
assert(asperity.load(out .. "/again.h5"):particle_count() == 2)
print("PASS")
