# The bonded benchmark scene of perf/bonded.lua, for YADE (perf/peers.sh SCENE=bonded):
#
#   yade -n -x -j2 perf/bonded_yade.py 40 1000     # n, timed steps [dt=5e-4] [strain=5e-4] [warmup=200]
#
# n^3 spheres R = 0.5 mm on a simple cubic lattice of spacing 2 R (touching, no overlap), every
# face-neighbour pair bonded by a cohesive contact (CohFrictMat, CohFrictPhys, the CohesionMoment
# law); no rotation (blocked for every sphere: asperity locks bonded particles), local damping 0.7,
# no gravity. The bottom layer is fixed, the top layer moves down at the velocity that brings it
# `strain` of the block's height down at the end of the warm-up + timed steps. dt fixed.
#
# asperity's REV material (scripts/lib/materials.lua) on YADE's one spring per contact (for two
# spheres of one material and radius R, YADE takes kn = young R and ks = poisson kn); asperity's
# beam_kn, beam_ks are the parallel bond's stiffnesses times its area A = pi R^2:
#   kn = contact kn + beam_kn          -> young = (kn + beam_kn) / R
#   ks = contact ks + beam_ks          -> poisson = (ks + beam_ks) / (kn + beam_kn)
#   tension breaks when asperity's beam (beam_kn / (kn + beam_kn) of the normal force) carries
#   st A:  normalAdhesion = normalCohesion R^2 = st A (kn + beam_kn) / beam_kn
#   shear breaks when the beam carries tau = 5 st:
#          shearAdhesion = shearCohesion R^2 = 5 st A (ks + beam_ks) / beam_ks
#   (YADE adds Fn tan(phi) to the shear limit; asperity's ellipse widens under compression too).
# No bond breaks in this loading in either engine: the bond counts stay equal.
import sys, time, math

# (names chosen not to shadow the yade launcher's globals, e.g. `opts`, which the script shares)
positional = [s for s in sys.argv[1:] if '=' not in s]
settings = dict(s.split('=', 1) for s in sys.argv[1:] if '=' in s)
n = int(positional[0]) if len(positional) > 0 else 40
steps = int(positional[1]) if len(positional) > 1 else 1000
dt = float(settings.get('dt', 5e-4))
strain = float(settings.get('strain', 5e-4))
warmup = int(settings.get('warmup', 200))

# asperity's REV material (scripts/lib/materials.lua: M.contact, M.damping, M.density, M.bond())
kn, ks, mu, damping, density = 0.1, 0.01, 0.5, 0.7, 2500.0
beam_kn, beam_ks, st = kn, 0.3 * kn, 0.031364
R = 0.5e-3
a = 2 * R
H = (n - 1) * a
v = strain * H / ((warmup + steps) * dt)

mat = O.materials.append(CohFrictMat(
    young=(kn + beam_kn) / R, poisson=(ks + beam_ks) / (kn + beam_kn), frictionAngle=math.atan(mu),
    density=density, isCohesive=True, fragile=True, momentRotationLaw=False,
    normalCohesion=math.pi * st * (kn + beam_kn) / beam_kn,
    shearCohesion=5 * math.pi * st * (ks + beam_ks) / beam_ks))

# x fastest, as perf/bonded.lua: ids 0 .. n^2-1 are the bottom layer, the last n^2 the top one.
# Masks: bottom 0b011, top 0b101, the others 0b001; the collider skips pairs of one mask sharing a
# bit with 0b110, i.e. pairs inside a boundary layer (asperity leaves bonds inside a rigid group out).
for k in range(n):
    for j in range(n):
        for i in range(n):
            b = sphere(((i + 0.5) * a, (j + 0.5) * a, (k + 0.5) * a), R, material=mat)
            if k == 0 or k == n - 1:
                b.state.blockedDOFs = 'xyzXYZ'
                b.mask = 0b011 if k == 0 else 0b101
            else:
                b.state.blockedDOFs = 'XYZ'
                b.mask = 0b001
            O.bodies.append(b)
top = range(n * n * (n - 1), n ** 3)
for i in top:
    O.bodies[i].state.vel = Vector3(0, 0, -v)

detect = 1.001   # find the touching pairs (centre distance 2 R up to rounding) on the first step
bo1 = Bo1_Sphere_Aabb(aabbEnlargeFactor=detect)
ig2 = Ig2_Sphere_Sphere_ScGeom6D(interactionDetectionFactor=detect, updateRotations=False)
O.engines = [
    ForceResetter(),
    InsertionSortCollider([bo1], verletDist=0.05 * a, avoidSelfInteractionMask=0b110),
    InteractionLoop([ig2],
                    [Ip2_CohFrictMat_CohFrictMat_CohFrictPhys(setCohesionNow=True, setCohesionOnNewContacts=False)],
                    [Law2_ScGeom6D_CohFrictPhys_CohesionMoment()]),
    NewtonIntegrator(damping=damping),
]
O.dt = dt


def bonds():
    return sum(1 for i in O.interactions if i.isReal and not i.phys.cohesionBroken)


O.run(1, True)                      # the bonds are made on this step
bo1.aabbEnlargeFactor = ig2.interactionDetectionFactor = 1.0
bonds0 = bonds()
i0 = next(i for i in O.interactions if i.isReal)
print("YADE bonded n=%d: %d particles, %d bonds (the %d inside the two boundary layers left out), "
      "dt %.4g s (P-wave estimate %.4g s), top velocity %.4g m/s; kn %.4g ks %.4g N/m, "
      "normalAdhesion %.4g shearAdhesion %.4g N; threads %d"
      % (n, len(O.bodies), bonds0, 4 * n * (n - 1), O.dt, PWaveTimeStep(), v,
         i0.phys.kn, i0.phys.ks, i0.phys.normalAdhesion, i0.phys.shearAdhesion, O.numThreads))
if warmup > 1:
    O.run(warmup - 1, True)     # the first step counts as warm-up
print("after %d warm-up steps: %d bonds, %d interactions"
      % (max(warmup, 1), bonds(), sum(1 for i in O.interactions if i.isReal)))
t = time.time()
O.run(steps, True)
el = time.time() - t
moved = (n - 0.5) * a - O.bodies[n * n * (n - 1)].state.pos[2]
m = n // 2
mid = O.bodies[m * n * n + m * n + m].state.pos[2] - (m + 0.5) * a   # the particle at the centre
print("timed: %d steps in %.4f s (%.2f ns/particle-step)" % (steps, el, 1e9 * el / (n ** 3 * steps)))
print("end: top layer moved %.4g m (strain %.3g), middle particle dz %.4g m" % (moved, moved / H, mid))
print("bonds in the step: %d at the start, %d at the end" % (bonds0, bonds()))
print("particle-steps/s: %.6g" % (n ** 3 * steps / el))
