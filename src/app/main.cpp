// shroudsim: friction damping of shrouded bladed disks. See README.md.
#include <exception>
#include <iostream>

#include "app/cli.hpp"
#include "core/allocator.hpp"
#include "distributed/task_pool.hpp"

int main(int argc, char** argv) {
  shroudsim::core::configure_allocator();  // before any thread exists
  // MPI_Init under an MPI launcher (`mpirun -n K shroudsim study`), MPI_Finalize at the end.
  shroudsim::distributed::Session mpi(&argc, &argv);
  try {
    return shroudsim::app::run_cli(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "shroudsim: error: " << e.what() << "\n";
    return 1;
  } catch (...) {
    std::cerr << "shroudsim: error: unknown failure\n";
    return 1;
  }
}
