#pragma once
// On-disk cache of modal bases and of read meshes (binary, this machine's byte order). K and M are not cached:
// assembling them is faster than reading them back (modal/modal_stage.hpp).
// A file holds a magic tag (kind and format version), the key it was written under, the
// payload and a 64-bit checksum (FNV-1a) of all of that. A file that does not match (other
// kind or version, another key, truncated, any changed byte, non-finite modes) is never
// used: load_* returns nullopt and names the problem, and the caller recomputes and
// overwrites it. Writes go to a temporary file renamed into place, so an interrupted run
// leaves no partial entry. Keys (also the file names) are built by the caller from
// fe::Hasher fingerprints of everything the entry depends on.
#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "linalg/sparse.hpp"
#include "mesh/mesh.hpp"
#include "modal/eigensolver.hpp"

namespace shroudsim::modal {

/// problem (optional): set when the file exists but cannot be used (left empty when absent).
void save_basis(const std::filesystem::path& path, const std::string& key, const ModalBasis& basis);
std::optional<ModalBasis> load_basis(const std::filesystem::path& path, const std::string& key,
                                     std::string* problem = nullptr);

/// A mesh as read and checked from a .msh file (pipeline/mesh_stage.cpp keys it by the
/// file's bytes and the read options): reading it back needs no gmsh.
void save_mesh(const std::filesystem::path& path, const std::string& key, const mesh::Mesh& mesh);
std::optional<mesh::Mesh> load_mesh(const std::filesystem::path& path, const std::string& key,
                                    std::string* problem = nullptr);

/// Real vectors and complex matrices, each with an integer tag (the forced response's
/// receptance data, pipeline/forced_model.cpp, docs/contract.md frf_model.receptances).
struct TaggedArrays {
  std::vector<std::int64_t> tags;
  std::vector<Eigen::VectorXd> vectors;
  std::vector<Eigen::MatrixXcd> matrices;
};
void save_arrays(const std::filesystem::path& path, const std::string& key, const TaggedArrays& arrays);
/// nullopt (with a problem) also when any value is not finite.
std::optional<TaggedArrays> load_arrays(const std::filesystem::path& path, const std::string& key,
                                        std::string* problem = nullptr);

/// The bound on a cache folder's entries (files named <kind>-<hex key>.bin): after an entry is
/// written, the least recently used of its folder's entries (used: written or read with its
/// key) are deleted until they total at most this many bytes; the entry just written is kept
/// even when it alone is larger. Temporary files of an interrupted write older than an hour
/// go too. Process-wide: the command line's --cache-limit (docs/contract.md), default
/// kDefaultCacheLimitBytes.
constexpr std::uintmax_t kDefaultCacheLimitBytes = 10ull << 30;
void set_cache_limit(std::uintmax_t bytes);
std::uintmax_t cache_limit();
/// Trims `dir` to `limit` bytes of entries as above, never deleting `keep`; returns the
/// number of entries deleted. A file another process deletes meanwhile is skipped.
int trim_cache(const std::filesystem::path& dir, std::uintmax_t limit, const std::filesystem::path& keep);

}  // namespace shroudsim::modal
