#pragma once
// Content hashes for caching FE results on disk: equal inputs give equal fingerprints on
// every run and machine of the same byte order (FNV-1a, 64 bit, over the raw values).
#include <cstdint>
#include <string>
#include <type_traits>

#include "fe/tet_element.hpp"
#include "mesh/mesh.hpp"

namespace shroudsim::fe {

class Hasher {
 public:
  void add_bytes(const void* data, std::size_t size);
  template <typename T>
  requires std::is_trivially_copyable_v<T>
  void add(const T& value) { add_bytes(&value, sizeof(T)); }
  void add(const std::string& s) {
    add(s.size());
    add_bytes(s.data(), s.size());
  }
  std::uint64_t value() const { return state_; }
  /// 16 lowercase hex digits.
  std::string hex() const;

 private:
  std::uint64_t state_ = 14695981039346656037ull;
};

/// Everything of the mesh that FE and cyclic results depend on: nodes, elements, order,
/// sectors, node sets, cyclic pairs.
void hash_into(Hasher& h, const mesh::Mesh& mesh);
void hash_into(Hasher& h, const Material& material);

}  // namespace shroudsim::fe
