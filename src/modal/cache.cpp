#include "modal/cache.hpp"

#include <cstdint>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "core/error.hpp"

namespace shroudsim::modal {
namespace {

constexpr std::uint64_t kMagicBasis = 0x32534142444f4d53ull;  // "SMODBAS2": key and checksum

// Largest cache file read (50 modes of a 240k-DOF sector are about 0.2 GB).
constexpr std::uintmax_t kMaxCacheBytes = 8ull << 30;

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
  return in;
}

}  // namespace

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

}  // namespace shroudsim::modal
