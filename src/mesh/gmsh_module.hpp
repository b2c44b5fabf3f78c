#pragma once
// gmsh, loaded when a command first needs it. Everything that calls the gmsh API (the .msh
// reader, the sector generator) is built into a module of its own, libshroudsim_gmsh.so,
// and dlopen()ed on the first read or generation. gmsh's dependency closure (OpenCASCADE,
// FLTK, X11: about 100 shared libraries) took 0.15 s of relocations at every start of the
// program, also in the commands and runs that never touch gmsh (a mesh read from the mesh
// cache, a lumped model, --version); see BENCHMARKS.md "Start-up".
//
// read_sector_mesh() and generate_sector_mesh() (msh_reader.hpp, sector_generator.hpp) are
// the interface; they forward to the module. Where the module is looked for, first found
// wins:
//   1. $SHROUDSIM_GMSH_MODULE (a path to the file);
//   2. beside the program (or the Python module) that calls it, then in
//      <its folder>/../<libdir>/shroudsim (an installed copy, also when moved);
//   3. the build tree it was built in;
//   4. <prefix>/lib/shroudsim of `cmake --install`.
// A module that cannot be found or loaded is an installation fault (std::runtime_error
// naming every place looked at).
#include <filesystem>
#include <string>
#include <vector>

#include "mesh/msh_reader.hpp"
#include "mesh/sector_generator.hpp"

namespace shroudsim::mesh::detail {

/// The module's entry points (one table, versioned: a module of another build is refused).
struct GmshApi {
  int version = 0;
  Mesh (*read_sector_mesh)(const std::filesystem::path& file, const ReadOptions& options) = nullptr;
  GenerateReport (*generate_sector_mesh)(const SectorGeometry& geometry, const std::filesystem::path& file,
                                         bool verbose) = nullptr;
};
inline constexpr int kGmshApiVersion = 1;
/// The exported symbol of the module: extern "C" const GmshApi* shroudsim_gmsh_api().
inline constexpr const char* kGmshApiSymbol = "shroudsim_gmsh_api";

/// The loaded module's table (loads it on the first call; thread-safe).
const GmshApi& gmsh_api();
/// The files the loader tries, in the order above (its error message lists them).
std::vector<std::filesystem::path> gmsh_module_candidates();
/// The module file loaded in this process (empty: not loaded, no gmsh was needed yet).
std::filesystem::path gmsh_module_path();

}  // namespace shroudsim::mesh::detail
