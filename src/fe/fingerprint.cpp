#include "fe/fingerprint.hpp"

#include <cstdio>

namespace shroudsim::fe {

void Hasher::add_bytes(const void* data, std::size_t size) {
  const auto* p = static_cast<const unsigned char*>(data);
  std::uint64_t s = state_;
  for (std::size_t i = 0; i < size; ++i) {
    s ^= p[i];
    s *= 1099511628211ull;
  }
  state_ = s;
}

std::string Hasher::hex() const {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(state_));
  return buf;
}

void hash_into(Hasher& h, const mesh::Mesh& mesh) {
  h.add(std::string("mesh/v1"));
  h.add(mesh.nodes.rows());
  h.add_bytes(mesh.nodes.data(), sizeof(double) * mesh.nodes.size());
  h.add(mesh.tets.rows());
  h.add(mesh.tets.cols());
  h.add_bytes(mesh.tets.data(), sizeof(int) * mesh.tets.size());
  h.add(mesh.element_order);
  h.add(mesh.sectors);
  for (const auto& [name, set] : mesh.node_sets) {
    h.add(name);
    h.add(set.size());
    h.add_bytes(set.data(), sizeof(int) * set.size());
  }
  h.add(mesh.cyclic_pairs.size());
  for (const auto& [p, q] : mesh.cyclic_pairs) {
    h.add(p);
    h.add(q);
  }
}

void hash_into(Hasher& h, const Material& m) {
  h.add(std::string("material/v1"));
  h.add(m.youngs_modulus);
  h.add(m.poisson_ratio);
  h.add(m.density);
}

}  // namespace shroudsim::fe
