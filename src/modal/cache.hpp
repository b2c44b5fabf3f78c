#pragma once
// On-disk cache of FE matrices and modal bases (binary, this machine's byte order).
// A file holds a magic tag, a format version and the payload; a file that does not match
// (other version, truncated, other key) reads as "absent", never as wrong data. Writes go
// to a temporary file renamed into place, so an interrupted run leaves no partial entry.
// Keys (file names) are built by the caller from fe::Hasher fingerprints of everything the
// entry depends on.
#include <filesystem>
#include <optional>

#include "linalg/sparse.hpp"
#include "modal/eigensolver.hpp"

namespace shroudsim::modal {

void save_matrices(const std::filesystem::path& path, const linalg::SparsePair<double>& km);
std::optional<linalg::SparsePair<double>> load_matrices(const std::filesystem::path& path);

void save_basis(const std::filesystem::path& path, const ModalBasis& basis);
std::optional<ModalBasis> load_basis(const std::filesystem::path& path);

}  // namespace shroudsim::modal
