# Installation by component. Each installed library declares, beside its build rules, the
# component it belongs to, the components it needs and the packages its users need (the packages
# of its PUBLIC and, for a static library, PRIVATE links: find_dependency arguments, one string
# each, e.g. "embree 3"):
#   msm_install_library(TARGET COMPONENT name [NEEDS component...] [PACKAGES "package [args]"...])
# msm_install_components() then installs one export file per component and msmConfig.cmake, which
# loads the requested components (and those they need) and finds only their packages:
#   find_package(msm COMPONENTS math)      the shared headers on GLM, nothing else
#   find_package(msm COMPONENTS reference) the ray tracer, with scene and core and their packages
#   find_package(msm)                      every installed component
# The components in the order that each one's needs come before it.
set(MSM_COMPONENT_ORDER math core oracle scene reference render evaluate viewer)

function(msm_install_library target)
  cmake_parse_arguments(ARG "" "COMPONENT" "NEEDS;PACKAGES" ${ARGN})
  if(NOT ARG_COMPONENT IN_LIST MSM_COMPONENT_ORDER)
    message(FATAL_ERROR "msm_install_library(${target}): component '${ARG_COMPONENT}' is not one of "
                        "${MSM_COMPONENT_ORDER}")
  endif()
  foreach(need ${ARG_NEEDS})
    list(FIND MSM_COMPONENT_ORDER ${need} need_index)
    list(FIND MSM_COMPONENT_ORDER ${ARG_COMPONENT} own_index)
    if(need_index EQUAL -1 OR NOT need_index LESS own_index)
      message(FATAL_ERROR "msm_install_library(${target}): '${need}' must be a component before '${ARG_COMPONENT}'")
    endif()
  endforeach()
  install(TARGETS ${target} EXPORT msm_${ARG_COMPONENT}_targets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
  set_property(GLOBAL APPEND PROPERTY MSM_INSTALLED_COMPONENTS ${ARG_COMPONENT})
  set_property(GLOBAL APPEND PROPERTY MSM_COMPONENT_NEEDS_${ARG_COMPONENT} ${ARG_NEEDS})
  set_property(GLOBAL APPEND PROPERTY MSM_COMPONENT_PACKAGES_${ARG_COMPONENT} ${ARG_PACKAGES})
endfunction()

# Installs the export file of every component that has a library and msmConfig.cmake (from
# cmake/msmConfig.cmake.in) with each component's needs and packages written out.
function(msm_install_components)
  set(destination ${CMAKE_INSTALL_LIBDIR}/cmake/msm)
  get_property(installed GLOBAL PROPERTY MSM_INSTALLED_COMPONENTS)
  set(MSM_COMPONENTS "")
  set(MSM_COMPONENT_DECLARATIONS "")
  foreach(component ${MSM_COMPONENT_ORDER})
    if(NOT component IN_LIST installed)
      continue()
    endif()
    list(APPEND MSM_COMPONENTS ${component})
    install(EXPORT msm_${component}_targets NAMESPACE msm:: FILE msm-${component}-targets.cmake
      DESTINATION ${destination})
    get_property(needs GLOBAL PROPERTY MSM_COMPONENT_NEEDS_${component})
    get_property(packages GLOBAL PROPERTY MSM_COMPONENT_PACKAGES_${component})
    list(REMOVE_DUPLICATES needs)
    list(REMOVE_DUPLICATES packages)
    foreach(need ${needs})
      if(NOT need IN_LIST installed)
        message(FATAL_ERROR "the installed component '${component}' needs '${need}', which installs nothing")
      endif()
    endforeach()
    string(APPEND MSM_COMPONENT_DECLARATIONS "set(_msm_needs_${component} ${needs})\n"
      "macro(_msm_find_packages_of_${component})\n")
    foreach(package ${packages})
      string(APPEND MSM_COMPONENT_DECLARATIONS "  find_dependency(${package})\n")
    endforeach()
    string(APPEND MSM_COMPONENT_DECLARATIONS "endmacro()\n")
  endforeach()
  configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/msmConfig.cmake.in
    ${PROJECT_BINARY_DIR}/msmConfig.cmake INSTALL_DESTINATION ${destination})
  write_basic_package_version_file(${PROJECT_BINARY_DIR}/msmConfigVersion.cmake COMPATIBILITY SameMinorVersion)
  install(FILES ${PROJECT_BINARY_DIR}/msmConfig.cmake ${PROJECT_BINARY_DIR}/msmConfigVersion.cmake
    ${PROJECT_SOURCE_DIR}/cmake/FindGLPK.cmake ${PROJECT_SOURCE_DIR}/cmake/Findlibdeflate.cmake
    ${PROJECT_SOURCE_DIR}/cmake/MsmFindImported.cmake
    DESTINATION ${destination})
endfunction()
