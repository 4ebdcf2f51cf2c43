// The materials of contacts and bonds (model.md 4, 5): part of the public API (WorldSettings,
// World), and all that the engine's bond and wall stores need of it.
#pragma once

namespace asperity {

// Contact springs and friction (model.md 4). Source values: kn = 0.1 N/m, ks = kn/10, mu = 0.5.
struct ContactMaterial {
  double kn = 0.1;         // normal stiffness, N/m
  double ks = 0.01;        // shear stiffness, N/m
  double friction = 0.5;   // Coulomb coefficient mu
};

// Contact bond + parallel bond installed together (model.md 5). The beam of radius
// Rb = radius_factor * min(Ra, Rb) acts as springs of stiffness kbn A = beam_kn and kbs A = beam_ks
// (defaults: as stiff as the contact springs, kbs = kbn / 10).
struct BondMaterial {
  double beam_kn = 0.1;            // kbn * A, N/m
  double beam_ks = 0.01;           // kbs * A, N/m
  double radius_factor = 1.0;      // lambda
  double tensile_strength = 0.0;   // st, Pa (elliptic criterion [3-46..3-49])
  bool breakable = true;           // false: the elastic model (bonds never break)
};

}  // namespace asperity
