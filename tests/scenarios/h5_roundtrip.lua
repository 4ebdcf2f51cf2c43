-- Files written by a run read back equal to what the world holds: snapshots (HDF5 + XDMF),
-- a series (HDF5 + CSV) and a JSON summary. Run with out=DIRECTORY.
local out = assert(params.out, "give out=DIRECTORY")
asperity.mkdir(out)

local w = asperity.world{gravity = {0, 0, -9.81}, material = {kn = 1e3, ks = 1e2}}
w:add_plane{point = {0, 0, 0}, normal = {0, 0, 1}}
for i = 1, 12 do
  w:add_particle({0.021 * (i % 4), 0.021 * (i // 4), 0.0101}, 0.0105)
end
local g = w:add_group({1, 2})
local s = asperity.series{"step", "time [s]", "kinetic [J]", attributes = {kn = 1e3, note = "roundtrip"}}
w:run{steps = 200, every = 20, callback = function(w)
  s:record{step = w:step(), time = w:time(), kinetic = w:energies().kinetic}
end}

local snaps = asperity.snapshots{dir = out, name = "snap"}
snaps:write(w)
w:cycle(10)
local path = snaps:write(w, {label = "second"})
assert(snaps:count() == 2)

local function same(a, b, what)
  local ra, ca = a:size()
  local rb, cb = b:size()
  assert(ra == rb and ca == cb, what .. ": shape " .. ra .. "x" .. ca .. " vs " .. rb .. "x" .. cb)
  for i = 1, ra do
    for j = 1, ca do
      assert(a:get(i, j) == b:get(i, j), ("%s: (%d, %d) differs: %.17g vs %.17g"):format(what, i, j, a:get(i, j), b:get(i, j)))
    end
  end
end

same(asperity.read_h5(path, "/particles/position"), w:positions(), "position")
same(asperity.read_h5(path, "/particles/velocity"), w:velocities(), "velocity")
same(asperity.read_h5(path, "/particles/radius"), w:radii(), "radius")
local ids = asperity.read_h5(path, "/particles/id")
for i = 1, #ids do assert(ids[i] == i, "ids count from 1") end
local groups = asperity.read_h5(path, "/particles/group")
assert(groups[1] == g and groups[2] == g and groups[3] == -1, "group numbers")
local contacts = asperity.read_h5(path, "/contacts/normal_force")
assert(#contacts == w:contact_count(), "one row per contact")
local listed = w:contacts()
for k, c in ipairs(listed) do
  assert(contacts[k] == c.normal_force, "contact normal force " .. k)
end
assert(asperity.h5_attribute(path, "/", "step") == w:step())
assert(asperity.h5_attribute(path, "/", "time") == w:time())
assert(asperity.h5_attribute(path, "/", "label") == "second")
assert(asperity.h5_attribute(path, "/particles/position", "units") == "m")
assert(asperity.h5_attribute(path, "/contacts/normal_force", "units") == "N")

local xdmf = assert(io.open(snaps:xdmf())):read("a")
assert(xdmf:find("snap_000001.h5:/particles/position", 1, true), "XDMF lists the second snapshot")
assert(xdmf:find('CollectionType="Temporal"', 1, true))

-- series
local h5, csv = s:write(out .. "/series")
assert(s:rows() == 10)
same(asperity.read_h5(h5, "/time"), s:column("time"), "series time")
same(asperity.read_h5(h5, "/kinetic"), s:column("kinetic"), "series kinetic")
assert(asperity.h5_attribute(h5, "/time", "units") == "s")
assert(asperity.h5_attribute(h5, "/", "note") == "roundtrip")
assert(asperity.h5_attribute(h5, "/", "kn") == 1e3)
local lines = {}
for line in io.lines(csv) do lines[#lines + 1] = line end
assert(lines[1] == "step,time [s],kinetic [J]", "CSV header: " .. lines[1])
assert(#lines == 11)
local step1, t1 = lines[2]:match("^([^,]+),([^,]+),")
assert(tonumber(step1) == s:column("step")[1] and tonumber(t1) == s:column("time")[1], "CSV values exact")

-- JSON
asperity.write_json(out .. "/summary.json", {steps = w:step(), list = {1, 2.5, "x"}, nested = {ok = true}})
local text = assert(io.open(out .. "/summary.json")):read("a")
assert(text:find('"steps": 210', 1, true) and text:find('[1, 2.5, "x"]', 1, true) and text:find('"ok": true', 1, true), text)

-- no temporary files left behind
for name in io.popen('ls -a "' .. out .. '"'):lines() do
  assert(not name:find("%.tmp%-"), "leftover temporary file " .. name)
end
print("PASS")
