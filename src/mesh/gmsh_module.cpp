// The entry point of libshroudsim_gmsh.so (mesh/gmsh_module.hpp). Built with hidden
// visibility: only shroudsim_gmsh_api() is exported, and the module's own copies of the
// reader (msh_reader.cpp), the generator (sector_generator.cpp) and the mesh checks bind
// inside it.
#include "mesh/gmsh_module.hpp"

extern "C" __attribute__((visibility("default"))) const shroudsim::mesh::detail::GmshApi* shroudsim_gmsh_api() {
  static const shroudsim::mesh::detail::GmshApi api{shroudsim::mesh::detail::kGmshApiVersion,
                                                    &shroudsim::mesh::read_sector_mesh,
                                                    &shroudsim::mesh::generate_sector_mesh};
  return &api;
}
