#pragma once
// A coarse generated sector (default geometry, mesh_size 0.03 m) with its assembled K, M and
// cyclic reduction: the small FE model the frf and forced tests build on.
#include <unistd.h>

#include <filesystem>
#include <memory>
#include <string>

#include "cyclic/cyclic_sector.hpp"
#include "fe/assembly.hpp"
#include "mesh/msh_reader.hpp"
#include "mesh/sector_generator.hpp"

namespace shroudsim::testing_support {

struct CoarseSector {
  mesh::Mesh mesh;
  linalg::SparsePair<double> km;
  std::unique_ptr<cyclic::CyclicSector> sector;

  /// tag names the temporary mesh file (with the process id: tests run in parallel).
  explicit CoarseSector(const std::string& tag, int element_order = 1, double mesh_size = 0.03) {
    mesh::SectorGeometry g;
    g.element_order = element_order;
    g.mesh_size = mesh_size;
    const auto file =
        std::filesystem::temp_directory_path() / ("shroudsim_" + tag + "_" + std::to_string(::getpid()) + ".msh");
    mesh::generate_sector_mesh(g, file, false);
    mesh = mesh::read_sector_mesh(file, {g.sectors, 1e-9});
    std::filesystem::remove(file);
    km = fe::assemble(mesh, fe::Material{});
    sector = std::make_unique<cyclic::CyclicSector>(mesh, km);
  }
};

}  // namespace shroudsim::testing_support
