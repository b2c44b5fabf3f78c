#include "modal/cache.hpp"

#include <cstdint>
#include <fstream>
#include <random>
#include <string>

#include "core/error.hpp"

namespace shroudsim::modal {
namespace {

constexpr std::uint64_t kMagicMatrices = 0x31584d4b4d495353ull;  // "SSIMKMX1"
constexpr std::uint64_t kMagicBasis = 0x31534142444f4d53ull;     // "SMODBAS1"

template <typename T>
void put(std::ofstream& out, const T& v) {
  out.write(reinterpret_cast<const char*>(&v), sizeof(T));
}
template <typename T>
void put_array(std::ofstream& out, const T* data, std::int64_t count) {
  put(out, count);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(sizeof(T) * count));
}
template <typename T>
bool get(std::ifstream& in, T& v) {
  return static_cast<bool>(in.read(reinterpret_cast<char*>(&v), sizeof(T)));
}
template <typename T>
bool get_array(std::ifstream& in, T* data, std::int64_t expected) {
  std::int64_t count = 0;
  if (!get(in, count) || count != expected) return false;
  return static_cast<bool>(in.read(reinterpret_cast<char*>(data), static_cast<std::streamsize>(sizeof(T) * count)));
}

template <typename Writer>
void write_atomic(const std::filesystem::path& path, Writer&& writer) {
  std::filesystem::create_directories(path.parent_path());
  std::random_device rd;
  const auto tmp = path.string() + ".tmp" + std::to_string(rd());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("cannot write cache file " + tmp);
    writer(out);
    out.flush();
    if (!out) throw std::runtime_error("cannot write cache file " + tmp);
  }
  std::filesystem::rename(tmp, path);
}

void put_sparse(std::ofstream& out, const linalg::SparseMatrixD& A) {
  SHROUDSIM_CHECK(A.isCompressed(), "cache: sparse matrix must be compressed");
  put<std::int64_t>(out, A.rows());
  put<std::int64_t>(out, A.cols());
  put_array(out, A.outerIndexPtr(), A.cols() + 1);
  put_array(out, A.innerIndexPtr(), A.nonZeros());
  put_array(out, A.valuePtr(), A.nonZeros());
}

bool get_sparse(std::ifstream& in, linalg::SparseMatrixD& A) {
  std::int64_t rows = 0, cols = 0;
  if (!get(in, rows) || !get(in, cols) || rows < 0 || cols < 0 || rows > (1ll << 31) || cols > (1ll << 31))
    return false;
  std::vector<int> outer(cols + 1);
  if (!get_array(in, outer.data(), cols + 1)) return false;
  const std::int64_t nnz = outer.back();
  if (nnz < 0 || outer.front() != 0) return false;
  A.resize(rows, cols);
  A.resizeNonZeros(nnz);
  std::copy(outer.begin(), outer.end(), A.outerIndexPtr());
  return get_array(in, A.innerIndexPtr(), nnz) && get_array(in, A.valuePtr(), nnz);
}

}  // namespace

void save_matrices(const std::filesystem::path& path, const linalg::SparsePair<double>& km) {
  write_atomic(path, [&](std::ofstream& out) {
    put(out, kMagicMatrices);
    put_sparse(out, km.K);
    put_sparse(out, km.M);
  });
}

std::optional<linalg::SparsePair<double>> load_matrices(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::uint64_t magic = 0;
  linalg::SparsePair<double> km;
  if (!get(in, magic) || magic != kMagicMatrices || !get_sparse(in, km.K) || !get_sparse(in, km.M))
    return std::nullopt;
  return km;
}

void save_basis(const std::filesystem::path& path, const ModalBasis& basis) {
  write_atomic(path, [&](std::ofstream& out) {
    put(out, kMagicBasis);
    put<std::int64_t>(out, basis.harmonic_index);
    put<std::int64_t>(out, basis.phi.rows());
    put_array(out, basis.omega.data(), basis.omega.size());
    put_array(out, basis.phi.data(), basis.phi.size());
  });
}

std::optional<ModalBasis> load_basis(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::uint64_t magic = 0;
  std::int64_t h = 0, rows = 0, count = 0;
  if (!get(in, magic) || magic != kMagicBasis || !get(in, h) || !get(in, rows) || rows < 0) return std::nullopt;
  if (!get(in, count) || count < 0 || count > (1 << 20)) return std::nullopt;
  ModalBasis b;
  b.harmonic_index = static_cast<int>(h);
  b.omega.resize(count);
  if (!in.read(reinterpret_cast<char*>(b.omega.data()), static_cast<std::streamsize>(sizeof(double) * count)))
    return std::nullopt;
  b.phi.resize(rows, count);
  if (!get_array(in, b.phi.data(), rows * count)) return std::nullopt;
  return b;
}

}  // namespace shroudsim::modal
