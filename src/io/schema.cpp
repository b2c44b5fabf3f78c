#include "io/schema.hpp"

#include <algorithm>

namespace shroudsim::io {

const std::vector<std::pair<std::string, std::string>>& case_sections() {
  static const std::vector<std::pair<std::string, std::string>> s = {
      {"", ""},
      {"structure", "what is analysed: an FE sector of a bladed disk, or a small lumped model"},
      {"geometry", "built-in shrouded blade sector generator (metres, degrees); used when structure.mesh is empty"},
      {"material", "isotropic linear elastic material (SI)"},
      {"modal", "cyclic-symmetry modal analysis"},
      {"campbell", "Campbell diagram"},
      {"static", "only for `shroudsim static`: the shroud contact of the spinning sector (interference, friction)"},
      {"excitation", "travelling-wave excitation"},
      {"response", "where the response amplitude is reported"},
      {"contact", "shroud friction contact"},
      {"hbm", "multiharmonic balance with the alternating frequency-time scheme"},
      {"continuation", "pseudo-arclength continuation over the excitation frequency"},
      {"motion", "only for `shroudsim contact`: prescribed relative motion, rows [harmonic, cosine, sine] in m"},
      {"study", "only for `shroudsim study`: parameter sweeps"},
      {"expect", "optional regression expectations (free keys, numbers), checked by the regression tests"},
  };
  return s;
}

const std::vector<KeySpec>& case_schema() {
  static const std::vector<KeySpec> s = {
      {"name", "\"shrouded_blade\"", "non-empty; letters, digits, _ - .", "result folder name (results/<name>) and mesh name (meshes/<name>.msh)"},

      {"structure.type", "\"sector\"", "\"sector\" | \"lumped\"", "FE sector (default) or lumped M, K, C matrices"},
      {"structure.sectors", "8", "2 <= sectors <= 1000 (lumped: >= 1)", "Nb, number of sectors of the wheel"},
      {"structure.mesh", "\"\"", "path (relative to the case file) or \"\"", "an existing .msh sector mesh with groups hub, cyclic_low/high, shroud_low/high; \"\" = generate from [geometry]"},
      {"structure.mass", "[]", "n x n, symmetric, positive definite (lumped only)", "lumped mass matrix (kg)"},
      {"structure.stiffness", "[]", "n x n, symmetric, positive semi-definite (lumped only)", "lumped stiffness matrix (N/m)"},
      {"structure.damping", "[]", "n x n or [] (lumped only)", "lumped viscous damping matrix (N s/m)"},

      {"geometry.hub_radius", "0.10", "> 0", "bore radius, clamped (m)"},
      {"geometry.disk_outer_radius", "0.16", "> hub_radius", "disk rim radius where the blade stands (m)"},
      {"geometry.disk_thickness", "0.03", "> 0", "axial thickness of the disk (m)"},
      {"geometry.blade_length", "0.25", "> 0", "radial length of the blade from rim to shroud (m)"},
      {"geometry.blade_chord", "0.05", "> 0", "blade chord (m)"},
      {"geometry.blade_thickness", "0.006", "> 0, < blade_chord", "blade thickness (m)"},
      {"geometry.blade_twist_deg", "20.0", "-60 <= twist <= 60", "blade twist from root to tip (deg)"},
      {"geometry.shroud_thickness", "0.006", "> 0", "radial thickness of the tip shroud (m)"},
      {"geometry.shroud_width", "0.05", "> 0", "axial width of the tip shroud (m)"},
      {"geometry.shroud_contact_angle_deg", "45.0", "0 <= angle < 90 (and faces must not cross)", "contact face angle to the radial plane (deg)"},
      {"geometry.element_order", "2", "1 | 2", "1 = 4-node, 2 = 10-node tetrahedra"},
      {"geometry.mesh_size", "0.01", "> 0, <= smallest feature", "target element size (m)"},
      {"geometry.max_elements", "1.0e6", "> 0", "largest estimated element count meshed (volume / (0.04 mesh_size^3), which overestimates gmsh's count by up to 2x); a finer mesh_size is refused before meshing unless this is raised"},

      {"material.youngs_modulus", "210e9", "> 0", "Young's modulus (Pa)"},
      {"material.poisson_ratio", "0.3", "-1 < nu < 0.5", "Poisson's ratio"},
      {"material.density", "7850.0", "> 0", "density (kg/m^3)"},

      {"modal.modes", "50", "1 <= modes <= 2000", "modes kept per harmonic index"},
      {"modal.harmonic_indices", "\"all\"", "\"all\" or a list of 0 <= h < sectors", "harmonic indices of the nodal diameter map"},
      {"modal.damping_ratio", "0.001", "0 <= ratio < 1", "modal damping ratio of every mode"},
      {"modal.residual_flexibility", "true", "true | false", "add the static flexibility of the truncated modes"},
      {"modal.shroud", "\"open\"", "\"open\" | \"stuck\" | \"contact\"", "shroud contact of `modes` and `campbell`: open (blades coupled through the disk only), stuck (every matched shroud pair tied by contact.normal_stiffness and tangential_stiffness, shared by tributary area, in its contact frame) or contact (the pairs the static shroud contact closes, with contact.interference, tied; at each speed of a Campbell diagram with rotating effects); the forced response always starts from the open sector"},
      {"modal.eigensolver", "\"block\"", "\"block\" | \"spectra\"", "block Krylov-Schur (default, faster) or Spectra's Lanczos (2n embedding for complex h)"},

      {"campbell.speed_rpm", "[0.0, 15000.0]", "[min, max], 0 <= min < max", "speed range (rpm)"},
      {"campbell.speed_points", "31", "2 <= points <= 10000", "speeds in the range"},
      {"campbell.engine_orders", "[1, 2, 3, 4, 5, 6]", "list of integers >= 1", "engine-order lines drawn and crossed"},
      {"campbell.rotating_effects", "false", "true | false", "centrifugal stiffening and spin softening"},

      {"static.speed_rpm", "0.0", ">= 0", "rotor speed of the static shroud contact (rpm)"},
      {"static.increments", "10", "1 <= increments <= 1000", "equal steps of speed^2 from rest to static.speed_rpm (the friction state is carried from step to step)"},

      {"excitation.engine_order", "1", ">= 0", "engine order m: harmonic n lives in harmonic index n*m mod Nb"},
      {"excitation.point", "[0.0, 0.35, 0.0]", "3 numbers (m)", "sector: the force acts at the nearest node"},
      {"excitation.force", "[1.0, 1.0, 1.0]", "3 numbers (N, global x y z); lumped: one number", "force amplitude"},
      {"excitation.dof", "0", "0 <= dof < n (lumped only)", "lumped: the excited DOF"},
      {"excitation.speed_rpm", "0.0", ">= 0", "rotor speed of the forced response (rpm); > 0 uses the modes with centrifugal stiffening and spin softening at that speed"},

      {"response.point", "[0.0, 0.34, 0.0]", "3 numbers (m)", "sector: the response is read at the nearest node"},
      {"response.dof", "0", "0 <= dof < n (lumped only)", "lumped: the response DOF"},

      {"contact.model", "\"full3d\"", "\"full3d\" | \"quasi3d\" | \"1d\" | \"1d_exact\"", "friction contact model"},
      {"contact.pairs", "\"all\"", "\"all\" or a count >= 1", "contact elements on the shroud face: the face split into this many patches (seeds spread evenly, each node to its nearest seed)"},
      {"contact.discretization", "\"patches\"", "\"patches\" | \"nodes\"", "sector: patches = each element acts on its patch's area-weighted mean relative displacement (converges under mesh refinement); nodes = on the patch's seed node pair alone (the paper's model)"},
      {"contact.friction_coefficient", "0.3", ">= 0", "Coulomb friction coefficient mu"},
      {"contact.normal_stiffness", "1.0e6", "> 0", "normal contact stiffness per interface (N/m), shared over pairs by tributary area"},
      {"contact.tangential_stiffness", "1.0e6", "> 0", "tangential contact stiffness per interface (N/m)"},
      {"contact.normal_preload", "0.25", "any; < 0 means an initial gap -N0/kn; or \"static\" (sector)", "normal preload per interface (N); \"static\": each contact patch's normal load (or gap) from the static shroud contact at excitation.speed_rpm (contact.interference, `shroudsim static`)"},
      {"contact.interference", "0.0", "any (m); < 0: a gap", "sector: overlap of the shroud faces at rest, uniform over the face (m), for the static shroud contact (`static`)"},
      {"contact.frame_angle_deg", "0.0", "any", "turns the tangential axes t1, t2 about the normal (deg)"},
      {"contact.tangential_update", "\"exact_linear\"", "\"exact_linear\" | \"radial_return\"", "time integration of the coupled tangential law"},
      {"contact.elements", "[]", "array of tables (lumped only)", "lumped contact elements: x_dof, y_dof, z_dof, other_x_dof, ... and per-element overrides"},

      {"hbm.harmonics", "5", "1 <= H <= 200, or \"auto\"", "H: harmonics 0..H"},
      {"hbm.time_samples", "512", "N >= 2H+1, <= 65536, or \"auto\"", "N: time samples per period"},
      {"hbm.jacobian", "\"analytic\"", "\"analytic\" | \"finite_difference\" | \"finite_difference_full\"", "Jacobian of the contact forces (finite_difference: per pair; _full: the whole force vector, for comparison only)"},
      {"hbm.tolerance", "1e-8", "0 < tol < 1", "Newton tolerance on the scaled residual"},
      {"hbm.energy_tolerance", "0.001", "0 < tol <= 1", "largest energy-balance error (|excitation work - dissipation| per cycle, relative) of a point before the run counts as failed numerics (exit 3)"},
      {"hbm.auto_tolerance", "0.01", "0 < tol < 1", "\"auto\" H or N: stop when the peak amplitude changes by less (relative)"},
      {"hbm.auto_max_harmonics", "25", "1 <= H <= 200", "\"auto\" harmonics: largest H tried"},
      {"hbm.auto_max_time_samples", "4096", "16 <= N <= 65536", "\"auto\" time samples: largest N tried"},

      {"continuation.frequency_start_hz", "100.0", "> 0", "start of the frequency range (Hz)"},
      {"continuation.frequency_end_hz", "220.0", "> 0, != start", "end of the frequency range (Hz)"},
      {"continuation.initial_step", "\"auto\"", "> 0 or \"auto\"", "initial arclength step: \"auto\" (1/400 of the range) or Hz-equivalent; never above 1/200 of the range"},
      {"continuation.max_points", "5000", "1 <= points <= 1000000", "maximum number of solution points"},

      {"motion.x", "[[1, 1e-5, 0.0]]", "rows [harmonic >= 0, cos, sin]", "relative tangential motion x(t) (m)"},
      {"motion.y", "[]", "rows [harmonic >= 0, cos, sin]", "relative tangential motion y(t) (m)"},
      {"motion.z", "[]", "rows [harmonic >= 0, cos, sin]", "relative normal motion z(t) (m), > 0 presses"},

      {"study.vary", "{}", "{ \"dotted.key\" = [values] }", "each key's values; the points are the Cartesian product"},
  };
  return s;
}

const KeySpec* find_key(const std::string& key) {
  const auto& s = case_schema();
  auto it = std::find_if(s.begin(), s.end(), [&](const KeySpec& k) { return k.key == key; });
  return it == s.end() ? nullptr : &*it;
}

}  // namespace shroudsim::io
