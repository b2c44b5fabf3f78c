#include "modal/cache.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <random>
#include <sstream>
#include <string>
#include <tuple>

#include "core/error.hpp"
#include "core/log.hpp"

namespace shroudsim::modal {
namespace {

constexpr std::uint64_t kMagicBasis = 0x32534142444f4d53ull;   // "SMODBAS2": key and checksum
constexpr std::uint64_t kMagicMesh = 0x3248534548534d53ull;    // "SMSHESH2" (version digit last)
constexpr std::uint64_t kMagicArrays = 0x3253594152524153ull;  // "SARRAYS2"

// Largest cache file read (50 modes of a 240k-DOF sector are about 0.2 GB).
constexpr std::uintmax_t kMaxCacheBytes = 8ull << 30;

std::atomic<std::uintmax_t> g_cache_limit{kDefaultCacheLimitBytes};

// <kind>-<hex>.bin, kind lowercase letters: what the stages write (mesh-, modes-,
// receptances-); any other file in the folder is not the cache's to delete.
bool is_entry_name(const std::string& name) {
  const auto dash = name.find('-');
  if (dash == std::string::npos || dash == 0 || name.size() < dash + 6 || !name.ends_with(".bin")) return false;
  for (std::size_t i = 0; i < dash; ++i)
    if (name[i] < 'a' || name[i] > 'z') return false;
  for (std::size_t i = dash + 1; i < name.size() - 4; ++i)
    if (!std::isxdigit(static_cast<unsigned char>(name[i]))) return false;
  return true;
}

// A temporary file of write_atomic: <entry name>.tmp<digits>.
bool is_temporary_name(const std::string& name) {
  const auto at = name.find(".bin.tmp");
  return at != std::string::npos && is_entry_name(name.substr(0, at + 4));
}

// FNV-1a, 64 bit, over the whole entry before the checksum.
std::uint64_t checksum(const char* data, std::size_t n) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (std::size_t i = 0; i < n; ++i) {
    h ^= static_cast<unsigned char>(data[i]);
    h *= 0x100000001b3ull;
  }
  return h;
}

template <typename T>
void put(std::ostream& out, const T& v) {
  out.write(reinterpret_cast<const char*>(&v), sizeof(T));
}
template <typename T>
void put_array(std::ostream& out, const T* data, std::int64_t count) {
  put(out, count);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(sizeof(T) * count));
}
template <typename T>
bool get(std::istream& in, T& v) {
  return static_cast<bool>(in.read(reinterpret_cast<char*>(&v), sizeof(T)));
}
template <typename T>
bool get_array(std::istream& in, T* data, std::int64_t expected) {
  std::int64_t count = 0;
  if (!get(in, count) || count != expected) return false;
  return static_cast<bool>(in.read(reinterpret_cast<char*>(data), static_cast<std::streamsize>(sizeof(T) * count)));
}

// An entry: magic, the key it was written under (length-prefixed), the payload, and the
// checksum of all of that.
template <typename Writer>
void write_atomic(const std::filesystem::path& path, std::uint64_t magic, const std::string& key, Writer&& writer) {
  std::ostringstream body(std::ios::binary);
  put(body, magic);
  put<std::int64_t>(body, static_cast<std::int64_t>(key.size()));
  body.write(key.data(), static_cast<std::streamsize>(key.size()));
  writer(body);
  const std::string bytes = body.str();
  const std::uint64_t sum = checksum(bytes.data(), bytes.size());
  std::filesystem::create_directories(path.parent_path());
  std::random_device rd;
  const auto tmp = path.string() + ".tmp" + std::to_string(rd());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("cannot write cache file " + tmp);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    put(out, sum);
    out.flush();
    if (!out) throw std::runtime_error("cannot write cache file " + tmp);
  }
  std::filesystem::rename(tmp, path);
  trim_cache(path.parent_path(), g_cache_limit.load(), path);
}

// Reads an entry; on success `in` is positioned at the payload. Absent: nullopt without a
// problem; present but unusable: nullopt and `problem` says why.
std::optional<std::istringstream> read_entry(const std::filesystem::path& path, std::uint64_t magic,
                                             const std::string& key, std::string* problem) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return std::nullopt;
  auto fail = [&](const std::string& why) -> std::optional<std::istringstream> {
    if (problem) *problem = why;
    return std::nullopt;
  };
  if (!std::filesystem::is_regular_file(path, ec)) return fail("not a regular file");
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec || size > kMaxCacheBytes) return fail("unreadable or too large");
  if (size < 2 * sizeof(std::uint64_t) + sizeof(std::int64_t)) return fail("truncated");
  std::string bytes(size, '\0');
  {
    std::ifstream in(path, std::ios::binary);
    if (!in.read(bytes.data(), static_cast<std::streamsize>(size))) return fail("unreadable");
  }
  // An entry of an earlier format (same kind, version 1: no key, no checksum) is simply
  // absent to this version; a file of another kind is reported.
  std::uint64_t head = 0;
  std::memcpy(&head, bytes.data(), sizeof head);
  if (head == (magic & ~(0xffull << 56)) + (static_cast<std::uint64_t>('1') << 56)) return std::nullopt;
  if (head != magic) return fail("not a cache entry of this kind");
  std::uint64_t stored = 0;
  std::memcpy(&stored, bytes.data() + size - sizeof stored, sizeof stored);
  bytes.resize(size - sizeof stored);
  if (checksum(bytes.data(), bytes.size()) != stored)
    return fail("checksum mismatch (the file was changed or truncated)");
  std::istringstream in(std::move(bytes), std::ios::binary);
  std::uint64_t m = 0;
  std::int64_t n = 0;
  if (!get(in, m) || m != magic) return fail("not an entry of this kind or version");
  if (!get(in, n) || n != static_cast<std::int64_t>(key.size())) return fail("written under another key");
  std::string k(key.size(), '\0');
  if (!in.read(k.data(), static_cast<std::streamsize>(k.size())) || k != key) return fail("written under another key");
  // Used now: the last an entry is trimmed (trim_cache goes by the modification time).
  std::filesystem::last_write_time(path, std::filesystem::file_time_type::clock::now(), ec);
  return in;
}

template <typename Matrix>
void put_matrix(std::ostream& out, const Matrix& m) {
  put<std::int64_t>(out, m.rows());
  put<std::int64_t>(out, m.cols());
  out.write(reinterpret_cast<const char*>(m.data()), static_cast<std::streamsize>(sizeof(*m.data()) * m.size()));
}
template <typename Matrix>
bool get_matrix(std::istream& in, Matrix& m, std::int64_t max_entries) {
  std::int64_t rows = 0, cols = 0;
  if (!get(in, rows) || !get(in, cols) || rows < 0 || cols < 0) return false;
  if (Matrix::ColsAtCompileTime != Eigen::Dynamic && cols != Matrix::ColsAtCompileTime) return false;
  if (cols > 0 && rows > max_entries / cols) return false;
  m.resize(rows, cols);
  return static_cast<bool>(
      in.read(reinterpret_cast<char*>(m.data()), static_cast<std::streamsize>(sizeof(*m.data()) * m.size())));
}
void put_string(std::ostream& out, const std::string& s) {
  put<std::int64_t>(out, static_cast<std::int64_t>(s.size()));
  out.write(s.data(), static_cast<std::streamsize>(s.size()));
}
bool get_string(std::istream& in, std::string& s) {
  std::int64_t n = 0;
  if (!get(in, n) || n < 0 || n > 4096) return false;
  s.assign(static_cast<std::size_t>(n), '\0');
  return static_cast<bool>(in.read(s.data(), n));
}
void put_pairs(std::ostream& out, const std::vector<std::pair<int, int>>& v) {
  put<std::int64_t>(out, static_cast<std::int64_t>(v.size()));
  for (const auto& [a, b] : v) {
    put<std::int32_t>(out, a);
    put<std::int32_t>(out, b);
  }
}
bool get_pairs(std::istream& in, std::vector<std::pair<int, int>>& v, std::int64_t max_count) {
  std::int64_t n = 0;
  if (!get(in, n) || n < 0 || n > max_count) return false;
  v.resize(static_cast<std::size_t>(n));
  for (auto& [a, b] : v) {
    std::int32_t x = 0, y = 0;
    if (!get(in, x) || !get(in, y)) return false;
    a = x;
    b = y;
  }
  return true;
}

}  // namespace

void save_mesh(const std::filesystem::path& path, const std::string& key, const mesh::Mesh& m) {
  write_atomic(path, kMagicMesh, key, [&](std::ostream& out) {
    put<std::int32_t>(out, m.element_order);
    put<std::int32_t>(out, m.sectors);
    put_matrix(out, m.nodes);
    put_matrix(out, m.tets);
    put<std::int64_t>(out, static_cast<std::int64_t>(m.node_sets.size()));
    for (const auto& [name, nodes] : m.node_sets) {
      put_string(out, name);
      put_array(out, nodes.data(), static_cast<std::int64_t>(nodes.size()));
    }
    put<std::int64_t>(out, static_cast<std::int64_t>(m.surface_triangles.size()));
    for (const auto& [name, tri] : m.surface_triangles) {
      put_string(out, name);
      put_matrix(out, tri);
    }
    put_pairs(out, m.cyclic_pairs);
    put_pairs(out, m.shroud_pairs);
  });
}

std::optional<mesh::Mesh> load_mesh(const std::filesystem::path& path, const std::string& key, std::string* problem) {
  auto in = read_entry(path, kMagicMesh, key, problem);
  if (!in) return std::nullopt;
  auto bad = [&]() -> std::optional<mesh::Mesh> {
    if (problem) *problem = "malformed payload";
    return std::nullopt;
  };
  constexpr std::int64_t kMaxEntries = std::int64_t{1} << 34;  // bounded by kMaxCacheBytes anyway
  constexpr std::int64_t kMaxGroups = 64;
  mesh::Mesh m;
  std::int32_t order = 0, sectors = 0;
  if (!get(*in, order) || !get(*in, sectors) || (order != 1 && order != 2) || sectors < 1) return bad();
  m.element_order = order;
  m.sectors = sectors;
  if (!get_matrix(*in, m.nodes, kMaxEntries) || !m.nodes.allFinite()) return bad();
  if (!get_matrix(*in, m.tets, kMaxEntries) || m.tets.cols() != (order == 1 ? 4 : 10)) return bad();
  const int n = m.n_nodes();
  auto in_range = [n](const auto& v) { return v.size() == 0 || (v.minCoeff() >= 0 && v.maxCoeff() < n); };
  if (!in_range(m.tets.reshaped())) return bad();
  std::int64_t groups = 0;
  if (!get(*in, groups) || groups < 0 || groups > kMaxGroups) return bad();
  for (std::int64_t g = 0; g < groups; ++g) {
    std::string name;
    std::int64_t count = 0;
    if (!get_string(*in, name) || !get(*in, count) || count < 0 || count > n) return bad();
    std::vector<int> nodes(static_cast<std::size_t>(count));
    if (!in->read(reinterpret_cast<char*>(nodes.data()), static_cast<std::streamsize>(sizeof(int) * count)))
      return bad();
    if (!in_range(Eigen::Map<const Eigen::VectorXi>(nodes.data(), count))) return bad();
    m.node_sets[name] = std::move(nodes);
  }
  if (!get(*in, groups) || groups < 0 || groups > kMaxGroups) return bad();
  for (std::int64_t g = 0; g < groups; ++g) {
    std::string name;
    mesh::ConnectivityMatrix tri;
    if (!get_string(*in, name) || !get_matrix(*in, tri, kMaxEntries) || !in_range(tri.reshaped())) return bad();
    m.surface_triangles[name] = std::move(tri);
  }
  if (!get_pairs(*in, m.cyclic_pairs, n) || !get_pairs(*in, m.shroud_pairs, n)) return bad();
  for (const auto* pairs : {&m.cyclic_pairs, &m.shroud_pairs})
    for (const auto& [p, q] : *pairs)
      if (p < 0 || p >= n || q < 0 || q >= n) return bad();
  if (in->peek() != std::char_traits<char>::eof()) return bad();
  return m;
}

void save_basis(const std::filesystem::path& path, const std::string& key, const ModalBasis& basis) {
  write_atomic(path, kMagicBasis, key, [&](std::ostream& out) {
    put<std::int64_t>(out, basis.harmonic_index);
    put<std::int64_t>(out, basis.phi.rows());
    put_array(out, basis.omega.data(), basis.omega.size());
    put_array(out, basis.phi.data(), basis.phi.size());
  });
}

std::optional<ModalBasis> load_basis(const std::filesystem::path& path, const std::string& key, std::string* problem) {
  auto in = read_entry(path, kMagicBasis, key, problem);
  if (!in) return std::nullopt;
  auto bad = [&]() -> std::optional<ModalBasis> {
    if (problem) *problem = "malformed payload";
    return std::nullopt;
  };
  std::int64_t h = 0, rows = 0, count = 0;
  if (!get(*in, h) || !get(*in, rows) || rows < 0) return bad();
  if (!get(*in, count) || count < 0 || count > (1 << 20)) return bad();
  ModalBasis b;
  b.harmonic_index = static_cast<int>(h);
  b.omega.resize(count);
  if (!in->read(reinterpret_cast<char*>(b.omega.data()), static_cast<std::streamsize>(sizeof(double) * count)))
    return bad();
  b.phi.resize(rows, count);
  if (!get_array(*in, b.phi.data(), rows * count)) return bad();
  if (!b.omega.allFinite() || !b.phi.allFinite()) return bad();
  return b;
}

void save_arrays(const std::filesystem::path& path, const std::string& key, const TaggedArrays& arrays) {
  write_atomic(path, kMagicArrays, key, [&](std::ostream& out) {
    put<std::int64_t>(out, static_cast<std::int64_t>(arrays.tags.size()));
    put_array(out, arrays.tags.data(), static_cast<std::int64_t>(arrays.tags.size()));
    put<std::int64_t>(out, static_cast<std::int64_t>(arrays.vectors.size()));
    for (const auto& v : arrays.vectors) put_matrix(out, v);
    put<std::int64_t>(out, static_cast<std::int64_t>(arrays.matrices.size()));
    for (const auto& m : arrays.matrices) put_matrix(out, m);
  });
}

std::optional<TaggedArrays> load_arrays(const std::filesystem::path& path, const std::string& key,
                                        std::string* problem) {
  auto in = read_entry(path, kMagicArrays, key, problem);
  if (!in) return std::nullopt;
  auto bad = [&]() -> std::optional<TaggedArrays> {
    if (problem) *problem = "malformed payload";
    return std::nullopt;
  };
  constexpr std::int64_t kMaxCount = 1 << 20, kMaxEntries = std::int64_t{1} << 32;
  TaggedArrays a;
  std::int64_t n = 0;
  if (!get(*in, n) || n < 0 || n > kMaxCount) return bad();
  a.tags.resize(static_cast<std::size_t>(n));
  if (!get_array(*in, a.tags.data(), n)) return bad();
  if (!get(*in, n) || n < 0 || n > kMaxCount) return bad();
  a.vectors.resize(static_cast<std::size_t>(n));
  for (auto& v : a.vectors)
    if (!get_matrix(*in, v, kMaxEntries) || !v.allFinite()) return bad();
  if (!get(*in, n) || n < 0 || n > kMaxCount) return bad();
  a.matrices.resize(static_cast<std::size_t>(n));
  for (auto& m : a.matrices)
    if (!get_matrix(*in, m, kMaxEntries) || !m.allFinite()) return bad();
  return a;
}

void set_cache_limit(std::uintmax_t bytes) { g_cache_limit.store(bytes); }

std::uintmax_t cache_limit() { return g_cache_limit.load(); }

int trim_cache(const std::filesystem::path& dir, std::uintmax_t limit, const std::filesystem::path& keep) {
  namespace fs = std::filesystem;
  using Entry = std::tuple<fs::file_time_type, fs::path, std::uintmax_t>;
  std::vector<Entry> entries;
  std::uintmax_t total = 0;
  std::error_code ec;
  const auto now = fs::file_time_type::clock::now();
  int deleted = 0;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    std::error_code e;
    if (!it->is_regular_file(e) || e) continue;
    const auto time = it->last_write_time(e);
    if (e) continue;
    if (is_temporary_name(name)) {  // an interrupted write's leftover
      if (now - time > std::chrono::hours(1) && fs::remove(it->path(), e)) ++deleted;
      continue;
    }
    if (!is_entry_name(name)) continue;
    const std::uintmax_t size = it->file_size(e);
    if (e) continue;
    total += size;
    if (!fs::equivalent(it->path(), keep, e)) entries.emplace_back(time, it->path(), size);
  }
  if (total <= limit) return deleted;
  std::sort(entries.begin(), entries.end());  // least recently used first
  std::uintmax_t freed = 0;
  int evicted = 0;
  for (const auto& [time, path, size] : entries) {
    if (total <= limit) break;
    std::error_code e;
    if (fs::remove(path, e)) {
      ++evicted;
      freed += size;
    }
    total -= size;  // gone either way (another process may have deleted it)
  }
  if (evicted > 0) {
    std::ostringstream m;
    m << std::setprecision(3) << "cache: deleted the " << evicted << " least recently used "
      << (evicted == 1 ? "entry" : "entries") << " of " << dir.string() << " ("
      << static_cast<double>(freed) / (1 << 20) << " MiB) to keep it within " << static_cast<double>(limit) / (1 << 20)
      << " MiB (--cache-limit)";
    log::info(m.str());
  }
  return deleted + evicted;
}

}  // namespace shroudsim::modal
