// The FE sector as the forced response sees it: modes of the harmonic indices the engine
// order reaches, shroud contact pairs with frames and tributary areas, excitation and
// response nodes (docs/physics.md sections 2 and 3).
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "core/error.hpp"
#include "core/log.hpp"
#include "fe/fingerprint.hpp"
#include "forced/stability.hpp"
#include "frf/contact_patches.hpp"
#include "frf/lumped.hpp"
#include "frf/sector.hpp"
#include "frf/static_shroud.hpp"
#include "io/output.hpp"
#include "modal/cache.hpp"
#include "modal/harmonic.hpp"
#include "modal/rotating.hpp"
#include "pipeline/forced_model.hpp"
#include "pipeline/modal_stage.hpp"

namespace shroudsim::pipeline {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// The force as a size times a direction, the force over its component of largest magnitude:
// 1 there, and the same bits for every multiple whose division is exact ([1, 1, 1] for
// [2.5, 2.5, 2.5] and for [-1, -1, -1]). No force: direction zero, size 1. The receptance data
// is computed for the direction and then scaled by the size (frf::SectorLinearPart::
// scale_force), whether the run computes it or reads it from the cache: so a run's curve does
// not depend on which excitation level computed the entry it reads.
struct ForceParts {
  Eigen::Vector3d direction;
  double size = 1.0;
};

ForceParts force_parts(const Eigen::Vector3d& f) {
  Eigen::Index largest = 0;
  if (f.cwiseAbs().maxCoeff(&largest) == 0.0) return {Eigen::Vector3d::Zero(), 1.0};
  return {f / f[largest], f[largest]};
}

// The fingerprint of everything the sector's receptance data depends on (frf::SectorLinearPart::
// Precomputed): the sector (mesh, its K and M as used, the tied shroud springs), the modes
// themselves, the contact rows (pairs, frames, patches), the forcing rows (response and
// excitation nodes, the force: its direction, force_parts), the harmonic indices and the
// factorization method (its round-off). Not the contact law, the damping, the frequencies or the
// force's size.
std::string receptances_key(const ModalModel& modal, const std::vector<frf::SectorContactPair>& pairs,
                            const frf::SectorForcing& forcing, int n_harmonics) {
  fe::Hasher h;
  h.add(std::string("receptances 3"));
  fe::hash_into(h, modal.mesh);
  for (const auto* a : {&modal.km.K, &modal.km.M}) {
    SHROUDSIM_CHECK(a->isCompressed(), "K and M compressed");
    h.add(a->rows());
    h.add(a->nonZeros());
    h.add_bytes(a->valuePtr(), sizeof(*a->valuePtr()) * static_cast<std::size_t>(a->nonZeros()));
    h.add_bytes(a->innerIndexPtr(), sizeof(*a->innerIndexPtr()) * static_cast<std::size_t>(a->nonZeros()));
    h.add_bytes(a->outerIndexPtr(), sizeof(*a->outerIndexPtr()) * static_cast<std::size_t>(a->outerSize() + 1));
  }
  h.add(modal.interface.size());
  for (const auto& s : modal.interface) {
    h.add(s.high_node);
    h.add(s.low_node);
    h.add_bytes(s.frame.data(), sizeof(double) * 9);
    h.add_bytes(s.stiffness.data(), sizeof(double) * 3);
  }
  h.add(static_cast<int>(modal.options.factor_method));
  for (const auto& [index, b] : modal.bases) {
    h.add(index);
    h.add(b.omega.size());
    h.add_bytes(b.omega.data(), sizeof(double) * static_cast<std::size_t>(b.omega.size()));
    h.add(b.phi.rows());
    h.add_bytes(b.phi.data(), sizeof(*b.phi.data()) * static_cast<std::size_t>(b.phi.size()));
  }
  h.add(pairs.size());
  for (const auto& p : pairs) {
    h.add(p.high_node);
    h.add(p.low_node);
    h.add_bytes(p.frame.data(), sizeof(double) * 9);
    h.add(p.patch.size());
    for (const auto& m : p.patch) {
      h.add(m.high_node);
      h.add(m.low_node);
      h.add(m.weight);
    }
  }
  h.add(forcing.engine_order);
  h.add(forcing.excitation_node);
  h.add_bytes(forcing.force.data(), sizeof(double) * 3);
  h.add(forcing.response_node);
  h.add(static_cast<int>(forcing.residual_flexibility));
  h.add(n_harmonics);
  return h.hex();
}

// The cache entry of the receptance data: per block (the static one tagged -1, then each
// harmonic index) omega as a vector, psi and flex as matrices; last, tagged -2, the force the
// data was computed with (its direction, force_parts; a vector, no matrices).
constexpr std::int64_t kStaticTag = -1, kForceTag = -2;

modal::TaggedArrays pack(const frf::SectorLinearPart::Precomputed& p, const Eigen::Vector3d& force) {
  modal::TaggedArrays a;
  auto add = [&a](std::int64_t tag, const frf::SectorLinearPart::IndexData& d) {
    a.tags.push_back(tag);
    a.vectors.push_back(d.omega);
    a.matrices.push_back(d.psi);
    a.matrices.push_back(d.flex);
  };
  add(kStaticTag, p.statics);
  for (const auto& [index, d] : p.dynamic) add(index, d);
  a.tags.push_back(kForceTag);
  a.vectors.emplace_back(force);
  return a;
}

struct ReceptanceEntry {
  frf::SectorLinearPart::Precomputed data;
  Eigen::Vector3d force;  ///< the force the data was computed with
};

// The entry back, or nullopt when its blocks are not those of this model (k rows and columns of
// flex, k rows of psi and one column per mode, each index once, the force last).
std::optional<ReceptanceEntry> unpack(modal::TaggedArrays a, Eigen::Index k) {
  const std::size_t blocks = a.tags.size() - 1;  // and the force
  if (a.tags.size() < 2 || a.vectors.size() != blocks + 1 || a.matrices.size() != 2 * blocks ||
      a.tags.front() != kStaticTag || a.tags.back() != kForceTag || a.vectors.back().size() != 3)
    return std::nullopt;
  ReceptanceEntry e;
  e.force = a.vectors.back();
  for (std::size_t b = 0; b < blocks; ++b) {
    frf::SectorLinearPart::IndexData d;
    d.omega = std::move(a.vectors[b]);
    d.psi = std::move(a.matrices[2 * b]);
    d.flex = std::move(a.matrices[2 * b + 1]);
    if (b == 0) {
      e.data.statics = std::move(d);
    } else if (a.tags[b] < 0 || !e.data.dynamic.emplace(static_cast<int>(a.tags[b]), std::move(d)).second) {
      return std::nullopt;
    }
  }
  if (!e.data.fits(k)) return std::nullopt;
  return e;
}

contact::PairParameters pair_of(const io::ContactSection& c, const io::ContactElement* e) {
  contact::PairParameters p;
  p.friction_coefficient = e && e->friction_coefficient ? *e->friction_coefficient : c.friction_coefficient;
  p.normal_stiffness = e && e->normal_stiffness ? *e->normal_stiffness : c.normal_stiffness;
  p.tangential_stiffness = e && e->tangential_stiffness ? *e->tangential_stiffness : c.tangential_stiffness;
  p.normal_preload = e && e->normal_preload ? *e->normal_preload : c.normal_preload;
  return p;
}

int nearest_node(const mesh::Mesh& m, const std::array<double, 3>& p) {
  const Eigen::RowVector3d x(p[0], p[1], p[2]);
  Eigen::Index best = 0;
  (m.nodes.rowwise() - x).rowwise().squaredNorm().minCoeff(&best);
  return static_cast<int>(best);
}

}  // namespace

void check_forced_points(const io::Case& c, const mesh::Mesh& mesh) {
  // More contact patches than the face has node pairs (one face pair per matched shroud
  // pair, frf::shroud_face).
  if (c.contact.pairs > static_cast<int>(mesh.shroud_pairs.size())) {
    throw InputError(c.where("contact.pairs") + ": contact.pairs = " + std::to_string(c.contact.pairs) +
                     " violates: pairs <= " + std::to_string(mesh.shroud_pairs.size()) +
                     " (the matched shroud node pairs of this mesh), or \"all\"");
  }
  // A point whose nearest node is clamped, or that lies off the sector, would give a silent
  // zero (or meaningless) response: an input error naming the key.
  const auto& hub = mesh.node_set("hub");
  const double size = (mesh.nodes.colwise().maxCoeff() - mesh.nodes.colwise().minCoeff()).norm();
  for (const auto& [key, point] : {std::pair{std::string("excitation.point"), c.excitation.point},
                                   std::pair{std::string("response.point"), c.response.point}}) {
    const int node = nearest_node(mesh, point);
    const Eigen::RowVector3d x(point[0], point[1], point[2]);
    const double distance = (mesh.nodes.row(node) - x).norm();
    const std::string where = c.where(key);
    if (std::find(hub.begin(), hub.end(), node) != hub.end())
      throw InputError(where + ": " + key + ": the nearest node (" + std::to_string(node) +
                       ") is on the clamped hub: it does not move; give a point on the blade or shroud");
    if (distance > 0.1 * size)
      throw InputError(where + ": " + key + " is " + io::format_number(distance) +
                       " m from the nearest node of the sector (" + "model size " + io::format_number(size) +
                       " m): give a point on the sector");
  }
}

namespace {

/// Hill's method asked for on an FE sector.
bool sector_hill(const io::Case& c) {
  return c.structure.type == io::StructureType::sector && c.response.stability &&
         c.response.stability_method == io::StabilityMethod::hill;
}

/// The friction slider's directions: 1 for the 1d laws, 2 otherwise.
int tangential_directions(const io::Case& c) { return contact::n_tangential_directions(c.contact.model); }

/// With friction the slider state adds (memory samples) x (tangential directions) x (contact
/// elements) to each family's pencil (forced::memory_samples). Where the case fixes N, H and the
/// number of patches (each at least one element), that lower bound is known before any mode is
/// computed: 0 where it is not.
long long slider_state_lower_bound(const io::Case& c) {
  if (c.contact.friction_coefficient <= 0.0 || c.contact.pairs <= 0 || c.hbm.time_samples_auto || c.hbm.harmonics_auto)
    return 0;
  const int dampers = tangential_directions(c) * c.contact.pairs;
  return static_cast<long long>(
             forced::memory_samples(c.response.stability_samples, c.hbm.time_samples, c.hbm.harmonics, dampers)) *
         dampers;
}

}  // namespace

bool sector_stability_requested(const io::Case& c) {
  return sector_hill(c) && slider_state_lower_bound(c) <= forced::kMaxSliderStateSize;
}

std::vector<int> forced_harmonic_indices(const io::Case& c) {
  std::set<int> needed;
  for (int n = 1; n <= c.hbm.harmonics; ++n)
    needed.insert(frf::harmonic_index(n, c.excitation.engine_order, c.structure.sectors));
  // Hill's method on a sector judges every harmonic index's perturbations (its families).
  if (sector_stability_requested(c))
    for (int h = 0; 2 * h <= c.structure.sectors; ++h) needed.insert(h);
  return {needed.begin(), needed.end()};
}

bool judged_by_shooting(const io::Case& c) {
  if (c.structure.type != io::StructureType::lumped || !c.response.stability) return false;
  if (c.response.stability_method != io::StabilityMethod::automatic)
    return c.response.stability_method == io::StabilityMethod::shooting;
  return std::any_of(c.contact.elements.begin(), c.contact.elements.end(),
                     [&](const io::ContactElement& e) { return pair_of(c.contact, &e).friction_coefficient > 0.0; });
}

std::string sector_stability_refusal(const io::Case& c) {
  if (c.structure.type != io::StructureType::sector || sector_stability_requested(c)) return "";
  if (sector_hill(c))
    return "not analysed (docs/physics.md section 9): with friction each perturbation family's pencil holds the "
           "damper position of every memory sample, tangential direction and contact element, at least " +
           std::to_string(slider_state_lower_bound(c)) + " unknowns here (response.stability_samples x " +
           std::to_string(tangential_directions(c)) + " x contact.pairs), above the limit of " +
           std::to_string(forced::kMaxSliderStateSize) + "; fewer samples or pairs bring it within";
  return "not analysed for an FE sector unless asked for (docs/physics.md section 9): response.stability_method = "
         "\"hill\" judges every point over the sector's perturbation families, which needs the modes of every "
         "harmonic index 0..Nb/2 and, with friction, a pencil wider by the damper positions of the slider state "
         "per family (response.stability_samples: the default case's 700 points took 833 s on 2 threads, its "
         "slider state at 80 of 512 samples, against 10 s for the rest of the run with its modes cached). On the "
         "coarse test sector its verdicts agree with the whole wheel's time integration (shooting in modal "
         "coordinates) wherever the multipliers are clearly off 1, and both find the travelling wave unstable over "
         "most of its friction range";
}

ForcedModel make_sector_model(Context& ctx) {
  const io::Case& c = ctx.config;
  const int m = c.excitation.engine_order;
  const std::vector<int> needed = forced_harmonic_indices(c);
  // contact.normal_preload = "static": the static shroud contact at the forced response's
  // speed, on the sector at rest plus its rotating operators (docs/physics.md section 8).
  std::optional<frf::StaticShroud> static_state;
  if (c.contact.normal_preload_static) {
    ModalModel rest = run_modal_stage(ctx, {});
    std::unique_ptr<modal::RotatingOperators> ops;
    if (c.excitation.speed_rpm > 0.0)
      ops = std::make_unique<modal::RotatingOperators>(
          modal::rotating_operators(rest.mesh, rest.material, rest.km, rest.cyclic()));
    static_state =
        frf::solve_static_shroud(rest.mesh, rest.km, ops.get(), static_shroud_settings(c, c.excitation.speed_rpm));
  }
  // The K_h factors (static and residual flexibility) are always computed on demand, never
  // kept from a modal solve: the solve's factor (of the same K_h, computed inside the parallel
  // modal solve) differs from it in round-off, so a run with the modes cached and one that solves them would
  // give different curves where the continuation's path is sensitive to round-off (the
  // default case: 649 points in two pieces against 343 in one, the same located peak).
  auto kept_modal =
      std::make_shared<ModalModel>(run_modal_stage(ctx, needed, c.excitation.speed_rpm));  // > 0: at that speed
  ModalModel& modal = *kept_modal;
  if (!modal.failures.empty()) throw NumericalError("modal stage failed: " + modal.failures.front());
  const mesh::Mesh& mesh = modal.mesh;

  const std::vector<frf::ShroudFaceNode> face = frf::shroud_face(mesh);
  if (face.empty()) throw InputError(c.file.string() + ": the mesh has no matched shroud node pairs");
  const frf::ContactDiscretization discretization = c.contact.discretization;
  // Each patch gets the share A_P / A of the face's stiffness and preload.
  std::vector<frf::ContactPatch> patches;
  try {
    patches = frf::partition_face(mesh, face, c.contact.pairs);  // 0: "all"
  } catch (const std::invalid_argument& e) {                     // more pairs than the face has
    throw InputError(c.locations.at("contact.pairs") + ": contact." + e.what());
  }
  std::vector<frf::SectorContactPair> pairs =
      frf::contact_pairs(mesh, face, patches, discretization, c.contact.frame_angle_deg * kDeg);
  double total = 0.0;
  for (const auto& f : face) total += f.area;
  ForcedModel model;
  contact::PairParameters totals;
  totals.friction_coefficient = c.contact.friction_coefficient;
  totals.tangential_stiffness = c.contact.tangential_stiffness;
  totals.normal_stiffness = c.contact.normal_stiffness;
  totals.normal_preload = c.contact.normal_preload;
  model.pairs = frf::patch_parameters(patches, total, totals, static_state ? &*static_state : nullptr);
  double static_preload = 0.0;
  for (const auto& pp : model.pairs) static_preload += pp.normal_preload;
  frf::SectorForcing forcing;
  forcing.engine_order = m;
  forcing.excitation_node = nearest_node(mesh, c.excitation.point);
  forcing.force = Eigen::Vector3d(c.excitation.force[0], c.excitation.force[1], c.excitation.force[2]);
  forcing.response_node = nearest_node(mesh, c.response.point);
  check_forced_points(c, mesh);
  forcing.damping_ratio = c.modal.damping_ratio;
  forcing.residual_flexibility = c.modal.residual_flexibility;
  log::Stopwatch clock;
  const cyclic::CyclicSector& sector = modal.cyclic();
  // The receptance data is reused from the case directory's cache when everything it depends
  // on is unchanged (receptances_key): a run that changes only the contact law, N, the damping,
  // the range, the continuation or the size of the force factorizes nothing (docs/contract.md,
  // frf_model.receptances). It is that of the force's direction, scaled (force_parts).
  const ForceParts force = force_parts(forcing.force);
  frf::SectorForcing unit = forcing;
  unit.force = force.direction;
  const std::string key = receptances_key(modal, pairs, unit, c.hbm.harmonics);
  const std::filesystem::path entry = c.directory / ".cache" / ("receptances-" + key + ".bin");
  std::string problem;
  std::unique_ptr<frf::SectorLinearPart> part;
  if (auto arrays = modal::load_arrays(entry, key, &problem)) {
    if (auto e = unpack(std::move(*arrays), 3 * static_cast<Eigen::Index>(pairs.size()) + 4)) {
      if (e->force == force.direction)
        part =
            std::make_unique<frf::SectorLinearPart>(std::move(e->data), pairs, unit, sector.sectors(), c.hbm.harmonics);
      else problem = "it was computed for another force";
    } else {
      problem = "its blocks do not fit this model";
    }
  }
  const bool reused = part != nullptr;
  if (!problem.empty())
    ctx.report.warn("the cache entry " + entry.string() + " is not used (" + problem + "); recomputing it");
  if (!reused) {
    // The K_h factors, one per pair of conjugate indices, computed in parallel: each lives only
    // as long as its job, so that at most one per worker is held (a map of them kept every factor
    // until the stage ended: up to five of the 238k-DOF sector's at once).
    const modal::HarmonicStiffnessFactors factor(sector, modal.options.factor_method);  // one symbolic analysis
    part = std::make_unique<frf::SectorLinearPart>(sector, modal.bases, std::cref(factor), pairs, unit, c.hbm.harmonics,
                                                   ctx.threads);
    try {
      modal::save_arrays(entry, key, pack(part->precomputed(), force.direction));
    } catch (const std::exception& e) {
      ctx.report.warn(std::string("the receptances could not be cached: ") + e.what());
    }
  }
  if (force.size != 1.0) part->scale_force(force.size, forcing.force);
  model.linear = std::move(part);
  model.sector_pairs = pairs;
  model.sector_forcing = forcing;
  ctx.report.stage("receptances", clock.seconds(), reused);
  ctx.report.section("frf_model")["receptances"] = {
      {"cache_entry", entry.string()}, {"reused", reused}, {"force_scale", force.size}};
  if (reused) log::info("frf: receptances reused from " + entry.string());
  if (log::detailed()) {
    const auto& part = static_cast<const frf::SectorLinearPart&>(*model.linear);
    for (const auto& t : part.build_times()) {
      std::string ids;
      for (int h : t.indices) ids += (ids.empty() ? "" : ", ") + std::to_string(h);
      log::info("frf: receptances of harmonic indices " + ids + ": factor " + io::format_number(t.factor_seconds) +
                " s, flexibility " + io::format_number(t.flexibility_seconds) + " s");
    }
  }
  auto& j = ctx.report.section("frf_model");
  j["contact_pairs"] = pairs.size();
  j["contact_discretization"] = frf::to_string(c.contact.discretization);
  j["shroud_pairs_available"] = face.size();
  j["contact_area_m2"] = total;
  if (static_state) {
    j["normal_preload_from"] = "static";
    j["static_normal_load_n"] = static_state->normal_load();
    j["static_open_pairs"] = static_state->count(contact::StaticState::open);
    j["normal_preload_total_n"] = static_preload;
    log::info("frf: preloads from the static shroud contact at " + io::format_number(c.excitation.speed_rpm) +
              " rpm: normal load " + io::format_number(static_state->normal_load()) + " N, " +
              std::to_string(static_state->count(contact::StaticState::open)) + " of " +
              std::to_string(static_state->results.size()) + " pairs open");
  }
  j["excitation_node"] = forcing.excitation_node;
  j["response_node"] = forcing.response_node;
  j["harmonic_indices"] = needed;
  std::ostringstream s;
  s << "frf: " << pairs.size()
    << (discretization == frf::ContactDiscretization::patches ? " contact patches over " : " of ") << face.size()
    << " shroud node pairs, contact area " << total * 1e6 << " mm^2; excitation node " << forcing.excitation_node
    << ", response node " << forcing.response_node;
  log::info(s.str());
  ctx.forced_modal = std::move(kept_modal);
  return model;
}

ForcedModel make_lumped_model(const io::Case& c) {
  ForcedModel model;
  std::vector<frf::LumpedContact> contacts;
  for (const auto& e : c.contact.elements) {
    frf::LumpedContact lc;
    lc.dof = {e.x_dof, e.y_dof, e.z_dof};
    lc.other = {e.other_x_dof, e.other_y_dof, e.other_z_dof};
    lc.frame_angle = (e.frame_angle_deg ? *e.frame_angle_deg : c.contact.frame_angle_deg) * kDeg;
    contacts.push_back(lc);
    model.pairs.push_back(pair_of(c.contact, &e));
  }
  if (contacts.empty())
    throw InputError(c.locations.at("contact.elements") +
                     ": contact.elements: a lumped forced response needs at least one [[contact.elements]]");
  model.linear = std::make_unique<frf::LumpedLinearPart>(c.structure.mass, c.structure.stiffness, c.structure.damping,
                                                         contacts, c.excitation.dof, c.excitation.force[0],
                                                         c.response.dof);
  return model;
}

hbm::ContactEvaluatorOptions evaluator_options(const io::Case& c, int threads) {
  hbm::ContactEvaluatorOptions o;
  o.n_harmonics = c.hbm.harmonics;
  o.n_time_samples = c.hbm.time_samples;
  o.law.model = c.contact.model;
  o.law.update = c.contact.tangential_update;
  o.jacobian = c.hbm.jacobian;
  o.threads = threads;
  // FFTW_MEASURE picks plans by timing, so round-off (and with it a Newton path through
  // nonsmooth contact states) would change from run to run: estimated plans are reproducible.
  o.measure_plans = false;
  if (o.law.model == contact::Model::one_d_exact && o.n_harmonics != 1)
    throw InputError(
        c.locations.at("hbm.harmonics") + ": hbm.harmonics = " + std::to_string(c.hbm.harmonics) +
        " violates: harmonics = 1 for contact.model = \"1d_exact\" (the time-continuous single-harmonic law)");
  std::vector<std::string> errors;
  if (!o.validate(&errors)) {
    throw InputError(c.where("hbm.time_samples") + ": hbm: " + errors.front());
  }
  return o;
}

forced::FrequencyResponseSettings frequency_response_settings(const io::Case& c) {
  forced::FrequencyResponseSettings s;
  s.frequency_start_hz = c.continuation.frequency_start_hz;
  s.frequency_end_hz = c.continuation.frequency_end_hz;
  s.initial_step_hz = c.continuation.initial_step;
  s.max_points = c.continuation.max_points;
  s.tolerance = c.hbm.tolerance;
  return s;
}

}  // namespace shroudsim::pipeline
