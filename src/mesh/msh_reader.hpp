#pragma once
// Reading a sector mesh (.msh, any version gmsh reads) and checking it against the
// conventions of mesh.hpp. Every failure is an InputError naming the file.
#include <filesystem>

#include "mesh/mesh.hpp"

namespace shroudsim::mesh {

struct ReadOptions {
  int sectors = 8;                ///< Nb: the rotation is 2*pi/sectors about z
  double match_tolerance = 1e-6;  ///< relative to the model size (bounding-box diagonal)
};

/// Reads and checks: the 2D physical groups hub, cyclic_low, cyclic_high, shroud_low,
/// shroud_high are present and non-empty; the 3D elements are tetrahedra of one order
/// (4 or 10 nodes; group "sector" if present, else every 3D element); cyclic and shroud
/// nodes match under the rotation within the tolerance (the worst pair is reported
/// otherwise); no element is inverted or degenerate.
/// The reader's version, part of the key under which pipeline/mesh_stage.cpp caches what it
/// read: change it whenever read_sector_mesh can give another Mesh for the same file and options.
inline constexpr const char* kReaderVersion = "msh-reader-1";

Mesh read_sector_mesh(const std::filesystem::path& file, const ReadOptions& options);

}  // namespace shroudsim::mesh
