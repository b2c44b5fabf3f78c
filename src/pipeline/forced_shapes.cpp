// Shapes and contact maps of a forced response: see forced_shapes.hpp.
#include "pipeline/forced_shapes.hpp"

#include <cmath>
#include <complex>
#include <filesystem>
#include <functional>
#include <numbers>
#include <sstream>
#include <string>

#include "core/error.hpp"
#include "core/log.hpp"
#include "forced/contact_map.hpp"
#include "frf/sector.hpp"
#include "io/output.hpp"
#include "io/vtu.hpp"
#include "modal/harmonic.hpp"
#include "pipeline/forced_model.hpp"
#include "pipeline/modal_stage.hpp"

namespace shroudsim::pipeline {
namespace {

// Frames of one period in the animated time series (ParaView plays them in a loop).
constexpr int kFrames = 24;
// Time points of the amplitude field max_t |u(t)|: those of the curve's amplitude
// (forced::ReducedEquations::analyse), so that the field at the response node is frf.csv's.
constexpr int kAmplitudePoints = 512;

struct Shape {
  std::string name;  ///< peak<k> or f<frequency>hz[_<j>]
  double frequency_hz = 0.0;
  Eigen::VectorXd x;  ///< the solution (contact motion)
  double amplitude_m = 0.0;
};

std::string frequency_name(double f) {
  std::string name("f");
  for (char ch : io::format_number(f)) name.push_back(ch == '.' ? 'p' : ch);
  name.append("hz");
  return name;
}

void write_contact_map_csv(const std::filesystem::path& file, const std::vector<Shape>& shapes,
                           const std::vector<std::vector<forced::PairState>>& states,
                           const std::vector<Eigen::Vector3d>& positions) {
  std::ostringstream csv;
  csv << "shape,frequency_hz,pair,x_m,y_m,z_m,normal_load_min_n,normal_load_max_n,slip_amplitude_m,stick_fraction,"
         "slip_fraction,open_fraction,energy_per_cycle_j\n";
  for (std::size_t s = 0; s < shapes.size(); ++s) {
    for (std::size_t p = 0; p < states[s].size(); ++p) {
      const forced::PairState& st = states[s][p];
      csv << shapes[s].name << "," << io::format_number(shapes[s].frequency_hz) << "," << p;
      for (int k = 0; k < 3; ++k)
        csv << "," << (positions.empty() ? std::string() : io::format_number(positions[p][k]));
      for (double v : {st.normal_load_min_n, st.normal_load_max_n, st.slip_amplitude_m, st.stick_fraction,
                       st.slip_fraction, st.open_fraction, st.energy_per_cycle_j})
        csv << "," << io::format_number(v);
      csv << "\n";
    }
  }
  io::write_file_atomic(file, csv.str());
}

/// The nodes each pair acts on (its node pair, or its patch's).
std::vector<std::vector<int>> pair_nodes(const std::vector<frf::SectorContactPair>& pairs) {
  std::vector<std::vector<int>> nodes(pairs.size());
  for (std::size_t p = 0; p < pairs.size(); ++p) {
    if (pairs[p].patch.empty()) nodes[p] = {pairs[p].high_node, pairs[p].low_node};
    for (const auto& pn : pairs[p].patch) {
      nodes[p].push_back(pn.high_node);
      nodes[p].push_back(pn.low_node);
    }
  }
  return nodes;
}

std::string pvd(const std::vector<std::string>& files) {
  std::ostringstream s;
  s << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
       "  <Collection>\n";
  for (std::size_t k = 0; k < files.size(); ++k)
    s << "    <DataSet timestep=\"" << static_cast<double>(k) / files.size() << "\" part=\"0\" file=\"" << files[k]
      << "\"/>\n";
  s << "  </Collection>\n</VTKFile>\n";
  return s.str();
}

void write_sector_files(Context& ctx, const forced::ForcedModel& model, const std::vector<Shape>& shapes,
                        const std::vector<std::vector<Eigen::VectorXcd>>& forces,
                        const std::vector<std::vector<forced::PairState>>& states, std::size_t largest,
                        std::vector<Eigen::Vector3d>& positions) {
  std::vector<frf::ShapeLoad> loads;
  for (std::size_t s = 0; s < shapes.size(); ++s)
    loads.push_back({2.0 * std::numbers::pi * shapes[s].frequency_hz, forces[s]});
  const SectorShapes shaped = sector_shapes(ctx, model, loads, "shapes");
  log::Stopwatch clock;
  const mesh::Mesh& mesh = shaped.mesh;
  const Eigen::Index nodes = mesh.nodes.rows();
  std::vector<io::PointField> fields;
  for (std::size_t s = 0; s < shapes.size(); ++s) {
    const ShapeFiles written = write_shape(ctx.out_dir, mesh, shaped.u[s], shapes[s].name, "frf_frames",
                                           "frf_" + shapes[s].name + ".pvd", fields);
    if (s == largest) io::write_file_atomic(ctx.out_dir / "frf.pvd", written.pvd);
  }
  io::write_point_fields_vtu(ctx.out_dir / "frf.vtu", mesh, fields);

  // The contact map on the face nodes; a pair sits at the mean of its high nodes.
  const std::vector<std::vector<int>> on = pair_nodes(model.sector_pairs);
  positions.assign(on.size(), Eigen::Vector3d::Zero());
  for (std::size_t p = 0; p < on.size(); ++p) {
    for (std::size_t k = 0; k < on[p].size(); k += 2) positions[p] += mesh.nodes.row(on[p][k]).transpose();
    positions[p] /= static_cast<double>(on[p].size() / 2);
  }
  std::vector<io::PointField> contact;
  Eigen::VectorXd pair_of = Eigen::VectorXd::Constant(nodes, -1.0);
  for (std::size_t p = 0; p < on.size(); ++p)
    for (int node : on[p]) pair_of[node] = static_cast<double>(p);
  contact.push_back({"contact_pair", pair_of});
  for (std::size_t s = 0; s < shapes.size(); ++s) {
    const auto add = [&](const std::string& field, auto member) {
      Eigen::VectorXd v = Eigen::VectorXd::Zero(nodes);
      for (std::size_t p = 0; p < on.size(); ++p)
        for (int node : on[p]) v[node] = states[s][p].*member;
      contact.push_back({shapes[s].name + "_" + field, v});
    };
    add("energy_per_cycle_j", &forced::PairState::energy_per_cycle_j);
    add("slip_amplitude_m", &forced::PairState::slip_amplitude_m);
    add("stick_fraction", &forced::PairState::stick_fraction);
    add("slip_fraction", &forced::PairState::slip_fraction);
    add("open_fraction", &forced::PairState::open_fraction);
    add("normal_load_min_n", &forced::PairState::normal_load_min_n);
    add("normal_load_max_n", &forced::PairState::normal_load_max_n);
  }
  io::write_point_fields_vtu(ctx.out_dir / "contact.vtu", mesh, contact);
  if (log::detailed()) log::info("shapes: files written in " + io::format_number(clock.seconds()) + " s");
}

}  // namespace

SectorShapes sector_shapes(const Context& ctx, const forced::ForcedModel& model,
                           const std::vector<frf::ShapeLoad>& loads, const std::string& what) {
  const io::Case& c = ctx.config;
  log::Stopwatch clock;
  // The modal model the forced response was built on, kept in the context; else (a model
  // built elsewhere) the modes again from the stage cache, in a run of its own so that
  // run.json keeps the forced model's modal section.
  std::shared_ptr<ModalModel> kept = ctx.forced_modal;
  if (!kept) {
    Context modal_ctx;
    modal_ctx.config = c;
    modal_ctx.out_dir = ctx.out_dir;
    modal_ctx.threads = ctx.threads;
    kept = std::make_shared<ModalModel>(run_modal_stage(modal_ctx, forced_harmonic_indices(c), c.excitation.speed_rpm));
  }
  ModalModel& modal = *kept;
  if (!modal.failures.empty()) throw NumericalError(what + ": modal stage failed: " + modal.failures.front());
  const double modal_seconds = clock.seconds();
  clock.restart();
  SectorShapes out;
  // K_h^-1 from the receptance stage's solutions where the model kept them, else factors
  // computed in parallel, one per pair of conjugate indices, each held only by its job.
  const cyclic::CyclicSector& sector = modal.cyclic();
  const modal::HarmonicStiffnessFactors factor(sector, modal.options.factor_method);  // one symbolic analysis
  out.u = frf::sector_displacements(sector, modal.bases, std::cref(factor), model.sector_pairs, *model.sector_forcing,
                                    loads, dynamic_cast<const frf::SectorLinearPart*>(model.linear.get()), ctx.threads);
  out.mesh = modal.mesh;
  if (log::detailed())
    log::info(what + ": modal stage " + io::format_number(modal_seconds) + " s, displacements " +
              io::format_number(clock.seconds()) + " s");
  return out;
}

ShapeFiles write_shape(const std::filesystem::path& out_dir, const mesh::Mesh& mesh,
                       const std::vector<Eigen::VectorXcd>& u, const std::string& name, const std::string& frames_dir,
                       const std::string& pvd_file, std::vector<io::PointField>& fields) {
  const Eigen::Index nodes = mesh.nodes.rows();
  auto node_field = [&](const Eigen::VectorXd& v) {  // n_full -> n_nodes x 3
    Eigen::MatrixXd f(nodes, 3);
    for (Eigen::Index i = 0; i < nodes; ++i) f.row(i) = v.segment(3 * i, 3).transpose();
    return f;
  };
  auto at = [&](double theta) {  // u(theta) = Re sum_n U_n exp(i n theta)
    Eigen::VectorXd ut = Eigen::VectorXd::Zero(u[0].size());
    for (std::size_t n = 0; n < u.size(); ++n) ut += (u[n] * std::polar(1.0, static_cast<double>(n) * theta)).real();
    return node_field(ut);
  };
  Eigen::VectorXd amplitude = Eigen::VectorXd::Zero(nodes);
  for (int k = 0; k < kAmplitudePoints; ++k)
    amplitude = amplitude.cwiseMax(at(2.0 * std::numbers::pi * k / kAmplitudePoints).rowwise().norm());
  std::filesystem::create_directories(out_dir / frames_dir);
  std::vector<std::string> frames;
  for (int k = 0; k < kFrames; ++k) {
    const Eigen::MatrixXd f = at(2.0 * std::numbers::pi * k / kFrames);
    char file[96];
    std::snprintf(file, sizeof file, "%s_t%02d.vtu", name.c_str(), k);
    io::write_point_fields_vtu(out_dir / frames_dir / file, mesh, {{"displacement_m", f}});
    frames.push_back(frames_dir + "/" + file);
  }
  ShapeFiles out;
  out.pvd = pvd(frames);
  io::write_file_atomic(out_dir / pvd_file, out.pvd);
  for (std::size_t n = 0; n < u.size(); ++n) {
    fields.push_back({name + "_u_h" + std::to_string(n) + "_re_m", node_field(u[n].real())});
    fields.push_back({name + "_u_h" + std::to_string(n) + "_im_m", node_field(u[n].imag())});
  }
  fields.push_back({name + "_amplitude_m", amplitude});
  out.largest_m = amplitude.maxCoeff();
  return out;
}

void write_shapes(Context& ctx, const forced::ForcedModel& model, hbm::ContactEvaluator& evaluator,
                  forced::ReducedEquations& equations, const forced::FrequencyResponse& response) {
  const io::Case& c = ctx.config;
  log::Stopwatch clock;
  std::vector<Shape> shapes;
  for (const auto& pk : response.peaks)
    shapes.push_back({"peak" + std::to_string(shapes.size() + 1), pk.frequency_hz, pk.x, pk.amplitude_m});
  if (shapes.empty() && !response.points.empty()) {  // no resonance peak: the sampled maximum
    std::size_t best = 0;
    for (std::size_t i = 0; i < response.results.size(); ++i)
      if (response.results[i].amplitude > response.results[best].amplitude) best = i;
    shapes.push_back(
        {"peak1", response.results[best].frequency_hz, response.points[best].x, response.results[best].amplitude});
  }
  std::size_t largest = 0;
  for (std::size_t s = 0; s < shapes.size(); ++s)
    if (shapes[s].amplitude_m > shapes[largest].amplitude_m) largest = s;
  for (double f : c.response.shapes_at_hz) {
    int failed = 0;
    const std::vector<Eigen::VectorXd> xs = forced::solutions_at_frequency(response, equations, f, &failed);
    if (xs.empty())
      ctx.report.warn("response.shapes_at_hz: the traced curve does not reach " + io::format_number(f) +
                      " Hz: no shape there");
    if (failed > 0)
      ctx.report.warn("response.shapes_at_hz: Newton at " + io::format_number(f) + " Hz failed from " +
                      std::to_string(failed) + " of the curve's crossings of it: no shape there");
    for (std::size_t j = 0; j < xs.size(); ++j) {
      std::string name = frequency_name(f);
      if (xs.size() > 1) name.append("_").append(std::to_string(j + 1));
      shapes.push_back({name, f, xs[j], equations.analyse(xs[j], f).amplitude});
    }
  }
  if (shapes.empty()) return;
  std::vector<std::vector<forced::PairState>> states;
  std::vector<std::vector<Eigen::VectorXcd>> forces;
  for (const Shape& s : shapes) {
    states.push_back(forced::pair_states(evaluator, s.x));
    forces.push_back(equations.contact_force_harmonics(s.x));
  }
  std::vector<Eigen::Vector3d> positions;  // sector: where each pair sits
  if (model.sector_forcing) write_sector_files(ctx, model, shapes, forces, states, largest, positions);
  write_contact_map_csv(ctx.out_dir / "contact_map.csv", shapes, states, positions);
  ctx.report.stage("shapes", clock.seconds());
  auto& j = ctx.report.section("shapes");
  j = nlohmann::json::array();
  for (std::size_t s = 0; s < shapes.size(); ++s)
    j.push_back({{"name", shapes[s].name},
                 {"frequency_hz", shapes[s].frequency_hz},
                 {"amplitude_m", shapes[s].amplitude_m},
                 {"largest_peak", s == largest}});
}

}  // namespace shroudsim::pipeline
