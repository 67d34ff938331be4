# Finds libdeflate (Debian: libdeflate-dev) and defines the imported target libdeflate::libdeflate.
include(${CMAKE_CURRENT_LIST_DIR}/MsmFindImported.cmake)
msm_find_imported(libdeflate libdeflate::libdeflate libdeflate.h deflate)
