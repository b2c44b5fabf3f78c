#pragma once
// The case file (docs/contract.md), parsed and validated: plain data handed to app/,
// which maps it onto each stage's own *Options. Every key has a default (see schema.cpp,
// `shroudsim --print-defaults`). Units: SI, angles in degrees, frequencies in Hz,
// speeds in rpm, as in the case file.
#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "mesh/sector_generator.hpp"

namespace shroudsim::io {

struct StructureSection {
  std::string type = "sector";          ///< "sector" (FE) or "lumped"
  int sectors = 8;                      ///< Nb >= 1
  std::filesystem::path mesh;           ///< absolute path of a given mesh, empty: generate
  Eigen::MatrixXd mass, stiffness, damping;  ///< lumped only, n x n (damping may be empty)
};

struct GeometrySection {
  double hub_radius = 0.10;
  double disk_outer_radius = 0.16;
  double disk_thickness = 0.03;
  double blade_length = 0.25;
  double blade_chord = 0.05;
  double blade_thickness = 0.006;
  double blade_twist_deg = 20.0;
  double shroud_thickness = 0.006;
  double shroud_width = 0.05;
  double shroud_contact_angle_deg = 45.0;
  int element_order = 2;
  double mesh_size = 0.01;
  double max_elements = 1.0e6;          ///< refuse to mesh when the estimated element count is larger
};

struct MaterialSection {
  double youngs_modulus = 210e9;
  double poisson_ratio = 0.3;
  double density = 7850.0;
};

struct ModalSection {
  int modes = 50;
  bool all_harmonic_indices = true;     ///< harmonic_indices = "all"
  std::vector<int> harmonic_indices;    ///< when not all
  double damping_ratio = 0.001;
  bool residual_flexibility = true;
  std::string eigensolver = "block";    ///< "block" (block Krylov-Schur) | "spectra" (Spectra's Lanczos)
  std::string shroud = "open";          ///< "open" | "stuck" | "contact" (modes and campbell; docs/physics.md sections 1, 8)
};

struct CampbellSection {
  std::vector<double> speed_rpm{0.0, 15000.0};  ///< [min, max]
  int speed_points = 31;
  std::vector<int> engine_orders{1, 2, 3, 4, 5, 6};
  bool rotating_effects = false;
};

struct StaticSection {
  double speed_rpm = 0.0;
  int increments = 10;
};

struct ExcitationSection {
  int engine_order = 1;
  std::array<double, 3> point{0.0, 0.35, 0.0};   ///< sector: nearest node
  std::array<double, 3> force{1.0, 1.0, 1.0};    ///< N; lumped: force[0] only
  int dof = 0;                                   ///< lumped only
  double speed_rpm = 0.0;
};

struct ResponseSection {
  std::array<double, 3> point{0.0, 0.34, 0.0};
  int dof = 0;                                   ///< lumped only
};

/// A lumped contact element: one DOF per direction (-1: absent), to ground or to other DOFs.
struct ContactElement {
  int x_dof = -1, y_dof = -1, z_dof = -1;
  int other_x_dof = -1, other_y_dof = -1, other_z_dof = -1;  ///< -1: ground
  std::optional<double> friction_coefficient, normal_stiffness, tangential_stiffness,
      normal_preload, frame_angle_deg;  ///< unset: the [contact] value
};

struct ContactSection {
  std::string model = "full3d";          ///< full3d | quasi3d | 1d | 1d_exact
  int pairs = 0;                         ///< 0: "all"
  std::string discretization = "patches"; ///< "patches" | "nodes" (sector only)
  double friction_coefficient = 0.3;
  double normal_stiffness = 1.0e6;       ///< N/m per interface
  double tangential_stiffness = 1.0e6;   ///< N/m per interface
  double normal_preload = 0.25;          ///< N per interface, < 0: gap
  bool normal_preload_static = false;    ///< "static": each patch's from the static shroud contact at excitation.speed_rpm
  double frame_angle_deg = 0.0;
  double interference = 0.0;            ///< sector: overlap of the shroud faces at rest [m]; < 0: a gap
  std::string tangential_update = "exact_linear";  ///< or "radial_return"
  std::vector<ContactElement> elements;  ///< lumped only
};

struct HbmSection {
  int harmonics = 5;                     ///< H (0 with harmonics_auto)
  bool harmonics_auto = false;
  int time_samples = 512;                ///< N
  bool time_samples_auto = false;
  std::string jacobian = "analytic";     ///< or "finite_difference"
  double tolerance = 1e-8;
  double energy_tolerance = 1e-3;        ///< energy-balance error above which a point fails the run
  double auto_tolerance = 0.01;          ///< "auto": relative change of the peak amplitude to stop at
  int auto_max_harmonics = 25;           ///< "auto": largest H tried
  int auto_max_time_samples = 4096;      ///< "auto": largest N tried
};

struct ContinuationSection {
  double frequency_start_hz = 100.0;
  double frequency_end_hz = 220.0;
  double initial_step = 0.0;             ///< Hz-equivalent arclength; 0: "auto" (docs/continuation.md)
  int max_points = 5000;
};

/// One harmonic of a prescribed motion: x(t) += c cos(n w t) + s sin(n w t).
struct MotionHarmonic {
  int harmonic = 0;
  double cosine = 0.0, sine = 0.0;
};

struct MotionSection {
  std::vector<MotionHarmonic> x, y, z;
};

struct StudySection {
  /// dotted key -> values, each a TOML value in text form (usable with --set).
  std::vector<std::pair<std::string, std::vector<std::string>>> vary;
};

/// A parsed, validated case.
struct Case {
  std::string name = "shrouded_blade";
  std::filesystem::path file;            ///< the case file (absolute)
  std::filesystem::path directory;       ///< its folder: relative paths resolve here
  StructureSection structure;
  GeometrySection geometry;
  MaterialSection material;
  ModalSection modal;
  CampbellSection campbell;
  StaticSection static_contact;          ///< [static]
  ExcitationSection excitation;
  ResponseSection response;
  ContactSection contact;
  HbmSection hbm;
  ContinuationSection continuation;
  MotionSection motion;
  StudySection study;
  std::map<std::string, double> expect;
  /// Where each key came from: "file:line:col" or "file: --set key=value" (for messages
  /// of later stages about a key's value, e.g. a mesh that fails its checks).
  std::map<std::string, std::string> locations;  ///< [expect]: regression expectations (free keys)
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
