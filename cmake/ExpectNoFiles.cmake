# cmake -DDIR=<dir> -P ExpectNoFiles.cmake: fails if <dir> holds any file (a rejected command
# must not leave partial output behind).
file(GLOB_RECURSE files "${DIR}/*")
if(files)
  message(FATAL_ERROR "unexpected output in ${DIR}: ${files}")
endif()
