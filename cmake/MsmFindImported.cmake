# msm_find_imported(PACKAGE TARGET HEADER LIBRARY): the Find module of a C library that ships no
# CMake configuration: finds its header and library, reports PACKAGE found or not, and defines the
# imported target TARGET. The cache variables are <PACKAGE in upper case>_INCLUDE_DIR and _LIBRARY.
macro(msm_find_imported package target header library)
  string(TOUPPER ${package} _msm_prefix)
  find_path(${_msm_prefix}_INCLUDE_DIR ${header})
  find_library(${_msm_prefix}_LIBRARY NAMES ${library})
  include(FindPackageHandleStandardArgs)
  find_package_handle_standard_args(${package} REQUIRED_VARS ${_msm_prefix}_LIBRARY ${_msm_prefix}_INCLUDE_DIR)
  if(${package}_FOUND AND NOT TARGET ${target})
    add_library(${target} UNKNOWN IMPORTED)
    set_target_properties(${target} PROPERTIES IMPORTED_LOCATION ${${_msm_prefix}_LIBRARY}
      INTERFACE_INCLUDE_DIRECTORIES ${${_msm_prefix}_INCLUDE_DIR})
  endif()
endmacro()
