// The program's side of the gmsh module (mesh/gmsh_module.hpp): finds, loads and forwards.
#include <dlfcn.h>

#include <cstdlib>
#include <mutex>
#include <stdexcept>

#include "mesh/gmsh_module.hpp"

#ifndef SHROUDSIM_GMSH_MODULE_BUILD
#define SHROUDSIM_GMSH_MODULE_BUILD ""
#endif
#ifndef SHROUDSIM_INSTALL_LIBDIR
#define SHROUDSIM_INSTALL_LIBDIR "lib"
#endif
#ifndef SHROUDSIM_GMSH_MODULE_INSTALL
#define SHROUDSIM_GMSH_MODULE_INSTALL ""
#endif

namespace shroudsim::mesh {
namespace detail {
namespace {

namespace fs = std::filesystem;
constexpr const char* kModuleFile = "libshroudsim_gmsh.so";
std::mutex path_mutex;
fs::path loaded_path;  // guarded by path_mutex

// The file this code was linked into: the program, or a shared object (the Python module).
fs::path own_object() {
  Dl_info info{};
  if (::dladdr(reinterpret_cast<const void*>(&gmsh_module_candidates), &info) && info.dli_fname &&
      info.dli_fname[0] == '/')
    return info.dli_fname;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path() : exe;
}

const GmshApi& load() {
  std::string tried;
  for (const fs::path& file : gmsh_module_candidates()) {
    std::error_code ec;
    if (!fs::is_regular_file(file, ec)) {
      tried += "\n  " + file.string() + " (absent)";
      continue;
    }
    void* handle = ::dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* why = ::dlerror();
      tried += "\n  " + file.string() + " (" + (why ? why : "cannot be loaded") + ")";
      continue;
    }
    using Entry = const GmshApi* (*)();
    auto entry = reinterpret_cast<Entry>(::dlsym(handle, kGmshApiSymbol));
    const GmshApi* api = entry ? entry() : nullptr;
    if (!api || api->version != kGmshApiVersion || !api->read_sector_mesh || !api->generate_sector_mesh) {
      tried += "\n  " + file.string() + " (not this build's gmsh module)";
      ::dlclose(handle);
      continue;
    }
    {
      const std::lock_guard<std::mutex> lock(path_mutex);
      loaded_path = file;
    }
    return *api;  // the handle stays open for the life of the process
  }
  throw std::runtime_error(std::string("cannot load shroudsim's gmsh module (") + kModuleFile +
                           "), which reads and generates meshes; looked at:" + tried +
                           "\nRebuild, or set SHROUDSIM_GMSH_MODULE to its path.");
}

}  // namespace

std::vector<fs::path> gmsh_module_candidates() {
  std::vector<fs::path> out;
  if (const char* env = std::getenv("SHROUDSIM_GMSH_MODULE"); env && *env) out.emplace_back(env);
  const fs::path self = own_object();
  if (!self.empty()) {
    out.push_back(self.parent_path() / kModuleFile);
    out.push_back(self.parent_path().parent_path() / SHROUDSIM_INSTALL_LIBDIR / "shroudsim" / kModuleFile);
  }
  if (*SHROUDSIM_GMSH_MODULE_BUILD) out.emplace_back(SHROUDSIM_GMSH_MODULE_BUILD);
  if (*SHROUDSIM_GMSH_MODULE_INSTALL) out.emplace_back(SHROUDSIM_GMSH_MODULE_INSTALL);
  return out;
}

const GmshApi& gmsh_api() {
  static const GmshApi& api = load();  // thread-safe; a failure throws and is retried next call
  return api;
}

fs::path gmsh_module_path() {
  const std::lock_guard<std::mutex> lock(path_mutex);
  return loaded_path;
}

}  // namespace detail

Mesh read_sector_mesh(const std::filesystem::path& file, const ReadOptions& options) {
  return detail::gmsh_api().read_sector_mesh(file, options);
}

GenerateReport generate_sector_mesh(const SectorGeometry& geometry, const std::filesystem::path& file, bool verbose) {
  return detail::gmsh_api().generate_sector_mesh(geometry, file, verbose);
}

}  // namespace shroudsim::mesh
