// `shroudsim static CASE`: the shroud contact of the spinning sector (docs/physics.md
// section 8) -> static_contact.csv (one row per matched shroud pair: state, gap, loads,
// pressure), contact_static.vtu (displacement, von Mises stress, contact pressure and state
// for ParaView), contact_static.png (the pressure over the face), run.json "static".
#include <cmath>
#include <iomanip>
#include <numbers>
#include <sstream>

#include "app/context.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "fe/rotating.hpp"
#include "frf/static_shroud.hpp"
#include "io/output.hpp"
#include "io/vtu.hpp"
#include "modal/rotating.hpp"

namespace shroudsim::app {

int cmd_static(Context& ctx) {
  const io::Case& c = ctx.config;
  if (c.structure.type != io::StructureType::sector)
    throw InputError(c.where("structure.type") + ": structure.type = \"" + io::to_string(c.structure.type) +
                     "\": `static` needs an FE sector");
  ModalModel model = run_modal_stage(ctx, {});
  log::Stopwatch clock;
  const double speed = c.static_contact.speed_rpm;
  std::unique_ptr<modal::RotatingOperators> ops;
  if (speed > 0.0)
    ops = std::make_unique<modal::RotatingOperators>(
        modal::rotating_operators(model.mesh, model.material, model.km, model.cyclic()));
  frf::StaticShroud st;
  try {
    st = frf::solve_static_shroud(model.mesh, model.km, ops.get(), static_shroud_settings(c, speed));
  } catch (const InputError& e) {
    throw InputError(c.file.string() + ": `static`: " + e.what());
  }
  const mesh::Mesh& m = model.mesh;

  std::ostringstream csv;
  csv << "pair,high_node,low_node,x_m,y_m,z_m,area_m2,state,gap_m,normal_load_n,tangential_load_n,pressure_pa\n";
  double tangential = 0.0, max_gap = 0.0, max_pressure = 0.0;
  Eigen::MatrixXd pressure = Eigen::MatrixXd::Zero(m.n_nodes(), 1),
                  state = Eigen::MatrixXd::Constant(m.n_nodes(), 1, -1.0);
  for (std::size_t i = 0; i < st.face.size(); ++i) {
    const auto& f = st.face[i];
    const auto& r = st.results[i];
    const double t = r.force.head<2>().norm(), p = r.force[2] / f.area;
    tangential += t;
    max_gap = std::max(max_gap, r.gap);
    max_pressure = std::max(max_pressure, p);
    csv << i << ',' << f.high << ',' << f.low;
    for (int k = 0; k < 3; ++k) csv << ',' << io::format_number(m.nodes(f.high, k));
    csv << ',' << io::format_number(f.area) << ',' << contact::to_string(r.state) << ',' << io::format_number(r.gap)
        << ',' << io::format_number(r.force[2]) << ',' << io::format_number(t) << ',' << io::format_number(p) << '\n';
    for (int node : {f.high, f.low}) {
      pressure(node, 0) = p;
      state(node, 0) = static_cast<double>(r.state);
    }
  }
  io::write_file_atomic(ctx.out_dir / "static_contact.csv", csv.str());

  Eigen::MatrixXd disp(m.n_nodes(), 3);
  for (int n = 0; n < m.n_nodes(); ++n) disp.row(n) = st.displacement.segment<3>(3 * n).transpose();
  const Eigen::VectorXd vm = fe::nodal_von_mises(m, model.material, st.displacement);
  const fe::PeakStress peak = fe::peak_von_mises(m, model.material, st.displacement);
  io::write_point_fields_vtu(ctx.out_dir / "contact_static.vtu", m,
                             {{"displacement_m", disp},
                              {"von_mises_pa", Eigen::MatrixXd(vm)},
                              {"contact_pressure_pa", pressure},
                              {"contact_state", state}});

  const int open = st.count(contact::StaticState::open), stick = st.count(contact::StaticState::stick),
            slip = st.count(contact::StaticState::slip);
  auto& j = ctx.report.section("static");
  j = {{"speed_rpm", speed},
       {"interference_m", c.contact.interference},
       {"increments", st.increments},
       {"newton_iterations", st.newton_iterations},
       {"pairs", st.face.size()},
       {"open", open},
       {"stick", stick},
       {"slip", slip},
       {"normal_load_n", st.normal_load()},
       {"tangential_load_n", tangential},
       {"max_gap_m", max_gap},
       {"max_pressure_pa", max_pressure},
       {"peak_von_mises_pa", peak.von_mises},
       {"peak_von_mises_element", peak.element},
       {"max_displacement_m", st.displacement.cwiseAbs().maxCoeff()},
       {"seconds", st.seconds}};
  ctx.report.stage("static", clock.seconds());
  std::ostringstream s;
  s << "static: " << speed << " rpm, interference " << c.contact.interference << " m: " << st.face.size() << " pairs, "
    << open << " open, " << stick << " stick, " << slip << " slip; normal load " << std::setprecision(4)
    << st.normal_load() << " N, tangential " << tangential << " N; peak von Mises " << peak.von_mises / 1e6 << " MPa ("
    << st.increments << " increments, " << st.newton_iterations << " Newton iterations, " << std::setprecision(3)
    << st.seconds << " s)";
  log::info(s.str());
  draw_plots(ctx);
  return 0;
}

}  // namespace shroudsim::app
