// Stage `walls`: ball-wall contacts (planes and triangle meshes) with the same contact law as
// ball-ball pairs (model.md 4), the wall in the role of body a: it translates with its prescribed
// velocity and does not spin. Plane contacts, as many as the particles along a box's faces and
// the same arithmetic for each, run through the SIMD plane kernel (kernels/wall_loop.hpp); mesh
// contacts here, scalar: their geometry branches per triangle feature (bodies/mesh.hpp).
#include <algorithm>
#include <cmath>
#include <memory>

#include "bodies/mesh.hpp"
#include "kernels/contact_law.hpp"
#include "stages/walls.hpp"

namespace asperity::detail {

// Declared in bodies/mesh.hpp with the other mesh geometry, defined here beside the wall stage
// that calls it for every mesh contact: with its body in this unit the compiler knows what it
// reads, writes and which registers it uses, and keeps the stage's values in registers across
// those calls.
Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c,
                               int& feature) {
  // Voronoi regions of the triangle's features, tested in turn (barycentric reasoning).
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) { feature = 1; return a; }
  const Vec3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) { feature = 2; return b; }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) { feature = 4; return a + ab * (d1 / (d1 - d3)); }
  const Vec3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) { feature = 3; return c; }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) { feature = 6; return a + ac * (d2 / (d2 - d6)); }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    feature = 5;
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  }
  feature = 0;
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

namespace {
// Feature code -> ownership bit (see Mesh::owns).
constexpr std::uint8_t kFeatureBit[7] = {0, 1 << 3, 1 << 4, 1 << 5, 1 << 0, 1 << 1, 1 << 2};

// Whether a contact whose closest point lies on an edge or a vertex of triangle t is a real
// contact: it is the shadow of another one when a triangle sharing that edge or vertex comes
// closer to the sphere (a sphere over a flat mesh touches one face; the neighbouring triangles'
// edges are also within reach but are not contacts). Among equally close triangles (a convex
// ridge or peak, where they all share the closest point) the owner of the feature counts it once.
bool mesh_feature_contact_is_real(const Mesh& mesh, int t, int feature, const Vec3& q, double d) {
  if (!(mesh.owns[t] & kFeatureBit[feature])) {
    // Not the owner: the owner (or a closer triangle) accounts for it.
    return false;
  }
  const auto& tri = mesh.triangles[t];
  int va, vb = -1;  // the vertex, or the two vertices of the edge
  if (feature <= 3) {
    va = tri[feature - 1];
  } else {
    va = tri[feature - 4];
    vb = tri[(feature - 3) % 3];
  }
  const double limit = d * (1 - 1e-9), tie = d * (1 + 1e-9);
  // Whether triangle o, which shares the feature, takes the contact from t.
  auto takes_it = [&](std::int32_t o) {
    const auto& ot = mesh.triangles[o];
    int f;
    const Vec3 cp = closest_point_on_triangle(q, mesh.vertices[ot[0]], mesh.vertices[ot[1]],
                                              mesh.vertices[ot[2]], f);
    const double od = norm(q - cp);
    // Equally close, and its face holds the closest point: the sphere is over the flat join of
    // two triangles, a hair past the edge (its distance to the edge and to the face agree to
    // ~1e-11 within 1e-8 m of the edge line). The face counts the contact, so the edge must not:
    // both did, and a sphere sliding over a flat mesh got twice its normal force for a step.
    return od < limit || (f == 0 && od <= tie);
  };
  // An edge shared by one other triangle (Mesh::edge_neighbour): that one alone, without walking
  // the triangles around the vertex (the same set, so the same answer).
  if (vb >= 0 && !mesh.edge_neighbour.empty()) {
    const std::int32_t across = mesh.edge_neighbour[3 * std::size_t(t) + std::size_t(feature - 4)];
    if (across == -1) return true;
    if (across >= 0) return !takes_it(across);
  }
  for (std::int32_t k = mesh.vertex_start[va]; k < mesh.vertex_start[va + 1]; ++k) {
    const std::int32_t o = mesh.vertex_triangles[k];
    if (o == t) continue;
    if (vb >= 0 && !holds_vertex(mesh.triangles[o], vb)) continue;  // does not share the edge
    if (takes_it(o)) return false;
  }
  return true;
}
}  // namespace

// Candidates ahead of the one evaluated whose mesh data the wall stage prefetches (meshes past the
// caches, Mesh::past_caches): far enough ahead that the lines arrive before they are read, near
// enough that they are not evicted again first; the distance is a trial's best, not derived.
constexpr std::size_t kWallAhead = 32;

StageLoop wall_stage(const WallStageView& s) {
  const std::size_t nw = s.walls.walls.size();
  WallContacts& wc = s.walls.contacts;
  wc.slip.resize(wc.n);  // an output only: a store read from a checkpoint has not sized it
  StageLoop st;
  st.blocks = (wc.n + kParticleBlock - 1) / kParticleBlock;
  // Per block: slip energy, boundary work, and the force on each wall. Per wall: the columns the
  // plane kernel reads (its current point, normal, velocity and material) and its kind.
  struct Sums {
    std::vector<double> slip, work;
    std::vector<Vec3> force;
    std::vector<double> px, py, pz, nx, ny, nz, vx, vy, vz, kn, ks, friction;
    std::vector<double> moved;  // how far each wall has moved since the neighbour build
    std::vector<std::uint8_t> plane;
    std::vector<std::uint8_t> prefetch;  // a mesh past the caches (Mesh::past_caches)
  };
  auto sums = std::make_shared<Sums>();
  sums->slip.assign(st.blocks, 0.0);
  sums->work.assign(st.blocks, 0.0);
  sums->force.assign(st.blocks * nw, Vec3{});
  // The wall columns, only when there are contacts to read them: a joint removes its walls after
  // packing (they stay listed), and its closure and shear then build no table per step.
  if (wc.n > 0) {
    Sums& t = *sums;
    for (auto* c : {&t.px, &t.py, &t.pz, &t.nx, &t.ny, &t.nz, &t.vx, &t.vy, &t.vz, &t.kn, &t.ks,
                    &t.friction})
      c->reserve(nw);
    t.plane.reserve(nw);
    t.prefetch.reserve(nw);
    t.moved.reserve(nw);
    for (const Wall& w : s.walls.walls) {
      const Vec3 point = w.point + w.displacement;
      t.px.push_back(point.x); t.py.push_back(point.y); t.pz.push_back(point.z);
      t.nx.push_back(w.normal.x); t.ny.push_back(w.normal.y); t.nz.push_back(w.normal.z);
      t.vx.push_back(w.velocity.x); t.vy.push_back(w.velocity.y); t.vz.push_back(w.velocity.z);
      t.kn.push_back(w.material.kn); t.ks.push_back(w.material.ks);
      t.friction.push_back(w.material.friction);
      t.plane.push_back(w.kind == Wall::Kind::plane ? 1 : 0);
      t.prefetch.push_back(w.kind == Wall::Kind::mesh && !w.removed && s.walls.meshes[w.mesh].past_caches());
      t.moved.push_back(norm(w.displacement - w.displacement_at_build));
    }
    // Readable to kMaxLanes entries for the kernel's lane permutations (PlaneWallArgs::walls).
    for (auto* c : {&t.px, &t.py, &t.pz, &t.nx, &t.ny, &t.nz, &t.vx, &t.vy, &t.vz, &t.kn, &t.ks,
                    &t.friction})
      c->resize(std::max(nw, kMaxLanes), 0.0);
  }
  const ParticleStore& p = s.p;
  const kernels::PlaneWallArgs plane_args{
      p.x.data(), p.y.data(), p.z.data(), p.vx.data(), p.vy.data(), p.vz.data(), p.wx.data(),
      p.wy.data(), p.wz.data(), p.radius.data(), wc.particle.data(), wc.wall.data(),
      wc.nx.data(), wc.ny.data(), wc.nz.data(), wc.fsx.data(), wc.fsy.data(), wc.fsz.data(),
      wc.fn.data(), wc.overlap.data(), wc.slip.data(), sums->px.data(), sums->py.data(),
      sums->pz.data(), sums->nx.data(), sums->ny.data(), sums->nz.data(), sums->vx.data(),
      sums->vy.data(), sums->vz.data(), sums->kn.data(), sums->ks.data(),
      sums->friction.data(), s.dt, nw};
  const bool rot = s.any_rotating;
  const auto plane_kernel = rot ? s.ctx.kernels->plane_walls : s.ctx.kernels->plane_walls_norot;
  const auto plane_tail = rot ? kernels::scalar_kernels().plane_walls
                              : kernels::scalar_kernels().plane_walls_norot;
  const std::size_t lanes = s.ctx.kernels->lanes;
  const bool any_prefetch = std::find(sums->prefetch.begin(), sums->prefetch.end(), 1) != sums->prefetch.end();
  st.run = [s, nw, sums, plane_args, plane_kernel, plane_tail, lanes, rot, any_prefetch](std::size_t blk) {
    const ParticleStore& p = s.p;
    WallContacts& wc = s.walls.contacts;
    const auto& walls = s.walls.walls;
    const double dt = s.dt;
    const std::uint8_t* plane = sums->plane.data();
    const std::uint8_t* prefetch = sums->prefetch.data();
    double* slip = sums->slip.data();
    double* work = sums->work.data();
    Vec3* force = sums->force.data();
    const std::size_t first = blk * kParticleBlock;
    const std::size_t end = std::min(wc.n, first + kParticleBlock);
    // The plane contacts, run by run: whole batches in SIMD, the rest by the scalar reference
    // (the same values either way).
    for (std::size_t k = first; k < end;) {
      if (!plane[wc.wall[k]]) {
        ++k;
        continue;
      }
      std::size_t e = k;
      while (e < end && plane[wc.wall[e]]) ++e;
      const std::size_t whole = k + (e - k) / lanes * lanes;
      plane_kernel(plane_args, k, whole);
      plane_tail(plane_args, whole, e);
      k = e;
    }
    // A mesh candidate untouched when last evaluated holds the zero outputs of a contact that
    // does not touch; it cannot touch now while its distance at the build, less how far the
    // particle and the wall have moved since, exceeds the radius (triangle inequality; the margin
    // covers the rounding of the three terms). Then nothing is computed: the law would write the
    // same zeros, and the normal it would refresh is read only to carry a zero shear force (signs
    // of zeros at most). A particle near the mould has ~40 candidates and touches one to three.
    const bool bounds = wc.distance.size() == wc.n;
    std::int32_t moved_of = -1;  // the particle whose displacement since the build is in `moved`
    double moved = 0;
    // Past the caches, a mesh candidate evaluated at the last step (touching, or the shadow of a
    // contact another triangle owns: most of those evaluated now) has its triangle fetched
    // 2 * kWallAhead candidates ahead and its vertices kWallAhead ahead, as the chain facet ->
    // triangle -> vertices otherwise waits on memory at each link (Mesh::past_caches).
    auto evaluated_last = [&](std::size_t a) {
      return prefetch[wc.wall[a]] && (wc.overlap[a] > 0 || wc.overlap[a] == -1.0);
    };
    // The sums in contact order, and the mesh contacts.
    for (std::size_t k = first; k < end; ++k) {
      if (any_prefetch) {
        if (k + 2 * kWallAhead < end && evaluated_last(k + 2 * kWallAhead)) {
          const Mesh& m = s.walls.meshes[walls[wc.wall[k + 2 * kWallAhead]].mesh];
          __builtin_prefetch(&m.triangles[wc.facet[k + 2 * kWallAhead]]);
        }
        if (k + kWallAhead < end && evaluated_last(k + kWallAhead)) {
          const Mesh& m = s.walls.meshes[walls[wc.wall[k + kWallAhead]].mesh];
          for (const int v : m.triangles[wc.facet[k + kWallAhead]]) __builtin_prefetch(&m.vertices[v]);
        }
      }
      const Wall& wall = walls[wc.wall[k]];
      if (plane[wc.wall[k]]) {
        if (!(wc.overlap[k] > 0)) continue;  // no contact: no force
        slip[blk] += wc.slip[k];
        const double fn = wc.fn[k];
        const Vec3 f{fn * wc.nx[k] + wc.fsx[k], fn * wc.ny[k] + wc.fsy[k], fn * wc.nz[k] + wc.fsz[k]};
        force[blk * nw + wc.wall[k]] -= f;
        work[blk] += dot(f, wall.velocity) * dt;  // model.md 8: boundary work of the wall
        continue;
      }
      const std::int32_t i = wc.particle[k];
      if (bounds && !(wc.overlap[k] > 0)) {
        if (moved_of != i) {
          const double dx = p.x[i] - p.x0[i], dy = p.y[i] - p.y0[i], dz = p.z[i] - p.z0[i];
          moved = std::sqrt(dx * dx + dy * dy + dz * dz);
          moved_of = i;
        }
        const double clearance = wc.distance[k] - moved - sums->moved[wc.wall[k]];
        if (clearance > p.radius[i] * (1 + 1e-9)) continue;
      }
      const Vec3 c{p.x[i], p.y[i], p.z[i]};
      const Mesh& mesh = s.walls.meshes[wall.mesh];
      const auto& tri = mesh.triangles[wc.facet[k]];
      int feature;
      const Vec3 q = c - wall.displacement;
      const Vec3 cp = closest_point_on_triangle(q, mesh.vertices[tri[0]], mesh.vertices[tri[1]],
                                                mesh.vertices[tri[2]], feature);
      const Vec3 dv = q - cp;
      const double d = norm(dv);
      const Vec3 n = d > 0 ? dv / d : Vec3{0, 0, 1};
      const double U = p.radius[i] - d;
      // Only a touching triangle needs the (costly) test of whether a neighbour owns the contact.
      const bool active =
          !(U > 0) || feature == 0 || mesh_feature_contact_is_real(mesh, wc.facet[k], feature, q, d);
      if (!(U > 0) || !active) {
        // No contact: the law would give no force and forget the shear history [model.md 4]
        // (exactly: every output is selected to zero), so skip it. A particle near a mesh has
        // tens of candidate triangles within the skin and touches one to three of them.
        wc.nx[k] = n.x; wc.ny[k] = n.y; wc.nz[k] = n.z;
        wc.fsx[k] = wc.fsy[k] = wc.fsz[k] = 0;
        wc.fn[k] = 0;
        wc.overlap[k] = active ? U : -1.0;
        continue;
      }
      Vec3 o{wc.nx[k], wc.ny[k], wc.nz[k]};
      if (dot(o, o) == 0) o = n;
      double fx = wc.fsx[k], fy = wc.fsy[k], fz = wc.fsz[k], fn;
      const double lb = p.radius[i] - 0.5 * U;
      const double wx = rot ? p.wx[i] : 0.0, wy = rot ? p.wy[i] : 0.0, wz = rot ? p.wz[i] : 0.0;
      const kernels::LawParams<double> law{wall.material.kn, wall.material.ks,
                                           wall.material.friction, dt};
      slip[blk] += kernels::contact_forces(n.x, n.y, n.z, U, 0.0, lb, wall.velocity.x,
                                           wall.velocity.y, wall.velocity.z, 0.0, 0.0, 0.0,
                                           p.vx[i], p.vy[i], p.vz[i], wx, wy, wz, o.x, o.y, o.z,
                                           0.0, fx, fy, fz, fn, law);
      wc.nx[k] = n.x; wc.ny[k] = n.y; wc.nz[k] = n.z;
      wc.fsx[k] = fx; wc.fsy[k] = fy; wc.fsz[k] = fz;
      wc.fn[k] = fn;
      wc.overlap[k] = U;
      const Vec3 f{fn * n.x + fx, fn * n.y + fy, fn * n.z + fz};  // on the particle
      force[blk * nw + wc.wall[k]] -= f;
      work[blk] += dot(f, wall.velocity) * dt;  // model.md 8: boundary work of the wall
    }
  };
  st.finish = [&walls = s.walls.walls, ledger = s.ledger, nw, sums, blocks = st.blocks] {
    for (auto& w : walls) w.force = {0, 0, 0};
    for (std::size_t blk = 0; blk < blocks; ++blk) {
      for (std::size_t w = 0; w < nw; ++w) walls[w].force += sums->force[blk * nw + w];
      if (ledger) {
        ledger->friction += sums->slip[blk];
        ledger->boundary += sums->work[blk];
      }
    }
  };
  return st;
}

}  // namespace asperity::detail
