# Spectra 1.0.1 as packaged by Debian (libspectra-dev) ships headers only, no CMake config.
# Defines the imported target Spectra::Spectra.
find_path(Spectra_INCLUDE_DIR NAMES Spectra/SymEigsShiftSolver.h)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(Spectra REQUIRED_VARS Spectra_INCLUDE_DIR)
if(Spectra_FOUND AND NOT TARGET Spectra::Spectra)
  add_library(Spectra::Spectra INTERFACE IMPORTED)
  set_target_properties(Spectra::Spectra PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${Spectra_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES Eigen3::Eigen)
endif()
mark_as_advanced(Spectra_INCLUDE_DIR)
