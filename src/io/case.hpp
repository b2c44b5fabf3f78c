#pragma once
// The case file (docs/contract.md), parsed and validated: plain data handed to app/,
// which maps it onto each stage's own *Options. Every key is declared once, in schema.cpp:
// its default (set by Case's constructor), its checks, its documentation
// (`shroudsim --print-defaults`, docs/case_keys.md). Units: SI, angles in degrees,
// frequencies in Hz, speeds in rpm, as in the case file. Keys with one of a few words as
// value are enums here (the stages' own where a stage has one); to_string gives the word.
#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "contact/contact_law.hpp"
#include "frf/contact_patches.hpp"
#include "hbm/contact_evaluator.hpp"
#include "mesh/sector_generator.hpp"
#include "modal/eigensolver.hpp"

namespace shroudsim::io {

/// structure.type
enum class StructureType { sector, lumped };
/// modal.shroud: the shroud contact of `modes` and `campbell` (docs/physics.md sections 1, 8).
enum class ModalShroud { open, stuck, contact };
/// response.stability_method: how frf judges the stability of its points (docs/physics.md
/// section 9): automatic = shooting for a lumped model with friction, Hill's method otherwise.
enum class StabilityMethod { automatic, hill, shooting };
std::string to_string(StructureType type);      ///< "sector", "lumped"
std::string to_string(ModalShroud shroud);      ///< "open", "stuck", "contact"
std::string to_string(StabilityMethod method);  ///< "auto", "hill", "shooting"

// The members below get their defaults from the schema (Case's constructor), not here.

struct StructureSection {
  StructureType type;                        ///< FE sector or lumped M, K, C
  int sectors;                               ///< Nb >= 1
  std::filesystem::path mesh;                ///< absolute path of a given mesh, empty: generate
  Eigen::MatrixXd mass, stiffness, damping;  ///< lumped only, n x n (damping may be empty)
};

struct GeometrySection {
  double hub_radius;
  double disk_outer_radius;
  double disk_thickness;
  double blade_length;
  double blade_chord;
  double blade_thickness;
  double blade_twist_deg;
  double shroud_thickness;
  double shroud_width;
  double shroud_contact_angle_deg;
  int element_order;
  double mesh_size;
  double max_elements;  ///< refuse to mesh when the estimated element count is larger
};

struct MaterialSection {
  double youngs_modulus;
  double poisson_ratio;
  double density;
};

struct ModalSection {
  int modes;
  bool all_harmonic_indices;          ///< harmonic_indices = "all"
  std::vector<int> harmonic_indices;  ///< when not all: sorted, without repeats
  double damping_ratio;
  bool residual_flexibility;
  modal::EigenMethod eigensolver;  ///< block Krylov-Schur or Spectra's Lanczos
  ModalShroud shroud;
};

struct CampbellSection {
  std::vector<double> speed_rpm;  ///< [min, max]
  int speed_points;
  std::vector<int> engine_orders;
  bool rotating_effects;
};

struct StaticSection {
  double speed_rpm;
  int increments;
};

struct ExcitationSection {
  int engine_order;
  std::array<double, 3> point;  ///< sector: nearest node
  std::array<double, 3> force;  ///< N; lumped: force[0] only
  int dof;                      ///< lumped only
  double speed_rpm;
};

struct ResponseSection {
  std::array<double, 3> point;
  int dof;                           ///< lumped only
  bool shapes = true;                ///< sector: frf.vtu, frf.pvd and contact.vtu (the ODS and contact maps)
  std::vector<double> shapes_at_hz;  ///< further frequencies of shapes and contact maps [Hz]
  bool stability = true;             ///< frf: Floquet exponents of every point
  StabilityMethod stability_method;  ///< Hill's method or shooting (automatic: by the model)
  int shooting_steps;                ///< shooting: least integration steps per excitation period
  double shooting_work;              ///< shooting: work bound of one curve [state-steps]
  /// hill with friction: time samples of the slider state (0: "auto", forced::memory_samples)
  int stability_samples = 0;
};

/// A lumped contact element: one DOF per direction (-1: absent), to ground or to other DOFs.
struct ContactElement {
  int x_dof = -1, y_dof = -1, z_dof = -1;
  int other_x_dof = -1, other_y_dof = -1, other_z_dof = -1;  ///< -1: ground
  std::optional<double> friction_coefficient, normal_stiffness, tangential_stiffness, normal_preload,
      frame_angle_deg;  ///< unset: the [contact] value
};

struct ContactSection {
  contact::Model model;
  int pairs;                                  ///< 0: "all"
  frf::ContactDiscretization discretization;  ///< sector only
  double friction_coefficient;
  double normal_stiffness;      ///< N/m per interface
  double tangential_stiffness;  ///< N/m per interface
  double normal_preload;        ///< N per interface, < 0: gap
  bool normal_preload_static;   ///< "static": each patch's from the static shroud contact at excitation.speed_rpm
  double frame_angle_deg;
  double interference;  ///< sector: overlap of the shroud faces at rest [m]; < 0: a gap
  contact::TangentialUpdate tangential_update;
  std::vector<ContactElement> elements;  ///< lumped only
};

struct HbmSection {
  int harmonics;  ///< H (0 with harmonics_auto)
  bool harmonics_auto;
  int time_samples;  ///< N (0 with time_samples_auto)
  bool time_samples_auto;
  hbm::JacobianMethod jacobian;
  double tolerance;
  double energy_tolerance;    ///< energy-balance error above which a point fails the run
  double auto_tolerance;      ///< "auto": relative change of the peak amplitude to stop at
  int auto_max_harmonics;     ///< "auto": largest H tried
  int auto_max_time_samples;  ///< "auto": largest N tried
  bool raise_time_samples;    ///< a fixed N that stops is traced again with 4 N, 16 N (docs/continuation.md)
};

struct ContinuationSection {
  double frequency_start_hz;
  double frequency_end_hz;
  double initial_step;  ///< Hz-equivalent arclength; 0: "auto" (docs/continuation.md)
  int max_points;
};

/// [nlmodes]: the nonlinear mode of `shroudsim nlmodes` (forced/nonlinear_modes.hpp).
struct NlmodesSection {
  double amplitude_start;  ///< modal amplitude a [m kg^0.5] (q_1^H M q_1 = a^2)
  double amplitude_end;
  int mode;  ///< 1-based linear mode index
  int max_points;
  std::vector<double> synthesis_scales;  ///< excitation scales of the synthesized curves
  bool compare_hb;                       ///< also the full harmonic balance at each scale
};

/// One harmonic of a prescribed motion: x(t) += c cos(n w t) + s sin(n w t).
struct MotionHarmonic {
  int harmonic = 0;
  double cosine = 0.0, sine = 0.0;
};

struct MotionSection {
  std::vector<MotionHarmonic> x, y, z;
};

/// How the points of a sampled study fill the unit cube (study/sampling.hpp).
enum class SampleMethod { random, latin_hypercube, sobol };
inline std::string to_string(SampleMethod m) {
  return m == SampleMethod::random ? "random" : m == SampleMethod::sobol ? "sobol" : "latin_hypercube";
}

/// One uncertain input of a sampled study: a number key and its distribution, "uniform"
/// (a = min, b = max), "normal" (a = mean, b = std) or "lognormal" (a = median, b = std of the
/// logarithm).
struct SampleInput {
  std::string key;
  std::string distribution;
  double a = 0.0, b = 0.0;
};

struct StudySection {
  /// dotted key -> values, each a TOML value in text form (usable with --set).
  std::vector<std::pair<std::string, std::vector<std::string>>> vary;
  std::vector<SampleInput> sample;  ///< sampled study: the uncertain inputs (empty: a sweep)
  int samples = 100;
  SampleMethod method = SampleMethod::latin_hypercube;
  int seed = 1;
  double threshold_m = 0.0;  ///< peak amplitude whose exceedance probability is reported (0: none)
};

/// A parsed, validated case. Default-constructed: every key at its schema default.
struct Case {
  Case();
  std::string name;
  std::filesystem::path file;       ///< the case file (absolute)
  std::filesystem::path directory;  ///< its folder: relative paths resolve here
  StructureSection structure;
  GeometrySection geometry;
  MaterialSection material;
  ModalSection modal;
  CampbellSection campbell;
  StaticSection static_contact;  ///< [static]
  ExcitationSection excitation;
  ResponseSection response;
  ContactSection contact;
  HbmSection hbm;
  ContinuationSection continuation;
  NlmodesSection nlmodes;
  MotionSection motion;
  StudySection study;
  /// Where each key came from: "file:line:col" or "file: --set key=value" (for messages
  /// of later stages about a key's value, e.g. a mesh that fails its checks).
  std::map<std::string, std::string> locations;
  /// "file:line:col" (or "file: --set key=value") of a key when known, else the case file:
  /// the head of a later stage's message about that key.
  std::string where(const std::string& key) const {
    const auto it = locations.find(key);
    return it != locations.end() ? it->second : file.string();
  }
  /// The case as run (after --set and defaults), as TOML text, and as JSON text.
  std::string resolved_toml;
  std::string resolved_json;
};

/// Reads, overrides and validates a case file. Throws InputError naming
/// file:line:col, key and the violated constraint.
/// overrides: "dotted.key=TOML value" strings (from --set), applied before validation.
Case load_case(const std::filesystem::path& file, const std::vector<std::string>& overrides = {});

/// Parses case text (file names the origin in messages).
Case parse_case(const std::string& text, const std::filesystem::path& file,
                const std::vector<std::string>& overrides = {});

/// The built-in generator's parameters of a case ([geometry] and structure.sectors).
mesh::SectorGeometry sector_geometry(const Case& c);

/// A complete, commented case file holding every key at its default.
std::string default_case_text();

}  // namespace shroudsim::io
