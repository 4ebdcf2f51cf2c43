-- The size study (scripts/size_study.lua) on tiny rigid joints (8 and 10 mm): one study folder per
-- size through the real runner, the table (mean per size and model, the difference from the
-- largest size, the verdict), the plot; a rerun finds every run finished and rebuilds the same table.
local json = require("json")
local out = assert(params.out, "give out=DIRECTORY")
os.execute("rm -rf '" .. out .. "'")
asperity.mkdir(out)
local sh = require("shell")
local exe = sh.program()
local script = asperity.scripts_dir .. "/size_study.lua"
local read = sh.read
local function run(args, log) return sh.run(("%s run %s %s"):format(sh.quote(exe), sh.quote(script), args), log) end

local dir = out .. "/size"
local args = ("sizes=0.01,0.008 models=rigid jobs=2 threads=1 tolerance=0.2 out='%s' " ..
              "joint='thickness=0.003 shear=1 pack_steps=50000'"):format(dir)
local status, log = run(args, out .. "/size.log")
assert(status == 0, "the size study failed:\n" .. log)
for _, cm in ipairs{"0.8", "1"} do
  assert(read(("%s/size_%scm/study.csv"):format(dir, cm)), cm .. " cm: no study table\n" .. log)
end
local t = json.read(dir .. "/size_study.json")
assert(#t.rows == 2 and t.reference_size_m == 0.01, ("%d rows, reference %s"):format(#t.rows, tostring(t.reference_size_m)))
assert(t.rows[1].size_m == 0.008 and t.rows[2].size_m == 0.01, "rows ordered by size")
for _, r in ipairs(t.rows) do
  local study = json.read(("%s/size_%gcm/study.json"):format(dir, r.size_m * 100))
  assert(r.runs == 1 and r.peak_mpa == study.runs[1].peak_shear_stress_mpa, "the row is the run's peak")
  local expect = math.abs(r.peak_vs_largest) <= 0.2 and math.abs(r.residual_vs_largest) <= 0.2
  assert(r.representative == expect, ("%g m: representative %s, differences %.3f / %.3f"):format(
         r.size_m, tostring(r.representative), r.peak_vs_largest, r.residual_vs_largest))
end
local ref = t.rows[2]
assert(ref.peak_vs_largest == 0 and ref.residual_vs_largest == 0 and ref.representative, "the largest is its own reference")
local want = t.rows[1].representative and 0.008 or 0.01
assert(t.smallest_representative_m.rigid == want and t.default_size_m == want,
       ("verdict %s, default %s, want %g"):format(tostring(t.smallest_representative_m.rigid), tostring(t.default_size_m), want))
assert(read(dir .. "/size_study.png"), "no plot")
local first = read(dir .. "/size_study.csv")
assert(select(2, first:gsub("\n", "")) == 3, "size_study.csv: a header and two rows\n" .. first)

-- Rerun: nothing is run again, the same table.
status, log = run(args, out .. "/size2.log")
assert(status == 0 and not log:find("started S1", 1, true), "a rerun runs nothing:\n" .. log)
assert(read(dir .. "/size_study.csv") == first, "the rerun rebuilds the same table")
print("PASS")
