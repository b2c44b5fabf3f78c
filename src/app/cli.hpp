#pragma once
// The `shroudsim` command line (docs/contract.md). Returns the process exit status:
// 0 done, 1 anything else, 2 bad input (usage, case file, mesh), 3 numerics failed.
namespace shroudsim::app {

int run_cli(int argc, char** argv);

}  // namespace shroudsim::app
