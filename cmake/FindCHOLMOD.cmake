# CHOLMOD from SuiteSparse 5.x (Debian libsuitesparse-dev), which ships no CMake config.
# Defines the imported target SuiteSparse::CHOLMOD (with its SuiteSparse dependencies).
find_path(CHOLMOD_INCLUDE_DIR NAMES cholmod.h PATH_SUFFIXES suitesparse)
find_library(CHOLMOD_LIBRARY NAMES cholmod)
find_library(SUITESPARSE_CONFIG_LIBRARY NAMES suitesparseconfig)
foreach(lib amd camd colamd ccolamd)
  string(TOUPPER ${lib} LIB)
  find_library(${LIB}_LIBRARY NAMES ${lib})
endforeach()
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(CHOLMOD
  REQUIRED_VARS CHOLMOD_LIBRARY CHOLMOD_INCLUDE_DIR SUITESPARSE_CONFIG_LIBRARY AMD_LIBRARY COLAMD_LIBRARY)
if(CHOLMOD_FOUND AND NOT TARGET SuiteSparse::CHOLMOD)
  add_library(SuiteSparse::CHOLMOD UNKNOWN IMPORTED)
  set(_deps ${AMD_LIBRARY} ${COLAMD_LIBRARY} ${SUITESPARSE_CONFIG_LIBRARY})
  if(CAMD_LIBRARY)
    list(APPEND _deps ${CAMD_LIBRARY})
  endif()
  if(CCOLAMD_LIBRARY)
    list(APPEND _deps ${CCOLAMD_LIBRARY})
  endif()
  set_target_properties(SuiteSparse::CHOLMOD PROPERTIES
    IMPORTED_LOCATION "${CHOLMOD_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${CHOLMOD_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "${_deps}")
endif()
mark_as_advanced(CHOLMOD_INCLUDE_DIR CHOLMOD_LIBRARY SUITESPARSE_CONFIG_LIBRARY)
