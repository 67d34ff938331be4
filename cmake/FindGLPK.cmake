# Finds GLPK (Debian: libglpk-dev) and defines the imported target GLPK::GLPK.
include(${CMAKE_CURRENT_LIST_DIR}/MsmFindImported.cmake)
msm_find_imported(GLPK GLPK::GLPK glpk.h glpk)
