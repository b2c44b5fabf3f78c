#pragma once
// Shapes and contact maps of a traced forced response (docs/contract.md, "Shapes and contact
// maps"; response.shapes, response.shapes_at_hz): at every resonance peak (the sampled
// maximum when none was located) and at each crossing of the frequencies the user lists,
//   contact_map.csv  per shape and pair: normal load range, slip amplitude, stick / slip /
//                    open fractions of the period, energy dissipated per cycle;
// and for a sector
//   frf.vtu          the operating deflection shape of every sector node as complex harmonic
//                    fields (<shape>_u_h<n>_re_m / _im_m) and its amplitude over the period;
//   frf_<shape>.pvd  the shape over one period in kFrames frames (frf_frames/), for ParaView
//                    to animate; frf.pvd: the same for the largest peak;
//   contact.vtu      the contact map on the shroud face nodes (contact_pair = -1 elsewhere).
// The displacements are those about the static state, from the same receptance as the harmonic
// balance (frf::sector_displacements), so their response and contact rows are the curve's.
#include <filesystem>
#include <string>
#include <vector>

#include "forced/frequency_response.hpp"
#include "forced/reduced_equations.hpp"
#include "frf/sector.hpp"
#include "hbm/contact_evaluator.hpp"
#include "io/vtu.hpp"
#include "mesh/mesh.hpp"
#include "pipeline/context.hpp"

namespace shroudsim::pipeline {

/// The sector's displacement harmonics U_n (n = 0..H, every DOF) of each load
/// (frf::sector_displacements), with the modes read again from the stage cache, and the mesh.
/// `what` names the caller in a modal failure's message.
struct SectorShapes {
  mesh::Mesh mesh;
  std::vector<std::vector<Eigen::VectorXcd>> u;
};
SectorShapes sector_shapes(const Context& ctx, const forced::ForcedModel& model,
                           const std::vector<frf::ShapeLoad>& loads, const std::string& what);

/// One shape u (U_n, n = 0..H): its fields for a .vtu appended to `fields`
/// (<name>_u_h<n>_re_m / _im_m, <name>_amplitude_m = max over 512 instants of the period of
/// |u|) and its frames over one period (<out_dir>/<frames_dir>/<name>_tKK.vtu, 24 of them) with
/// the collection <out_dir>/<pvd_file> listing them, for ParaView to animate.
struct ShapeFiles {
  std::string pvd;         ///< the collection's text
  double largest_m = 0.0;  ///< the largest amplitude of any node
};
ShapeFiles write_shape(const std::filesystem::path& out_dir, const mesh::Mesh& mesh,
                       const std::vector<Eigen::VectorXcd>& u, const std::string& name, const std::string& frames_dir,
                       const std::string& pvd_file, std::vector<io::PointField>& fields);

/// Writes the files above into ctx.out_dir (atomically); warnings (a listed frequency the
/// curve does not reach) go to the report. Records the "shapes" stage.
void write_shapes(Context& ctx, const forced::ForcedModel& model, hbm::ContactEvaluator& evaluator,
                  forced::ReducedEquations& equations, const forced::FrequencyResponse& response);

}  // namespace shroudsim::pipeline
