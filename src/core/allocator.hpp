#pragma once
// The heap policy of a process that factors large sparse matrices (the program and the
// benchmarks call it first thing in main, before any thread exists).
//
// The modal stage allocates and frees matrices and factors of 10 to 500 MB per harmonic
// index. glibc serves every block above 32 MB by a fresh mmap and unmaps it on free, so each
// one is paged in again: one page fault per 4 kB, zeroed by the kernel. At 40k DOFs a third
// of `shroudsim modes` was spent in page faults (BENCHMARKS.md, "Against CalculiX"). With
// this policy large blocks come from the heap, stay there after free, and come from one
// arena, so a worker thread reuses what another freed. The price: the process keeps its
// peak heap until it exits. No effect with another C library or under a sanitizer's
// allocator.
namespace shroudsim::core {

void configure_allocator();

}  // namespace shroudsim::core
