-- asperity.surface from Lua (spec surfaces.md): generation, files, analysis results as tables of
-- numbers and Arrays, and the steps from a synthetic surface to a DEM surface on particles of a
-- World (profilometer, mean plane, surface vs porosity particles, noise study).
-- Run with out=DIRECTORY. Prints PASS.
local out = assert(params.out, "give out=DIRECTORY")
asperity.mkdir(out)
local S = asperity.surface

local function near(a, b, tol, what)
  if not (math.abs(a - b) <= tol) then
    error(("%s: %.17g vs %.17g (tolerance %g)"):format(what, a, b, tol), 2)
  end
end

local function fails(pattern, f, ...)
  local ok, msg = pcall(f, ...)
  assert(not ok, "expected an error matching " .. pattern)
  assert(tostring(msg):find(pattern), "error '" .. tostring(msg) .. "' does not match " .. pattern)
end

-- Generation: by name and by parameters; one seed, one phase field.
local ref = S.reference("S5", {n = 129})
assert(ref.H == 0.52 and ref.Lc == 0.016 and ref.n == 129, "reference S5")
local s5 = S.generate{name = "S5", n = 129, seed = 4}
local same = S.generate{H = 0.52, Lc = 0.016, variance = 0.547e-6, n = 129, seed = 4}
local nx, ny = s5:size()
assert(nx == 129 and ny == 129, "size")
near(s5:spacing(), 0.1 / 129, 1e-18, "spacing")
local h = s5:heights()
local rows, cols = h:size()
assert(rows == 129 and cols == 129, "heights Array is ny x nx")
assert(h:get(3, 7) == s5:at(7, 3), "Array row = y index, column = x index")
local h2 = same:heights()
for k = 1, 129 do assert(h:get(k, k) == h2:get(k, k), "name and parameters give the same surface") end
near(s5:amplitude().variance, 0.547e-6, 1e-15, "variance exact")
assert(s5:params().name == "S5" and same:params().name == "", "params")
-- anisotropic
local an = S.generate{Hx = 0.8, Hy = 0.4, Lc = 0.016, variance = 1e-6, n = 129}
local sx, sy = an:structure_function("x"), an:structure_function("y")
assert(sx.value[1] < sy.value[1], "smoother (higher H) along x at the first lag")
assert(an:params().isotropic == false, "anisotropic params")

-- Analysis: numbers and Arrays.
local r = s5:analyze{directions = 4}
assert(math.abs(r.hurst_psd.hurst - 0.52) < 0.1, "H from the PSD: " .. r.hurst_psd.hurst)
assert(r.hurst_structure.points > 0 and r.hurst_psd.r2 > 0.9, "fits")
assert(#r.polar == 4 and r.polar[1].angle == 0, "polar data")
assert(#r.structure_radial.lag == #r.structure_radial.value, "lag series")
assert(getmetatable(r.psd_radial.psd).__name == "asperity.Array", "bulk results are Arrays")
assert(r.correlation_length > 0 and r.rolloff_length > 0, "lengths")
local g = s5:variogram("radial")
near(g.value[3], 0.5 * s5:structure_function().value[3], 1e-20, "variogram = S/2")
local row, step = s5:row(10)
local pr = S.analyze_profile(row, step)
assert(pr.amplitude.count == 129 and pr.psd.frequency[1] > 0, "profile analysis")
local fit = S.fit_power_law({1, 2, 4, 8}, {3, 12, 48, 192})
near(fit.slope, 2, 1e-12, "power-law fit")
assert(#s5:abbott(51).height == 51, "abbott levels")
assert(s5:slopes("x", 5).z2[1] > 0 and s5:colatitude(0).samples > 0, "slopes, colatitudes")

-- Files: HDF5 round trip with the parameters, CSV grid import, maps from Arrays.
s5:save(out .. "/s5.h5")
local back = S.load(out .. "/s5.h5")
assert(back:params().name == "S5" and back:params().seed == 4, "parameters read back")
local hb = back:heights()
for k = 1, 129, 16 do assert(hb:get(k, 130 - k) == h:get(k, 130 - k), "heights read back") end
s5:save_csv(out .. "/s5.csv")
local csv = S.load_grid(out .. "/s5.csv")
near(csv:at(5, 9), s5:at(5, 9), 1e-18, "CSV grid")
local fromarray = S.height_map{heights = h, spacing = s5:spacing()}
assert(fromarray:at(100, 2) == s5:at(100, 2) and fromarray:params() == nil, "height_map")
s5:plot(out .. "/s5.png", {title = "S5, n = 129"})
assert(io.open(out .. "/s5.png", "rb"):read(4):sub(2) == "PNG", "elevation map PNG")

-- Errors name what is wrong.
fails("unknown option 'Hurst'", S.generate, {Hurst = 0.5})
fails("S1 S2 S3 S4 S5 S6 S7 S8", S.generate, {name = "S9"})
fails("missing: Lc", S.generate, {H = 0.5})
fails("must be odd", S.generate, {name = "S1", n = 100})

-- From a synthetic surface to a DEM surface, on particles of a World: spheres of radius 0.45 h
-- on the nodes of a 65 x 65 S4, their tops on the synthetic surface shifted by dv, every 9th
-- deeper by 3 rms (seen through a hole of the packing: porosity).
local syn = S.generate{name = "S4", n = 65, seed = 2}
local n65 = 65
local sp = syn:spacing()
local R, dv, rms = 0.45 * sp, 0.2e-3, syn:amplitude().rms
local xyz, radii, tops, deep = asperity.array(n65 * n65, 3), asperity.array(n65 * n65), {}, {}
local id = 0
for j = 1, n65 do
  for i = 1, n65 do
    id = id + 1
    local hole = id % 9 == 0
    if hole then deep[#deep + 1] = id end
    local zc = syn:at(i, j) + dv - R - (hole and 3 * rms or 0)
    xyz[id] = {(i - 1) * sp, (j - 1) * sp, zc}
    radii[id] = R
    tops[id] = zc + R
  end
end
local w = asperity.world{}
w:add_particles(xyz, radii)
local prof = S.profilometer{positions = w:positions(), radii = w:radii(), grid = syn, side = "lower"}
assert(prof.covered == n65 * n65 and prof.particles == n65 * n65, "every node covered")
local dem = prof.surface:heights()
for k = 1, n65 * n65, 7 do
  local j, i = (k - 1) // n65 + 1, (k - 1) % n65 + 1
  assert(dem:get(j, i) == tops[k], "profilometer height exact at node " .. k)
  assert(prof.particle:get(j, i) == k, "profilometer particle id")
end
local up = S.profilometer{positions = w:positions(), radii = w:radii(), grid = syn, side = "upper",
                          origin = {0, 0}, ids = {1, 2, 3}}
assert(up.covered == 3 and up.surface:at(2, 1) == tops[2] - 2 * R, "upper side, subset")
local mp = S.mean_plane(prof, syn)
near(mp.shift, dv, 1e-6 * rms, "DEM mean plane shift")
near(mp.coinciding_fraction, 1 - #deep / (n65 * n65), 1e-12, "coinciding fraction")
local cls = S.classify(prof, syn, {band = rms})
assert(#cls.porosity == #deep, "porosity particles")
for k, v in ipairs(deep) do assert(cls.porosity[k] == v, "porosity id") end
near(cls.retained_fraction, 1 - #deep / (n65 * n65), 1e-12, "retained fraction")
assert(#S.classify(prof, syn).porosity == #deep, "default band (mean radius) and shift")

-- Noise study: H falls, s2 grows with the noise.
local study = S.noise_study(syn, {levels = {0, 0.3, 1}, seed = 5})
assert(#study == 3, "noise levels")
for k = 2, 3 do
  assert(study[k].hurst_psd < study[k - 1].hurst_psd, "H_psd falls with noise")
  assert(study[k].variance > study[k - 1].variance, "s2 grows with noise")
end

print("PASS")
